#include "server/store/store.h"

#include <fcntl.h>
#include <unistd.h>

#include <sqlite3.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <limits>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "common/packed_doubles/packed_doubles.h"
#include "server/store/double_blob.h"
#include "server/store/sqlite_statement.h"

namespace mbopt::store {
namespace {

// How long a statement waits for a lock held by another connection.
constexpr int kBusyTimeoutMs = 1000;

std::int64_t NowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Version 1, as first released. A new database is created as version 1 and
// then migrated step by step (kMigrations), so every migration runs on every
// new database too. Changing a table means a new version and a new step.
constexpr const char* kSchemaV1 = R"sql(
CREATE TABLE schema_version (
  version INTEGER NOT NULL
);
CREATE TABLE jobs (
  id              TEXT PRIMARY KEY,
  seq             INTEGER NOT NULL UNIQUE,
  study_name      TEXT NOT NULL,
  source_name     TEXT NOT NULL,
  study           BLOB NOT NULL,
  state           TEXT NOT NULL,
  message         TEXT NOT NULL,
  created_unix_ms INTEGER NOT NULL,
  updated_unix_ms INTEGER NOT NULL,
  records         INTEGER NOT NULL DEFAULT 0,
  cycles          INTEGER NOT NULL DEFAULT 0,
  analyses        INTEGER NOT NULL DEFAULT 0,
  wall_seconds    REAL NOT NULL DEFAULT 0
);
CREATE TABLE analyses (
  job_id               TEXT NOT NULL REFERENCES jobs(id),
  request_id           INTEGER NOT NULL,
  x_scaled             BLOB NOT NULL,
  ok                   INTEGER NOT NULL,
  failure_reason       TEXT NOT NULL,
  objective_terms      BLOB NOT NULL,
  constraint_values    BLOB NOT NULL,
  worker               TEXT NOT NULL,
  wall_seconds         REAL NOT NULL,
  attempts             INTEGER NOT NULL,
  time_steps           INTEGER NOT NULL,
  rhs_evaluations      INTEGER NOT NULL,
  jacobian_evaluations INTEGER NOT NULL,
  newton_iterations    INTEGER NOT NULL,
  position_solves      INTEGER NOT NULL,
  committed_unix_ms    INTEGER NOT NULL,
  PRIMARY KEY (job_id, request_id)
);
CREATE TABLE cycles (
  job_id   TEXT NOT NULL REFERENCES jobs(id),
  idx      INTEGER NOT NULL,
  cycle    INTEGER NOT NULL,
  attempt  INTEGER NOT NULL,
  record   BLOB NOT NULL,
  PRIMARY KEY (job_id, idx)
);
CREATE TABLE events (
  id       INTEGER PRIMARY KEY AUTOINCREMENT,
  job_id   TEXT NOT NULL,
  unix_ms  INTEGER NOT NULL,
  kind     TEXT NOT NULL,
  message  TEXT NOT NULL
);
)sql";

// kMigrations[v - 1] turns version v into version v + 1.
constexpr const char* kMigrations[] = {
    // 1 -> 2: the gradients of simulator sensitivities with each analysis
    // (blobs of doubles like the values; empty: none) and why they are
    // missing. Rows of version 1 had no gradients, which the defaults say.
    R"sql(
ALTER TABLE analyses ADD COLUMN objective_gradients BLOB NOT NULL DEFAULT x'';
ALTER TABLE analyses ADD COLUMN constraint_gradients BLOB NOT NULL DEFAULT x'';
ALTER TABLE analyses ADD COLUMN gradients_unavailable TEXT NOT NULL DEFAULT '';
UPDATE schema_version SET version = 2;
)sql",
    // 2 -> 3: the failure kind of each analysis (spec/analysis_outcome.h
    // names). Failed rows of version 2 predate kinds: "unclassified".
    R"sql(
ALTER TABLE analyses ADD COLUMN failure_kind TEXT NOT NULL DEFAULT 'ok';
UPDATE analyses SET failure_kind = 'unclassified' WHERE ok = 0;
UPDATE schema_version SET version = 3;
)sql",
    // 3 -> 4: the last job number given, so that an id is never given twice
    // once pruning (mbopt-server gc) has deleted the newest jobs.
    R"sql(
