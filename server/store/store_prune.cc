// Pruning and export of finished jobs (mbopt-server gc; docs/store.md).
#include <sqlite3.h>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/store/sqlite_statement.h"
#include "server/store/store.h"

namespace mbopt::store {
namespace {

// Runs `sql` with `job_id` bound to its one parameter.
absl::Status RunForJob(sqlite3* db, const std::string& sql, const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(Statement stmt, Statement::Prepare(db, sql));
  stmt.BindText(1, job_id);
  return stmt.Run();
}

}  // namespace

absl::Status Store::DeleteJob(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  return InTransaction(db_, [&]() -> absl::Status {
    // Children first: the foreign keys are enforced.
    MBOPT_RETURN_IF_ERROR(RunForJob(db_, "DELETE FROM analyses WHERE job_id = ?", job_id));
    MBOPT_RETURN_IF_ERROR(RunForJob(db_, "DELETE FROM cycles WHERE job_id = ?", job_id));
    MBOPT_RETURN_IF_ERROR(RunForJob(db_, "DELETE FROM events WHERE job_id = ?", job_id));
    MBOPT_RETURN_IF_ERROR(RunForJob(db_, "DELETE FROM jobs WHERE id = ?", job_id));
    if (sqlite3_changes(db_) != 1) return absl::NotFoundError(absl::StrCat("no job '", job_id, "' in ", path_));
    return absl::OkStatus();
  });
}

absl::Status Store::ExportJobs(const std::vector<std::string>& job_ids, const std::string& path) {
  {
    // Creates (or migrates) the destination with this build's schema, so
    // that its tables have the same columns in the same order.
    MBOPT_ASSIGN_OR_RETURN(std::unique_ptr<Store> destination, Store::Open(path));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(Statement attach, Statement::Prepare(db_, "ATTACH DATABASE ? AS export_db"));
  attach.BindText(1, path);
  MBOPT_RETURN_IF_ERROR(attach.Run());
  absl::Status status = InTransaction(db_, [&]() -> absl::Status {
    for (const std::string& id : job_ids) {
      MBOPT_ASSIGN_OR_RETURN(Statement taken,
                             Statement::Prepare(db_, "SELECT count(*) FROM export_db.jobs WHERE id = ? OR seq = "
                                                     "(SELECT seq FROM main.jobs WHERE id = ?)"));
      taken.BindText(1, id);
      taken.BindText(2, id);
      MBOPT_ASSIGN_OR_RETURN(bool row, taken.Step());
      if (row && taken.ColumnInt(0) != 0) {
        return absl::AlreadyExistsError(absl::StrCat(path, " already holds a job with the id or number of '", id, "'"));
      }
      MBOPT_RETURN_IF_ERROR(RunForJob(db_, "INSERT INTO export_db.jobs SELECT * FROM main.jobs WHERE id = ?", id));
      if (sqlite3_changes(db_) != 1) return absl::NotFoundError(absl::StrCat("no job '", id, "' in ", path_));
      MBOPT_RETURN_IF_ERROR(
          RunForJob(db_, "INSERT INTO export_db.analyses SELECT * FROM main.analyses WHERE job_id = ?", id));
      MBOPT_RETURN_IF_ERROR(RunForJob(db_, "INSERT INTO export_db.cycles SELECT * FROM main.cycles WHERE job_id = ?", id));
      MBOPT_RETURN_IF_ERROR(RunForJob(db_,
                                      "INSERT INTO export_db.events(job_id, unix_ms, kind, message) "
                                      "SELECT job_id, unix_ms, kind, message FROM main.events WHERE job_id = ? "
                                      "ORDER BY id",
                                      id));
    }
    return Exec(db_,
                "UPDATE export_db.job_sequence SET last_seq = max(last_seq, "
                "(SELECT coalesce(max(seq), 0) FROM export_db.jobs))");
  });
  const absl::Status detached = Exec(db_, "DETACH DATABASE export_db");
  if (!status.ok()) return status;
  return detached;
}

absl::Status Store::Compact() {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_RETURN_IF_ERROR(Exec(db_, "VACUUM"));
  // The WAL holds the rewritten pages until a checkpoint: truncate it too.
  return Exec(db_, "PRAGMA wal_checkpoint(TRUNCATE)");
}

}  // namespace mbopt::store
