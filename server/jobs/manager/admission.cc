#include "server/jobs/manager/admission.h"

#include "absl/strings/str_cat.h"

namespace mbopt::jobs::manager {
namespace {

std::string Who(const std::string& owner) { return owner.empty() ? "this server's user" : absl::StrCat("user '", owner, "'"); }

}  // namespace

int Admission::RunningOf(const std::string& owner) const {
  auto it = running_by_owner_.find(owner);
  return it == running_by_owner_.end() ? 0 : it->second;
}

int Admission::QueuedOf(const std::string& owner) const {
  auto it = queued_by_owner_.find(owner);
  return it == queued_by_owner_.end() ? 0 : it->second;
}

bool Admission::HasRoomFor(const std::string& owner) const {
  if (limits_.max_running_jobs > 0 && running_ >= limits_.max_running_jobs) return false;
  return limits_.max_running_jobs_per_user <= 0 || RunningOf(owner) < limits_.max_running_jobs_per_user;
}

absl::Status Admission::CheckQueueRoom(const std::string& owner) const {
  if (limits_.max_queued_jobs_per_user <= 0 || QueuedOf(owner) < limits_.max_queued_jobs_per_user) {
    return absl::OkStatus();
  }
  return absl::ResourceExhaustedError(
      absl::StrCat(Who(owner), " already has ", limits_.max_queued_jobs_per_user,
                   " jobs waiting to run (the server's --max-queued-jobs-per-user): wait for some to start or "
                   "cancel them"));
}

void Admission::Started(const std::string& owner) {
  ++running_;
  ++running_by_owner_[owner];
}

void Admission::Stopped(const std::string& owner) {
  auto it = running_by_owner_.find(owner);
  if (it == running_by_owner_.end()) return;
  --running_;
  if (--it->second == 0) running_by_owner_.erase(it);
}

void Admission::Enqueue(std::int64_t seq, const std::string& job_id, const std::string& owner) {
  Remove(job_id);
  if (auto taken = queue_.find(seq); taken != queue_.end()) Remove(taken->second.job_id);
  queue_[seq] = Waiting{job_id, owner};
  seq_of_[job_id] = seq;
  ++queued_by_owner_[owner];
  places_valid_ = false;
}

void Admission::Remove(const std::string& job_id) {
  auto it = seq_of_.find(job_id);
  if (it == seq_of_.end()) return;
  auto waiting = queue_.find(it->second);
  if (auto owner = queued_by_owner_.find(waiting->second.owner); owner != queued_by_owner_.end()) {
    if (--owner->second == 0) queued_by_owner_.erase(owner);
  }
  queue_.erase(waiting);
  seq_of_.erase(it);
  places_valid_ = false;
}

std::optional<std::string> Admission::NextToStart() const {
  if (limits_.max_running_jobs > 0 && running_ >= limits_.max_running_jobs) return std::nullopt;
  for (const auto& [seq, w] : queue_) {
    if (HasRoomFor(w.owner)) return w.job_id;
  }
  return std::nullopt;
}

std::string Admission::WhyWaiting(const std::string& job_id) const {
  auto it = seq_of_.find(job_id);
  if (it == seq_of_.end()) return "";
  const Waiting& w = queue_.at(it->second);
  if (!places_valid_) {
    place_of_.clear();
    int place = 0;
    for (const auto& [seq, waiting] : queue_) place_of_[waiting.job_id] = place++;
    places_valid_ = true;
  }
  const int ahead = place_of_.at(job_id);
  std::string limit;
  if (limits_.max_running_jobs > 0 && running_ >= limits_.max_running_jobs) {
    limit = absl::StrCat("the server runs ", running_, " jobs, its limit (--max-running-jobs ",
                         limits_.max_running_jobs, ")");
  } else {
    limit = absl::StrCat(Who(w.owner), " runs ", RunningOf(w.owner), " jobs, the limit per user (--max-running-jobs-per-user ",
                         limits_.max_running_jobs_per_user, ")");
  }
  return absl::StrCat("waiting to run: ", ahead, ahead == 1 ? " job" : " jobs", " ahead in the queue; ", limit);
}

}  // namespace mbopt::jobs::manager