CREATE TABLE job_sequence (
  last_seq INTEGER NOT NULL
);
INSERT INTO job_sequence(last_seq) SELECT coalesce(max(seq), 0) FROM jobs;
UPDATE schema_version SET version = 4;
)sql",
    // 4 -> 5: who submitted each job (the name of the token's holder), so a
    // user sees only their own jobs. Jobs of servers without tokens have none.
    R"sql(
ALTER TABLE jobs ADD COLUMN owner TEXT NOT NULL DEFAULT '';
UPDATE schema_version SET version = 5;
)sql",
    // 5 -> 6: each analysis' latency, from its task's queueing to its result
    // reaching the server (bench/service reads its percentiles). Rows of
    // version 5 were not measured: 0.
    R"sql(
ALTER TABLE analyses ADD COLUMN latency_seconds REAL NOT NULL DEFAULT 0;
UPDATE schema_version SET version = 6;
)sql",
    // 6 -> 7: an analysis' objective terms and constraint values packed
    // (common/packed_doubles, about 10x smaller on fine time grids). Rows of
    // version 6 hold 8 bytes a value: 0.
    R"sql(
ALTER TABLE analyses ADD COLUMN values_packed INTEGER NOT NULL DEFAULT 0;
UPDATE schema_version SET version = 7;
)sql",
    // 7 -> 8: the name of the token whose worker delivered each analysis
    // (per-worker tokens: a job's results say which machines computed
    // them). Rows of version 7 were not attributed: ''.
    R"sql(
ALTER TABLE analyses ADD COLUMN holder TEXT NOT NULL DEFAULT '';
UPDATE schema_version SET version = 8;
)sql",
};
static_assert(sizeof(kMigrations) / sizeof(kMigrations[0]) == kSchemaVersion - 1,
              "one migration step per schema version after the first");

absl::StatusOr<std::int64_t> QueryInt(sqlite3* db, const std::string& sql) {
  MBOPT_ASSIGN_OR_RETURN(Statement stmt, Statement::Prepare(db, sql));
  MBOPT_ASSIGN_OR_RETURN(bool row, stmt.Step());
  if (!row) return absl::InternalError(absl::StrCat("`", sql, "` returned no row"));
  return stmt.ColumnInt(0);
}

absl::StatusOr<std::string> QueryText(sqlite3* db, const std::string& sql) {
  MBOPT_ASSIGN_OR_RETURN(Statement stmt, Statement::Prepare(db, sql));
  MBOPT_ASSIGN_OR_RETURN(bool row, stmt.Step());
  if (!row) return absl::InternalError(absl::StrCat("`", sql, "` returned no row"));
  return stmt.ColumnText(0);
}

// An analysis' values as logged: packed (schema 7 on), or 8 bytes each.
absl::StatusOr<std::vector<double>> ValuesOfColumn(const std::string& blob, bool packed_values) {
  if (!packed_values) return DecodeDoubles(blob);
  // The log's own bytes: the only bound is the one UnpackDoubles always
  // applies, what deflated bytes of that size can hold.
  absl::StatusOr<std::vector<double>> values =
      packed::UnpackDoubles(blob, std::numeric_limits<std::size_t>::max());
  if (!values.ok()) return absl::DataLossError(values.status().message());
  return values;
}

// Prefixes every error of opening with the file name and what it means.
absl::Status NotUsable(const std::string& path, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat("cannot use '", path, "' as the mbopt job database: ",
                                                  status.message()));
}

