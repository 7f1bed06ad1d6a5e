// Group commit of analysis results (store.h, AddAnalysis; docs/store.md).
#include "absl/status/status.h"
#include "server/store/sqlite_statement.h"
#include "server/store/store.h"

namespace mbopt::store {

absl::Status Store::AddAnalysis(const std::string& job_id, const jobs::AnalysisRecord& analysis) {
  PendingAnalysis mine{&job_id, &analysis, absl::OkStatus()};
  std::unique_lock<std::mutex> lock(group_mutex_);
  group_queue_.push_back(&mine);
  while (!mine.done) {
    if (group_committing_) {
      group_done_.wait(lock);
      continue;
    }
    // This caller commits everything queued so far, its own row included;
    // rows that arrive meanwhile wait for the next group.
    group_committing_ = true;
    std::vector<PendingAnalysis*> group;
    group.swap(group_queue_);
    lock.unlock();
    CommitAnalysisGroup(group);
    lock.lock();
    for (PendingAnalysis* p : group) p->done = true;
    group_committing_ = false;
    ++analysis_transactions_;
    group_done_.notify_all();
  }
  return mine.status;
}

void Store::CommitAnalysisGroup(const std::vector<PendingAnalysis*>& group) {
  std::lock_guard<std::mutex> lock(mutex_);
  absl::Status begun = Exec(db_, "BEGIN IMMEDIATE");
  if (!begun.ok()) {
    for (PendingAnalysis* p : group) p->status = begun;
    return;
  }
  // A row that fails (a duplicate request id) fails alone: SQLite undoes
  // only that statement, and the others commit.
  for (PendingAnalysis* p : group) p->status = InsertAnalysisLocked(*p->job_id, *p->record);
  const absl::Status committed = Exec(db_, "COMMIT");
  if (!committed.ok()) {
    (void)Exec(db_, "ROLLBACK");
    for (PendingAnalysis* p : group) {
      if (p->status.ok()) p->status = committed;
    }
  }
}

std::int64_t Store::AnalysisTransactions() const {
  std::lock_guard<std::mutex> lock(group_mutex_);
  return analysis_transactions_;
}

}  // namespace mbopt::store
