// Taking back part of a running job's log (spot checks: the answers of a
// quarantined worker, and what the job did after the first of them).
#include <sqlite3.h>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/store/sqlite_statement.h"
#include "server/store/store.h"

namespace mbopt::store {

absl::Status Store::RewindJob(const std::string& job_id, const std::vector<std::int64_t>& request_ids,
                              std::int64_t keep_records) {
  std::lock_guard<std::mutex> lock(mutex_);
  return InTransaction(db_, [&]() -> absl::Status {
    MBOPT_ASSIGN_OR_RETURN(Statement forget,
                           Statement::Prepare(db_, "DELETE FROM analyses WHERE job_id = ? AND request_id = ?"));
    for (const std::int64_t request_id : request_ids) {
      forget.BindText(1, job_id);
      forget.BindInt(2, request_id);
      MBOPT_RETURN_IF_ERROR(forget.Run());
      forget.Reset();
    }
    MBOPT_ASSIGN_OR_RETURN(Statement cycles, Statement::Prepare(db_, "DELETE FROM cycles WHERE job_id = ? AND idx >= ?"));
    cycles.BindText(1, job_id);
    cycles.BindInt(2, keep_records);
    MBOPT_RETURN_IF_ERROR(cycles.Run());
    // The next record is appended at index `records` (AppendCyclesLocked).
    MBOPT_ASSIGN_OR_RETURN(Statement count, Statement::Prepare(db_, "UPDATE jobs SET records = ? WHERE id = ?"));
    count.BindInt(1, keep_records);
    count.BindText(2, job_id);
    MBOPT_RETURN_IF_ERROR(count.Run());
    if (sqlite3_changes(db_) != 1) return absl::NotFoundError(absl::StrCat("no job '", job_id, "' in ", path_));
    return absl::OkStatus();
  });
}

}  // namespace mbopt::store