// Brings a database of schema version `from` to kSchemaVersion in one
// transaction: a crash in the middle leaves the old version intact.
absl::Status Migrate(sqlite3* db, std::int64_t from) {
  if (from >= kSchemaVersion) return absl::OkStatus();
  MBOPT_RETURN_IF_ERROR(Exec(db, "BEGIN IMMEDIATE"));
  absl::Status status;
  for (std::int64_t v = from; v < kSchemaVersion && status.ok(); ++v) {
    status = Exec(db, kMigrations[v - 1]);
    if (!status.ok()) {
      status = absl::Status(status.code(), absl::StrCat("migrating schema version ", v, " to ", v + 1, ": ",
                                                        status.message()));
    }
  }
  if (status.ok()) return Exec(db, "COMMIT");
  (void)Exec(db, "ROLLBACK");
  return status;
}

absl::Status CreateSchema(sqlite3* db) {
  MBOPT_RETURN_IF_ERROR(Exec(db, "BEGIN IMMEDIATE"));
  absl::Status status = Exec(db, kSchemaV1);
  if (status.ok()) status = Exec(db, "INSERT INTO schema_version(version) VALUES (1)");
  if (status.ok()) status = Exec(db, absl::StrCat("PRAGMA application_id = ", kApplicationId));
  if (status.ok()) status = Exec(db, "COMMIT");
  if (!status.ok()) {
    (void)Exec(db, "ROLLBACK");
    return status;
  }
  return Migrate(db, 1);
}

// Checks that `db` is an mbopt database this code can use, creating the
// schema in an empty file.
absl::Status CheckOrCreateSchema(sqlite3* db) {
  // Reading the header is the first access to the file: a file that is not
  // SQLite fails here with "file is not a database".
  MBOPT_ASSIGN_OR_RETURN(std::int64_t application_id, QueryInt(db, "PRAGMA application_id"));
  MBOPT_ASSIGN_OR_RETURN(std::int64_t objects, QueryInt(db, "SELECT count(*) FROM sqlite_master"));
  if (application_id == 0 && objects == 0) {
    MBOPT_RETURN_IF_ERROR(Exec(db, "PRAGMA journal_mode = WAL"));
    return CreateSchema(db);
  }
  if (application_id != kApplicationId) {
    return absl::FailedPreconditionError(absl::StrCat(
        "it is an SQLite database of another application (application_id ", application_id,
        ", expected ", kApplicationId, ")"));
  }
  MBOPT_ASSIGN_OR_RETURN(std::int64_t version, QueryInt(db, "SELECT max(version) FROM schema_version"));
  if (version > kSchemaVersion) {
    return absl::FailedPreconditionError(absl::StrCat(
        "it has schema version ", version, ", newer than version ", kSchemaVersion,
        " of this mbopt-server; use a newer mbopt-server"));
  }
  if (version < 1) {
    return absl::DataLossError(absl::StrCat("its schema version table holds ", version));
  }
  MBOPT_ASSIGN_OR_RETURN(std::string check, QueryText(db, "PRAGMA quick_check"));
  if (check != "ok") return absl::DataLossError(absl::StrCat("integrity check failed: ", check));
  return Migrate(db, version);
}

JobRow ReadJob(const Statement& stmt) {
  JobRow job;
  job.id = stmt.ColumnText(0);
  job.seq = stmt.ColumnInt(1);
  job.study_name = stmt.ColumnText(2);
  job.source_name = stmt.ColumnText(3);
  job.study = stmt.ColumnBlob(4);
  job.state = stmt.ColumnText(5);
  job.message = stmt.ColumnText(6);
  job.created_unix_ms = stmt.ColumnInt(7);
  job.updated_unix_ms = stmt.ColumnInt(8);
  job.records = stmt.ColumnInt(9);
  job.cycles = static_cast<std::int32_t>(stmt.ColumnInt(10));
  job.analyses = stmt.ColumnInt(11);
  job.wall_seconds = stmt.ColumnDouble(12);
  job.owner = stmt.ColumnText(13);
  return job;
}

constexpr const char* kJobColumns =
    "id, seq, study_name, source_name, study, state, message, created_unix_ms, "
    "updated_unix_ms, records, cycles, analyses, wall_seconds, owner";

}  // namespace

