// The job database: one SQLite file holding jobs, their studies, every
// analysis result, every cycle record and an event log. The schema, the
// version rule and what survives a crash are written down in docs/store.md.
//
// Durability: WAL journal; which commits are synced to disk is the
// Durability level (by default those that carry cycle records: a crash of
// the machine may cost recomputing the cycle in progress, never a record).
// What a job's results change (their analysis rows, and the cycle records
// they completed with the job's progress) is one JobWrite, committed
// atomically, together with the writes of other callers that arrive
// meanwhile (group commit), so after a crash the database holds either all
// of a write or none of it.
//
// Thread-safe: one connection, serialized by a mutex. Calls are short
// (a handful of rows); the caller should still not hold its own locks across
// them if it can avoid it.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/jobs/analysis_record.h"
#include "server/store/records.h"
#include "server/store/sqlite_statement.h"

struct sqlite3;

namespace mbopt::store {

// The schema version this code writes. A database with a newer version is
// refused; older versions are migrated on open (docs/store.md lists the
// versions and their migrations).
inline constexpr int kSchemaVersion = 8;
// PRAGMA application_id of an mbopt database ("mbop").
inline constexpr std::int32_t kApplicationId = 0x6d626f70;

// How much of the log a machine crash (power loss, kernel panic) may take
// with it; a crash of the server process alone loses nothing committed at
// either level (docs/store.md, "Durability").
enum class Durability {
  // Every commit is synced to disk (synchronous = FULL): one fdatasync per
  // transaction of results.
  kFull,
  // The default. Commits with cycle records (and every other change: jobs,
  // states, events) are synced; commits of results alone reach the
  // operating system at once and the disk with the next synced commit. A
  // machine crash may lose the results of the cycle in progress, never a
  // cycle record anyone has seen: a resume analyses them again and ends with
  // the same result, bit for bit.
  kCycles,
  // Commits reach the operating system, which writes them soon
  // (synchronous = NORMAL): a machine crash may lose the last commits. A
  // job resumes from what is left, analyses again what was lost and ends
  // with the same result, bit for bit.
  kNormal,
};

// "full" / "cycles" / "normal".
const char* DurabilityName(Durability durability);
std::optional<Durability> ParseDurability(const std::string& name);

// What one batch of a job's results changes, committed atomically
// (Store::Commit): the analysis rows, and the cycle records they completed
// with the job's progress. Pointers: the rows are not copied (a result may be
// megabytes).
struct JobWrite {
  std::string job_id;
  std::vector<const jobs::AnalysisRecord*> analyses;
  std::vector<CycleRow> cycles;             // appended to the record log, indices in order
  std::optional<JobProgress> progress;      // updates the job row; required with cycles
  std::optional<NewEvent> event = std::nullopt;  // logged with the rest (the job's end)
  // At Durability::kCycles: the cycle records are not synced by this
  // commit; the caller publishes them only after SyncLog (the job manager
  // does, on its own thread, so that no call waits for the sync).
  bool defer_sync = false;
};

class Store {
 public:
  // Opens or creates the database at `path`. FailedPrecondition for a file
  // that is not an mbopt database (another SQLite database, or not SQLite at
  // all) or one written by a newer mbopt; DataLoss when SQLite reports
  // corruption; Unavailable when the file cannot be opened.
  static absl::StatusOr<std::unique_ptr<Store>> Open(const std::string& path,
                                                     Durability durability = Durability::kCycles);
  ~Store();
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;

  const std::string& path() const { return path_; }

  // Inserts a job, and `event` with it; `seq` of `job` is assigned, and so
  // is `id` ("job-<seq>") when it is empty. Returns the row as stored.
  absl::StatusOr<JobRow> CreateJob(const JobRow& job, const std::optional<NewEvent>& event = std::nullopt);
  absl::StatusOr<JobRow> GetJob(const std::string& job_id);  // NotFound
  absl::StatusOr<std::vector<JobRow>> ListJobs();             // by seq
  // Sets the state and its message, and logs `event`, in one transaction.
  absl::Status SetJobState(const std::string& job_id, const std::string& state, const std::string& message,
                           const std::optional<NewEvent>& event = std::nullopt);

  // Commits `write` atomically: all of it or none (AlreadyExists if the job
  // already has a result for one of the request ids, NotFound for an unknown
  // job with cycle records). Returns once it is committed (and synced, at
  // Durability::kFull, and at kCycles when it carries cycle records). Group commit (store_group_commit.cc): writes that
  // arrive while another commit is under way are committed together in the
  // next transaction, one sync for all, each in a savepoint of its own so
  // that one that fails fails alone; a caller never waits for more than the
  // commit under way and its own.
  absl::Status Commit(const JobWrite& write);
  // Commits `writes` (of one or several jobs) in the same group: one
  // transaction unless a commit is under way, each write in its own
  // savepoint, one status per write, in order. A worker's results for
  // several jobs take one transaction instead of one per job.
  std::vector<absl::Status> CommitAll(const std::vector<const JobWrite*>& writes);
  // Commits one analysis result (Commit of a write with that row only).
  absl::Status AddAnalysis(const std::string& job_id, const jobs::AnalysisRecord& analysis);
  // Transactions that committed writes so far (for tests and benchmarks:
  // fewer than the writes when they arrived together).
  std::int64_t AnalysisTransactions() const;
  // Of those, the ones committed with a sync (all at kFull; at kCycles those
  // with cycle records not deferred to SyncLog, or with an event; none at
  // kNormal).
  std::int64_t SyncedTransactions() const;
  // Commits this store began on its database, of any kind (a statement
  // outside a transaction is one; SQLite's commit hook, so a commit that
  // then fails counts too): what a change costs in commits.
  std::int64_t Commits() const { return commits_.load(std::memory_order_relaxed); }
  // Makes every commit that has returned so far durable (fdatasync of the
  // write-ahead log), without holding up commits meanwhile. No-op at
  // Durability::kNormal.
  absl::Status SyncLog();
  std::int64_t LogSyncs() const;  // SyncLog calls that synced (for tests)
  Durability durability() const { return durability_; }
  // Testing: called inside each group transaction after its rows are
  // written and before COMMIT, with the transaction's number (1-based), so
  // a test can kill the process in the middle of a group commit.
  void SetBeforeCommitHook(std::function<void(std::int64_t transaction)> hook);
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> LoadAnalyses(const std::string& job_id);  // by request id
  // How many of the job's logged analyses each token holder's workers
  // computed, by holder name ("" for analyses of a server without tokens,
  // of the server itself, or logged before schema version 8).
  absl::StatusOr<std::vector<AnalysesByHolder>> CountAnalysesByHolder(const std::string& job_id);

