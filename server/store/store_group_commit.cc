// Group commit of job writes (store.h, Commit; docs/store.md).
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/store/sqlite_statement.h"
#include "server/store/store.h"

namespace mbopt::store {

absl::Status Store::AddAnalysis(const std::string& job_id, const jobs::AnalysisRecord& analysis) {
  JobWrite write;
  write.job_id = job_id;
  write.analyses.push_back(&analysis);
  return Commit(write);
}

absl::Status Store::Commit(const JobWrite& write) { return CommitAll({&write}).front(); }

std::vector<absl::Status> Store::CommitAll(const std::vector<const JobWrite*>& writes) {
  std::vector<PendingWrite> mine;
  mine.reserve(writes.size());
  for (const JobWrite* write : writes) mine.push_back(PendingWrite{write, absl::OkStatus()});
  std::unique_lock<std::mutex> lock(group_mutex_);
  for (PendingWrite& p : mine) group_queue_.push_back(&p);
  auto all_done = [&] { return std::all_of(mine.begin(), mine.end(), [](const PendingWrite& p) { return p.done; }); };
  while (!all_done()) {
    if (group_committing_) {
      group_done_.wait(lock);
      continue;
    }
    // This caller commits everything queued so far, its own writes included;
    // writes that arrive meanwhile wait for the next group.
    group_committing_ = true;
    std::vector<PendingWrite*> group;
    group.swap(group_queue_);
    const std::int64_t transaction = analysis_transactions_ + 1;
    const std::function<void(std::int64_t)> hook = before_commit_;
    lock.unlock();
    CommitGroup(group, transaction, hook);
    lock.lock();
    for (PendingWrite* p : group) p->done = true;
    group_committing_ = false;
    ++analysis_transactions_;
    group_done_.notify_all();
  }
  std::vector<absl::Status> statuses;
  statuses.reserve(mine.size());
  for (PendingWrite& p : mine) statuses.push_back(std::move(p.status));
  return statuses;
}

absl::Status Store::WriteLocked(const JobWrite& write) {
  if (!write.cycles.empty() && !write.progress.has_value()) {
    return absl::InvalidArgumentError(absl::StrCat("cycle records of job '", write.job_id, "' without its progress"));
  }
  for (const jobs::AnalysisRecord* a : write.analyses) {
    MBOPT_RETURN_IF_ERROR(InsertAnalysisLocked(write.job_id, *a));
  }
  if (write.progress.has_value()) {
    MBOPT_RETURN_IF_ERROR(AppendCyclesLocked(write.job_id, write.cycles, *write.progress));
  }
  if (write.event.has_value()) MBOPT_RETURN_IF_ERROR(InsertEventLocked(write.job_id, *write.event));
  return absl::OkStatus();
}

void Store::CommitGroup(const std::vector<PendingWrite*>& group, std::int64_t transaction,
                        const std::function<void(std::int64_t)>& before_commit) {
  std::lock_guard<std::mutex> lock(mutex_);
  // At kCycles a group of results alone, or with records whose caller syncs
  // the log itself (JobWrite::defer_sync), is not synced: it reaches the
  // disk with the next sync (the WAL is synced as a whole), and until then a
  // machine crash can take only what replay computes again. Every other
  // transaction runs FULL.
  if (durability_ == Durability::kCycles) {
    const bool needs_sync = std::any_of(group.begin(), group.end(), [](const PendingWrite* p) {
      return (p->write->progress.has_value() && !p->write->defer_sync) || p->write->event.has_value();
    });
    if (!needs_sync) {
      const absl::Status mode = SetSynchronousLocked(false);
      if (!mode.ok()) {
        for (PendingWrite* p : group) p->status = mode;
        return;
      }
    }
  }
  const bool synced = synchronous_full_;
  CommitGroupLocked(group, transaction, before_commit);
  if (durability_ == Durability::kCycles && !synchronous_full_) {
    // Back to FULL for everything else; should that fail, the next commit
    // is merely not synced, and the one after tries again.
    (void)SetSynchronousLocked(true);
  }
  if (synced && std::any_of(group.begin(), group.end(), [](const PendingWrite* p) { return p->status.ok(); })) {
    ++synced_transactions_;
  }
}

absl::Status Store::SetSynchronousLocked(bool full) {
  MBOPT_ASSIGN_OR_RETURN(Statement * pragma, full ? PreparedLocked(pragma_sync_full_, "PRAGMA synchronous = FULL")
                                                  : PreparedLocked(pragma_sync_normal_, "PRAGMA synchronous = NORMAL"));
  const absl::Status status = pragma->Run();
  pragma->Reset();
  if (status.ok()) synchronous_full_ = full;
  return status;
}

void Store::CommitGroupLocked(const std::vector<PendingWrite*>& group, std::int64_t transaction,
                              const std::function<void(std::int64_t)>& before_commit) {
  absl::Status begun = Exec(db_, "BEGIN IMMEDIATE");
  if (!begun.ok()) {
    for (PendingWrite* p : group) p->status = begun;
    return;
  }
  if (group.size() == 1) {
    group[0]->status = WriteLocked(*group[0]->write);
  } else {
    // A write that fails (a second result for the same request) fails
    // alone: its savepoint is rolled back, and the others commit.
    for (PendingWrite* p : group) {
      absl::Status status = Exec(db_, "SAVEPOINT job_write");
      if (status.ok()) status = WriteLocked(*p->write);
      if (status.ok()) {
        status = Exec(db_, "RELEASE job_write");
      } else {
        (void)Exec(db_, "ROLLBACK TO job_write");
        (void)Exec(db_, "RELEASE job_write");
      }
      p->status = status;
    }
  }
  if (group.size() == 1 && !group[0]->status.ok()) {
    (void)Exec(db_, "ROLLBACK");
    return;
  }
  if (before_commit) before_commit(transaction);
  const absl::Status committed = Exec(db_, "COMMIT");
  if (!committed.ok()) {
    (void)Exec(db_, "ROLLBACK");
    for (PendingWrite* p : group) {
      if (p->status.ok()) p->status = committed;
    }
  }
}

void Store::SetBeforeCommitHook(std::function<void(std::int64_t transaction)> hook) {
  std::lock_guard<std::mutex> lock(group_mutex_);
  before_commit_ = std::move(hook);
}

absl::Status Store::SyncLog() {
  if (durability_ == Durability::kNormal) return absl::OkStatus();
  std::lock_guard<std::mutex> lock(log_sync_mutex_);
  if (wal_fd_ < 0) {
    // Its own descriptor: syncing through SQLite's would hold the
    // connection (and every commit) for the length of the sync. fdatasync
    // makes durable what was written to the file through any descriptor.
    wal_fd_ = open((path_ + "-wal").c_str(), O_RDONLY | O_CLOEXEC);
    if (wal_fd_ < 0) {
      if (errno == ENOENT) return absl::OkStatus();  // no log yet: every commit is in the main file
      return absl::UnavailableError(absl::StrCat("cannot open ", path_, "-wal to sync it: ", std::strerror(errno)));
    }
  }
  if (fdatasync(wal_fd_) != 0) {
    return absl::UnavailableError(absl::StrCat("cannot sync ", path_, "-wal: ", std::strerror(errno)));
  }
  ++log_syncs_;
  return absl::OkStatus();
}

std::int64_t Store::LogSyncs() const {
  std::lock_guard<std::mutex> lock(log_sync_mutex_);
  return log_syncs_;
}

std::int64_t Store::AnalysisTransactions() const {
  std::lock_guard<std::mutex> lock(group_mutex_);
  return analysis_transactions_;
}

std::int64_t Store::SyncedTransactions() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return synced_transactions_;
}

}  // namespace mbopt::store