const char* DurabilityName(Durability durability) {
  switch (durability) {
    case Durability::kFull:
      return "full";
    case Durability::kCycles:
      return "cycles";
    case Durability::kNormal:
      return "normal";
  }
  return "full";
}

std::optional<Durability> ParseDurability(const std::string& name) {
  if (name == "full") return Durability::kFull;
  if (name == "cycles") return Durability::kCycles;
  if (name == "normal") return Durability::kNormal;
  return std::nullopt;
}

absl::StatusOr<std::unique_ptr<Store>> Store::Open(const std::string& path, Durability durability) {
  // A job database holds studies and every result: readable by its owner
  // only. SQLite gives the -wal and -shm files the database file's mode, so
  // creating the file 0600 before SQLite does covers all three. An existing
  // file keeps the mode its owner gave it.
  if (path != ":memory:") {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
    if (fd >= 0) {
      ::close(fd);
    } else if (errno != EEXIST) {
      return absl::UnavailableError(absl::StrCat("cannot create the job database ", path, ": ",
                                                 std::strerror(errno)));
    }
  }
  sqlite3* db = nullptr;
  const int code = sqlite3_open_v2(path.c_str(), &db,
                                   SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_NOMUTEX,
                                   nullptr);
  if (code != SQLITE_OK) {
    absl::Status status = SqliteStatus(db, code, "open");
    sqlite3_close(db);
    return NotUsable(path, status);
  }
  std::unique_ptr<Store> store(new Store(path, db, durability));
  sqlite3_extended_result_codes(db, 1);
  // One server per database: the exclusive lock, taken below and held until
  // close, makes a second process's open fail instead of both running the
  // same jobs. (The lock dies with the process, so a crash does not leave it.)
  absl::Status status = Exec(db, absl::StrCat("PRAGMA busy_timeout = ", kBusyTimeoutMs));
  if (status.ok()) status = Exec(db, "PRAGMA locking_mode = EXCLUSIVE");
  if (status.ok()) status = CheckOrCreateSchema(db);
  // WAL survives in the file; FULL syncs the WAL on every commit so that a
  // commit that returned is on disk even if the machine loses power.
  if (status.ok()) {
    absl::StatusOr<std::string> mode = QueryText(db, "PRAGMA journal_mode = WAL");
    if (!mode.ok()) {
      status = mode.status();
    } else if (*mode != "wal") {
      status = absl::UnavailableError(absl::StrCat("SQLite refused WAL mode (journal_mode is ", *mode, ")"));
    }
  }
  if (status.ok()) {
    // kCycles runs FULL and drops to NORMAL only for commits of results
    // alone (store_group_commit.cc).
    status = Exec(db, durability == Durability::kNormal ? "PRAGMA synchronous = NORMAL" : "PRAGMA synchronous = FULL");
  }
  if (status.ok()) status = Exec(db, "PRAGMA foreign_keys = ON");
  if (status.ok()) status = Exec(db, "BEGIN EXCLUSIVE; COMMIT");
  if (absl::IsUnavailable(status)) {
    status = absl::UnavailableError(
        absl::StrCat("it is in use by another process (is another mbopt-server running on it?): ", status.message()));
  }
  if (!status.ok()) return NotUsable(path, status);
  return store;
}

Store::Store(std::string path, sqlite3* db, Durability durability)
    : path_(std::move(path)), durability_(durability), synchronous_full_(durability != Durability::kNormal), db_(db) {
  sqlite3_commit_hook(
      db_,
      [](void* store) {
        static_cast<Store*>(store)->commits_.fetch_add(1, std::memory_order_relaxed);
        return 0;  // 0: let the commit go on
      },
      this);
}

Store::~Store() {
  for (std::optional<Statement>* prepared : {&insert_analysis_, &select_records_, &insert_cycle_, &update_progress_,
                                             &pragma_sync_normal_, &pragma_sync_full_}) {
    prepared->reset();
  }
  // Closing checkpoints the WAL into the main file; nothing is lost if it
  // fails (the WAL is replayed on the next open).
  sqlite3_close_v2(db_);
  if (wal_fd_ >= 0) close(wal_fd_);
}

