// Which jobs may run: a limit on running jobs, server-wide and per user, and
// on the jobs one user may keep waiting. Jobs beyond the running limits wait
// in submission order; a user at their own limit does not hold up others.
// Bookkeeping only (no locks, no I/O): the job manager keeps it under a
// mutex of its own and starts what NextToStart names.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "absl/status/status.h"

namespace mbopt::jobs::manager {

// 0 means no limit.
struct AdmissionLimits {
  int max_running_jobs = 0;           // server-wide
  int max_running_jobs_per_user = 0;  // per owner ("" on a server without tokens is one owner)
  int max_queued_jobs_per_user = 0;   // waiting jobs per owner; more are refused at submit
};

class Admission {
 public:
  explicit Admission(AdmissionLimits limits) : limits_(limits) {}

  const AdmissionLimits& limits() const { return limits_; }

  // Whether a job of `owner` may start now.
  bool HasRoomFor(const std::string& owner) const;
  // ResourceExhausted, saying the limit, when `owner` may not queue one more job.
  absl::Status CheckQueueRoom(const std::string& owner) const;

  void Started(const std::string& owner);
  void Stopped(const std::string& owner);
  // `seq` orders the queue (submission order).
  void Enqueue(std::int64_t seq, const std::string& job_id, const std::string& owner);
  void Remove(const std::string& job_id);

  // The first waiting job whose owner has room, if the server has room.
  std::optional<std::string> NextToStart() const;
  // Why a waiting job waits, for its status: its place in the queue and the
  // limit that holds it. "" for a job that does not wait.
  std::string WhyWaiting(const std::string& job_id) const;

  int running() const { return running_; }
  int queued() const { return static_cast<int>(queue_.size()); }

 private:
  struct Waiting {
    std::string job_id;
    std::string owner;
  };
  int RunningOf(const std::string& owner) const;
  int QueuedOf(const std::string& owner) const;

  AdmissionLimits limits_;
  int running_ = 0;
  std::map<std::string, int> running_by_owner_;
  std::map<std::string, int> queued_by_owner_;
  std::map<std::int64_t, Waiting> queue_;  // by seq
  std::map<std::string, std::int64_t> seq_of_;
  // Each waiting job's place, numbered once per change of the queue: a
  // listing asks every waiting job's place, which would otherwise cost the
  // queue's length each.
  mutable std::map<std::string, int> place_of_;
  mutable bool places_valid_ = false;
};

}  // namespace mbopt::jobs::manager