  // Commits `records` (appended to the job's record log, indices assigned in
  // order after the existing ones) and `progress` in ONE transaction (Commit
  // of a write without analyses).
  absl::Status CommitCycle(const std::string& job_id, const std::vector<CycleRow>& records,
                           const JobProgress& progress);
  absl::StatusOr<std::vector<CycleRow>> LoadCycles(const std::string& job_id);  // by index

  absl::Status AddEvent(const std::string& job_id, const std::string& kind,
                        const std::string& message);
  absl::StatusOr<std::vector<EventRow>> LoadEvents(const std::string& job_id);

  // Pruning (store_prune.cc). Deletes a job and everything logged for it in
  // one transaction; its id is never given to another job. NotFound for an
  // unknown id.
  absl::Status DeleteJob(const std::string& job_id);
  // Takes back part of a running job's log in one transaction
  // (store_rewind.cc): the analyses of `request_ids` and the cycle records
  // from index `keep_records` on. For spot checks: the answers of a
  // quarantined worker and what followed them.
  absl::Status RewindJob(const std::string& job_id, const std::vector<std::int64_t>& request_ids,
                         std::int64_t keep_records);
  // Copies the jobs, with every row logged for them, into the mbopt
  // database at `path` (created if missing, migrated if older), in one
  // transaction. AlreadyExists naming the job when `path` holds its id.
  absl::Status ExportJobs(const std::vector<std::string>& job_ids, const std::string& path);
  // Gives the pages of deleted rows back to the file system (VACUUM).
  absl::Status Compact();

 private:
  Store(std::string path, sqlite3* db, Durability durability);
  // `slot`'s statement, prepared on first use (parsing a statement for every
  // write was a third of the server's CPU); the caller holds mutex_.
  absl::StatusOr<Statement*> PreparedLocked(std::optional<Statement>& slot, const char* sql);
  // One INSERT into analyses; the caller holds mutex_ (and a transaction).
  absl::Status InsertAnalysisLocked(const std::string& job_id, const jobs::AnalysisRecord& analysis);
  // One INSERT into events; the caller holds mutex_.
  absl::Status InsertEventLocked(const std::string& job_id, const NewEvent& event);

  // The rows of one write; the caller holds mutex_ and a transaction.
  absl::Status WriteLocked(const JobWrite& write);
  absl::Status AppendCyclesLocked(const std::string& job_id, const std::vector<CycleRow>& cycles,
                                  const JobProgress& progress);

  // A write waiting for its group's commit.
  struct PendingWrite {
    const JobWrite* write;
    absl::Status status;
    bool done = false;
  };
  void CommitGroup(const std::vector<PendingWrite*>& group, std::int64_t transaction,
                   const std::function<void(std::int64_t)>& before_commit);
  // Switches the connection's sync mode (synchronous_full_ follows).
  absl::Status SetSynchronousLocked(bool full);
  // The transaction itself; the caller holds mutex_ and set the sync mode.
  void CommitGroupLocked(const std::vector<PendingWrite*>& group, std::int64_t transaction,
                         const std::function<void(std::int64_t)>& before_commit);

  std::string path_;
  const Durability durability_;
  mutable std::mutex mutex_;
  bool synchronous_full_ = true;  // the connection's mode now; guarded by mutex_
  std::int64_t synced_transactions_ = 0;  // guarded by mutex_
  std::atomic<std::int64_t> commits_{0};  // counted by SQLite's commit hook
  sqlite3* db_;  // owned
  // The INSERT of InsertAnalysisLocked, prepared once: preparing it for every
  // analysis was a third of the server's CPU (docs/benchmarks.md). Guarded
  // by mutex_; finalized before db_ is closed.
  std::optional<Statement> insert_analysis_;
  // The statements of AppendCyclesLocked and of the sync-level switch
  // (kCycles), prepared once like the INSERT.
  std::optional<Statement> select_records_;
  std::optional<Statement> insert_cycle_;
  std::optional<Statement> update_progress_;
  std::optional<Statement> pragma_sync_normal_;
  std::optional<Statement> pragma_sync_full_;

  mutable std::mutex group_mutex_;  // guards the members below
  std::condition_variable group_done_;
  std::vector<PendingWrite*> group_queue_;
  bool group_committing_ = false;
  std::int64_t analysis_transactions_ = 0;

  std::function<void(std::int64_t)> before_commit_;

  mutable std::mutex log_sync_mutex_;  // guards wal_fd_, log_syncs_
  int wal_fd_ = -1;            // the write-ahead log, opened by SyncLog
  std::int64_t log_syncs_ = 0;
};

}  // namespace mbopt::store