absl::StatusOr<JobRow> Store::CreateJob(const JobRow& job, const std::optional<NewEvent>& event) {
  std::lock_guard<std::mutex> lock(mutex_);
  JobRow stored = job;
  const std::int64_t now = NowUnixMs();
  if (stored.created_unix_ms == 0) stored.created_unix_ms = now;
  stored.updated_unix_ms = now;
  MBOPT_RETURN_IF_ERROR(InTransaction(db_, [&]() -> absl::Status {
    MBOPT_ASSIGN_OR_RETURN(std::int64_t last,
                           QueryInt(db_, "SELECT max((SELECT coalesce(max(seq), 0) FROM jobs), "
                                         "(SELECT coalesce(max(last_seq), 0) FROM job_sequence))"));
    stored.seq = last + 1;
    MBOPT_RETURN_IF_ERROR(Exec(db_, absl::StrCat("UPDATE job_sequence SET last_seq = ", stored.seq)));
    if (stored.id.empty()) stored.id = absl::StrCat("job-", stored.seq);
    MBOPT_ASSIGN_OR_RETURN(Statement stmt,
                           Statement::Prepare(db_, absl::StrCat("INSERT INTO jobs(", kJobColumns,
                                                                ") VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?)")));
    stmt.BindText(1, stored.id);
    stmt.BindInt(2, stored.seq);
    stmt.BindText(3, stored.study_name);
    stmt.BindText(4, stored.source_name);
    stmt.BindBlob(5, stored.study);
    stmt.BindText(6, stored.state);
    stmt.BindText(7, stored.message);
    stmt.BindInt(8, stored.created_unix_ms);
    stmt.BindInt(9, stored.updated_unix_ms);
    stmt.BindInt(10, stored.records);
    stmt.BindInt(11, stored.cycles);
    stmt.BindInt(12, stored.analyses);
    stmt.BindDouble(13, stored.wall_seconds);
    stmt.BindText(14, stored.owner);
    MBOPT_RETURN_IF_ERROR(stmt.Run());
    return event.has_value() ? InsertEventLocked(stored.id, *event) : absl::OkStatus();
  }));
  return stored;
}

absl::StatusOr<JobRow> Store::GetJob(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(Statement stmt,
                         Statement::Prepare(db_, absl::StrCat("SELECT ", kJobColumns, " FROM jobs WHERE id = ?")));
  stmt.BindText(1, job_id);
  MBOPT_ASSIGN_OR_RETURN(bool row, stmt.Step());
  if (!row) return absl::NotFoundError(absl::StrCat("no job '", job_id, "' in ", path_));
  return ReadJob(stmt);
}

absl::StatusOr<std::vector<JobRow>> Store::ListJobs() {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(Statement stmt,
                         Statement::Prepare(db_, absl::StrCat("SELECT ", kJobColumns, " FROM jobs ORDER BY seq")));
  std::vector<JobRow> jobs;
  while (true) {
    MBOPT_ASSIGN_OR_RETURN(bool row, stmt.Step());
    if (!row) break;
    jobs.push_back(ReadJob(stmt));
  }
  return jobs;
}

absl::Status Store::SetJobState(const std::string& job_id, const std::string& state, const std::string& message,
                                const std::optional<NewEvent>& event) {
  std::lock_guard<std::mutex> lock(mutex_);
  return InTransaction(db_, [&]() -> absl::Status {
    MBOPT_ASSIGN_OR_RETURN(
        Statement stmt, Statement::Prepare(db_, "UPDATE jobs SET state = ?, message = ?, updated_unix_ms = ? WHERE id = ?"));
    stmt.BindText(1, state);
    stmt.BindText(2, message);
    stmt.BindInt(3, NowUnixMs());
    stmt.BindText(4, job_id);
    MBOPT_RETURN_IF_ERROR(stmt.Run());
    if (sqlite3_changes(db_) != 1) return absl::NotFoundError(absl::StrCat("no job '", job_id, "' in ", path_));
    return event.has_value() ? InsertEventLocked(job_id, *event) : absl::OkStatus();
  });
}

absl::Status Store::InsertAnalysisLocked(const std::string& job_id, const jobs::AnalysisRecord& a) {
  MBOPT_ASSIGN_OR_RETURN(
      Statement * insert,
      PreparedLocked(insert_analysis_,
                     "INSERT INTO analyses(job_id, request_id, x_scaled, ok, failure_reason, objective_terms, "
                     "constraint_values, worker, wall_seconds, attempts, time_steps, rhs_evaluations, "
                     "jacobian_evaluations, newton_iterations, position_solves, committed_unix_ms, "
                     "objective_gradients, constraint_gradients, gradients_unavailable, failure_kind, "
                     "latency_seconds, values_packed, holder) "
                     "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,?,1,?)"));
  Statement& stmt = *insert;
  stmt.BindText(1, job_id);
  stmt.BindInt(2, a.request_id);
  stmt.BindBlob(3, EncodeDoubles(a.x_scaled));
  stmt.BindInt(4, a.ok() ? 1 : 0);
  stmt.BindText(5, a.failure.reason);
  // As the worker packed them; packed here when they came unpacked.
  stmt.BindBlob(6, a.objective_terms_packed.empty() ? packed::PackDoubles(a.objective_terms)
                                                    : a.objective_terms_packed);
  stmt.BindBlob(7, a.constraint_values_packed.empty() ? packed::PackDoubles(a.constraint_values)
                                                      : a.constraint_values_packed);
  stmt.BindText(8, a.worker);
  stmt.BindDouble(9, a.counters.wall_seconds);
  stmt.BindInt(10, a.attempts);
  stmt.BindInt(11, a.counters.time_steps);
  stmt.BindInt(12, a.counters.rhs_evaluations);
  stmt.BindInt(13, a.counters.jacobian_evaluations);
  stmt.BindInt(14, a.counters.newton_iterations);
  stmt.BindInt(15, a.counters.position_solves);
  stmt.BindInt(16, NowUnixMs());
  stmt.BindBlob(17, EncodeDoubles(a.objective_gradients));
  stmt.BindBlob(18, EncodeDoubles(a.constraint_gradients));
  stmt.BindText(19, a.gradients_unavailable);
  stmt.BindText(20, spec::FailureKindName(a.failure.kind));
  stmt.BindDouble(21, a.latency_seconds);
  stmt.BindText(22, a.holder);
  absl::Status status = stmt.Run();
  // Ready for the next analysis, and holding nothing of this one (its blobs
  // were copied in) while it waits.
  stmt.Reset();
  if (absl::IsAlreadyExists(status)) {
    return absl::AlreadyExistsError(absl::StrCat("job '", job_id, "' already has a result for request ",
                                                 a.request_id, " (or the job does not exist)"));
  }
  return status;
}

absl::StatusOr<std::vector<jobs::AnalysisRecord>> Store::LoadAnalyses(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(
      Statement stmt,
      Statement::Prepare(db_,
                         "SELECT request_id, x_scaled, ok, failure_reason, objective_terms, constraint_values, "
                         "worker, wall_seconds, attempts, time_steps, rhs_evaluations, jacobian_evaluations, "
                         "newton_iterations, position_solves, committed_unix_ms, objective_gradients, "
                         "constraint_gradients, gradients_unavailable, failure_kind, latency_seconds, values_packed, "
                         "holder FROM analyses WHERE job_id = ? ORDER BY request_id"));
  stmt.BindText(1, job_id);
  std::vector<jobs::AnalysisRecord> rows;
  while (true) {
    MBOPT_ASSIGN_OR_RETURN(bool more, stmt.Step());
    if (!more) break;
    jobs::AnalysisRecord a;
    a.request_id = stmt.ColumnInt(0);
    MBOPT_ASSIGN_OR_RETURN(a.x_scaled, DecodeDoubles(stmt.ColumnBlob(1)));
    const bool ok = stmt.ColumnInt(2) != 0;
    const std::optional<spec::FailureKind> kind = spec::ParseFailureKind(stmt.ColumnText(18));
    if (!kind.has_value() || (*kind == spec::FailureKind::kNone) != ok) {
      return absl::DataLossError(absl::StrCat("analysis ", a.request_id, " of job '", job_id, "' in ", path_,
                                              " has failure kind '", stmt.ColumnText(18), "' with ok = ", ok));
    }
    a.failure = spec::AnalysisFailure::Of(*kind, stmt.ColumnText(3));
    const bool packed_values = stmt.ColumnInt(20) != 0;
    MBOPT_ASSIGN_OR_RETURN(a.objective_terms, ValuesOfColumn(stmt.ColumnBlob(4), packed_values));
    MBOPT_ASSIGN_OR_RETURN(a.constraint_values, ValuesOfColumn(stmt.ColumnBlob(5), packed_values));
    a.worker = stmt.ColumnText(6);
    a.counters.wall_seconds = stmt.ColumnDouble(7);
    a.attempts = static_cast<std::int32_t>(stmt.ColumnInt(8));
    a.counters.time_steps = stmt.ColumnInt(9);
    a.counters.rhs_evaluations = stmt.ColumnInt(10);
    a.counters.jacobian_evaluations = stmt.ColumnInt(11);
    a.counters.newton_iterations = stmt.ColumnInt(12);
    a.counters.position_solves = stmt.ColumnInt(13);
    MBOPT_ASSIGN_OR_RETURN(a.objective_gradients, DecodeDoubles(stmt.ColumnBlob(15)));
    MBOPT_ASSIGN_OR_RETURN(a.constraint_gradients, DecodeDoubles(stmt.ColumnBlob(16)));
    a.gradients_unavailable = stmt.ColumnText(17);
    a.latency_seconds = stmt.ColumnDouble(19);
    a.holder = stmt.ColumnText(21);
    rows.push_back(std::move(a));
  }
  return rows;
}

absl::StatusOr<std::vector<AnalysesByHolder>> Store::CountAnalysesByHolder(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(
      Statement stmt,
      Statement::Prepare(db_, "SELECT holder, count(*) FROM analyses WHERE job_id = ? GROUP BY holder ORDER BY holder"));
  stmt.BindText(1, job_id);
  std::vector<AnalysesByHolder> counts;
  while (true) {
    MBOPT_ASSIGN_OR_RETURN(bool more, stmt.Step());
    if (!more) break;
    counts.push_back(AnalysesByHolder{stmt.ColumnText(0), stmt.ColumnInt(1)});
  }
  return counts;
}

absl::Status Store::CommitCycle(const std::string& job_id, const std::vector<CycleRow>& records,
                                const JobProgress& progress) {
  JobWrite write;
  write.job_id = job_id;
  write.cycles = records;
  write.progress = progress;
  return Commit(write);
}

absl::StatusOr<Statement*> Store::PreparedLocked(std::optional<Statement>& slot, const char* sql) {
  if (!slot.has_value()) {
    MBOPT_ASSIGN_OR_RETURN(Statement prepared, Statement::Prepare(db_, sql));
    slot.emplace(std::move(prepared));
  }
  return &*slot;
}

absl::Status Store::AppendCyclesLocked(const std::string& job_id, const std::vector<CycleRow>& records,
                                       const JobProgress& progress) {
  MBOPT_ASSIGN_OR_RETURN(Statement * select, PreparedLocked(select_records_, "SELECT records FROM jobs WHERE id = ?"));
  MBOPT_ASSIGN_OR_RETURN(
      Statement * insert_cycle,
      PreparedLocked(insert_cycle_, "INSERT INTO cycles(job_id, idx, cycle, attempt, record) VALUES (?,?,?,?,?)"));
  MBOPT_ASSIGN_OR_RETURN(Statement * update_progress,
                         PreparedLocked(update_progress_,
                                        "UPDATE jobs SET records = ?, state = ?, message = ?, cycles = ?, "
                                        "analyses = ?, wall_seconds = ?, updated_unix_ms = ? WHERE id = ?"));
  Statement& count = *select;
  count.BindText(1, job_id);
  absl::StatusOr<bool> found = count.Step();
  const std::int64_t first = found.ok() && *found ? count.ColumnInt(0) : 0;
  count.Reset();
  if (!found.ok()) return found.status();
  if (!*found) return absl::NotFoundError(absl::StrCat("no job '", job_id, "' in ", path_));
  std::int64_t next = first;
  Statement& insert = *insert_cycle;
  for (const CycleRow& r : records) {
    insert.BindText(1, job_id);
    insert.BindInt(2, next++);
    insert.BindInt(3, r.cycle);
    insert.BindInt(4, r.attempt);
    insert.BindBlob(5, r.record);
    absl::Status inserted = insert.Run();
    insert.Reset();
    MBOPT_RETURN_IF_ERROR(inserted);
  }
  Statement& update = *update_progress;
  update.BindInt(1, next);
  update.BindText(2, progress.state);
  update.BindText(3, progress.message);
  update.BindInt(4, progress.cycles);
  update.BindInt(5, progress.analyses);
  update.BindDouble(6, progress.wall_seconds);
  update.BindInt(7, NowUnixMs());
  update.BindText(8, job_id);
  absl::Status updated = update.Run();
  update.Reset();
  return updated;
}

absl::StatusOr<std::vector<CycleRow>> Store::LoadCycles(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(
      Statement stmt,
      Statement::Prepare(db_, "SELECT idx, cycle, attempt, record FROM cycles WHERE job_id = ? ORDER BY idx"));
  stmt.BindText(1, job_id);
  std::vector<CycleRow> rows;
  while (true) {
    MBOPT_ASSIGN_OR_RETURN(bool more, stmt.Step());
    if (!more) break;
    CycleRow r;
    r.index = stmt.ColumnInt(0);
    r.cycle = static_cast<std::int32_t>(stmt.ColumnInt(1));
    r.attempt = static_cast<std::int32_t>(stmt.ColumnInt(2));
    r.record = stmt.ColumnBlob(3);
    rows.push_back(std::move(r));
  }
  return rows;
}

absl::Status Store::AddEvent(const std::string& job_id, const std::string& kind, const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  return InsertEventLocked(job_id, NewEvent{kind, message});
}

absl::Status Store::InsertEventLocked(const std::string& job_id, const NewEvent& event) {
  MBOPT_ASSIGN_OR_RETURN(
      Statement stmt, Statement::Prepare(db_, "INSERT INTO events(job_id, unix_ms, kind, message) VALUES (?,?,?,?)"));
  stmt.BindText(1, job_id);
  stmt.BindInt(2, NowUnixMs());
  stmt.BindText(3, event.kind);
  stmt.BindText(4, event.message);
  return stmt.Run();
}

absl::StatusOr<std::vector<EventRow>> Store::LoadEvents(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  MBOPT_ASSIGN_OR_RETURN(
      Statement stmt,
      Statement::Prepare(db_, "SELECT id, job_id, unix_ms, kind, message FROM events WHERE job_id = ? ORDER BY id"));
  stmt.BindText(1, job_id);
  std::vector<EventRow> rows;
  while (true) {
    MBOPT_ASSIGN_OR_RETURN(bool more, stmt.Step());
    if (!more) break;
    EventRow e;
    e.id = stmt.ColumnInt(0);
    e.job_id = stmt.ColumnText(1);
    e.unix_ms = stmt.ColumnInt(2);
    e.kind = stmt.ColumnText(3);
    e.message = stmt.ColumnText(4);
    rows.push_back(std::move(e));
  }
  return rows;
}

}  // namespace mbopt::store
