// The job database: exact round trips, reopening, and refusing files it
// cannot trust (newer schema, other applications, garbage), with crash
// atomicity of transactions.
#include "server/store/store.h"

#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/packed_doubles/packed_doubles.h"
#include "server/store/double_blob.h"

namespace mbopt::store {
namespace {

using ::testing::HasSubstr;

class StoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("mbopt_store_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "jobs.db").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  static JobRow SampleJob() {
    JobRow job;
    job.study_name = "oscillator";
    job.source_name = "oscillator.study.textproto";
    job.study = std::string("\x00\x01\x02study bytes\xff", 15);
    job.state = "RUNNING";
    return job;
  }

  // A new database at `durability` (its files removed first) with one job,
  // whose id goes to *job_id.
  std::unique_ptr<Store> FreshStoreWithJob(Durability durability, std::string* job_id) {
    std::filesystem::remove(path_);
    std::filesystem::remove(path_ + "-wal");
    std::filesystem::remove(path_ + "-shm");
    auto store = Store::Open(path_, durability);
    EXPECT_TRUE(store.ok()) << store.status();
    if (!store.ok()) return nullptr;
    auto job = (*store)->CreateJob(SampleJob());
    EXPECT_TRUE(job.ok()) << job.status();
    if (!job.ok()) return nullptr;
    *job_id = job->id;
    return *std::move(store);
  }

  std::filesystem::path dir_;
  std::string path_;
};

// Values chosen to catch any decimal round trip or float narrowing.
std::vector<double> AwkwardDoubles() {
  return {0.1, -0.0, 1.0 / 3.0, std::numeric_limits<double>::denorm_min(),
          std::numeric_limits<double>::max(), -std::numeric_limits<double>::infinity(),
          std::nextafter(1.0, 2.0), 6.02214076e23};
}

bool BitIdentical(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

TEST(DoubleBlob, RoundTripIsBitExactIncludingNaNPayloadAndNegativeZero) {
  std::vector<double> values = AwkwardDoubles();
  std::uint64_t nan_bits = 0x7ff8000000012345ULL;
  double nan;
  std::memcpy(&nan, &nan_bits, sizeof nan);
  values.push_back(nan);
  absl::StatusOr<std::vector<double>> back = DecodeDoubles(EncodeDoubles(values));
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(BitIdentical(values, *back));
}

TEST(DoubleBlob, RejectsLengthNotMultipleOfEight) {
  EXPECT_EQ(DecodeDoubles("abc").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(StoreTest, AnalysisRoundTripIsBitExact) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto job = (*store)->CreateJob(SampleJob());
  ASSERT_TRUE(job.ok()) << job.status();
  jobs::AnalysisRecord a;
  const std::string a_job = job->id;
  a.request_id = 7;
  a.x_scaled = {1.0 / 7.0, 2.0 / 3.0};
  a.objective_terms = AwkwardDoubles();
  a.constraint_values = {std::sqrt(2.0), -1e-300};
  // Gradients: 8 terms x 2 variables and 2 rows x 2 variables, row-major.
  for (double v : AwkwardDoubles()) {
    a.objective_gradients.push_back(v);
    a.objective_gradients.push_back(-v / 3.0);
  }
  std::uint64_t nan_bits = 0x7ff8000000054321ULL;
  double nan;
  std::memcpy(&nan, &nan_bits, sizeof nan);
  a.constraint_gradients = {nan, -0.0, std::nextafter(0.0, 1.0), 1.0 / 49.0};
  a.worker = "w-1";
  a.counters.time_steps = 1234;
  a.latency_seconds = 0.000123;
  ASSERT_TRUE((*store)->AddAnalysis(a_job, a).ok());
  auto rows = (*store)->LoadAnalyses(job->id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 1u);
  EXPECT_EQ((*rows)[0].request_id, 7);
  EXPECT_EQ((*rows)[0].latency_seconds, 0.000123);
  EXPECT_TRUE(BitIdentical((*rows)[0].x_scaled, a.x_scaled));
  EXPECT_TRUE(BitIdentical((*rows)[0].objective_terms, a.objective_terms));
  EXPECT_TRUE(BitIdentical((*rows)[0].constraint_values, a.constraint_values));
  EXPECT_TRUE(BitIdentical((*rows)[0].objective_gradients, a.objective_gradients));
  EXPECT_TRUE(BitIdentical((*rows)[0].constraint_gradients, a.constraint_gradients));
  EXPECT_EQ((*rows)[0].counters.time_steps, 1234);
  EXPECT_EQ((*rows)[0].worker, "w-1");
}

void RunSql(const std::string& path, const std::string& sql);

std::string ColumnBlob(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) return "";
  sqlite3_stmt* stmt = nullptr;
  std::string blob;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt, nullptr) == SQLITE_OK && sqlite3_step(stmt) == SQLITE_ROW) {
    const char* bytes = static_cast<const char*>(sqlite3_column_blob(stmt, 0));
    blob.assign(bytes == nullptr ? "" : bytes, static_cast<size_t>(sqlite3_column_bytes(stmt, 0)));
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return blob;
}

// Values a worker packed are logged as they came (the server does not pack
// them again); values that came unpacked are packed by the store. Both read
// back bit for bit, and a smooth series takes a fraction of 8 bytes a value.
TEST_F(StoreTest, ValuesAreLoggedPackedAsTheWorkerPackedThem) {
  std::vector<double> series;
  for (int i = 0; i < 4001; ++i) {
    series.push_back(std::sin(1e-3 * i));
    series.push_back(-series.back());
  }
  jobs::AnalysisRecord from_worker;
  from_worker.request_id = 0;
  from_worker.objective_terms = AwkwardDoubles();
  from_worker.constraint_values = series;
  from_worker.objective_terms_packed = packed::PackDoubles(from_worker.objective_terms);
  from_worker.constraint_values_packed = packed::PackDoubles(series);
  jobs::AnalysisRecord unpacked = from_worker;
  unpacked.request_id = 1;
  unpacked.objective_terms_packed.clear();
  unpacked.constraint_values_packed.clear();
  std::string job_id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    job_id = (*store)->CreateJob(SampleJob())->id;
    ASSERT_TRUE((*store)->AddAnalysis(job_id, from_worker).ok());
    ASSERT_TRUE((*store)->AddAnalysis(job_id, unpacked).ok());
  }
  EXPECT_EQ(ColumnBlob(path_, "SELECT constraint_values FROM analyses WHERE request_id = 0"),
            from_worker.constraint_values_packed);
  EXPECT_EQ(ColumnBlob(path_, "SELECT objective_terms FROM analyses WHERE request_id = 0"),
            from_worker.objective_terms_packed);
  const std::string packed_here = ColumnBlob(path_, "SELECT constraint_values FROM analyses WHERE request_id = 1");
  EXPECT_FALSE(packed_here.empty());
  EXPECT_LT(packed_here.size() * 4, series.size() * sizeof(double)) << packed_here.size() << " bytes";
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto rows = (*store)->LoadAnalyses(job_id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 2u);
  for (const jobs::AnalysisRecord& row : *rows) {
    EXPECT_TRUE(BitIdentical(row.objective_terms, from_worker.objective_terms));
    EXPECT_TRUE(BitIdentical(row.constraint_values, series));
  }
}

// A damaged packed blob is named as lost data, not read as other values.
TEST_F(StoreTest, DamagedPackedValuesAreDataLoss) {
  std::string job_id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    job_id = (*store)->CreateJob(SampleJob())->id;
    jobs::AnalysisRecord a;
    a.objective_terms = {1.0, 2.0};
    ASSERT_TRUE((*store)->AddAnalysis(job_id, a).ok());
  }
  RunSql(path_, "UPDATE analyses SET objective_terms = x'0102030405'");
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto rows = (*store)->LoadAnalyses(job_id);
  ASSERT_FALSE(rows.ok());
  EXPECT_EQ(rows.status().code(), absl::StatusCode::kDataLoss) << rows.status();
}

TEST_F(StoreTest, AnalysisWithoutGradientsKeepsTheReason) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto job = (*store)->CreateJob(SampleJob());
  ASSERT_TRUE(job.ok()) << job.status();
  jobs::AnalysisRecord a;
  const std::string a_job = job->id;
  a.request_id = 3;
  a.objective_terms = {1.5};
  a.gradients_unavailable = "design variable x3 sets an offset";
  ASSERT_TRUE((*store)->AddAnalysis(a_job, a).ok());
  auto rows = (*store)->LoadAnalyses(job->id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 1u);
  EXPECT_TRUE((*rows)[0].objective_gradients.empty());
  EXPECT_TRUE((*rows)[0].constraint_gradients.empty());
  EXPECT_EQ((*rows)[0].gradients_unavailable, a.gradients_unavailable);
}

TEST_F(StoreTest, SecondResultForTheSameRequestIsRefused) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok());
  auto job = (*store)->CreateJob(SampleJob());
  ASSERT_TRUE(job.ok());
  jobs::AnalysisRecord a;
  const std::string a_job = job->id;
  a.request_id = 0;
  ASSERT_TRUE((*store)->AddAnalysis(a_job, a).ok());
  EXPECT_EQ((*store)->AddAnalysis(a_job, a).code(), absl::StatusCode::kAlreadyExists);
}

TEST_F(StoreTest, EverythingSurvivesCloseAndReopen) {
  std::string job_id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    auto job = (*store)->CreateJob(SampleJob());
    ASSERT_TRUE(job.ok());
    job_id = job->id;
    jobs::AnalysisRecord a;
    const std::string a_job = job_id;
    a.request_id = 0;
    a.failure = spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "integrator failed");
    ASSERT_TRUE((*store)->AddAnalysis(a_job, a).ok());
    JobProgress progress{"CONVERGED", "", 3, 12, 1.5};
    ASSERT_TRUE((*store)->CommitCycle(job_id, {{0, 1, 0, "r1"}, {0, 1, 1, std::string("r\0 2", 4)}}, progress).ok());
    ASSERT_TRUE((*store)->AddEvent(job_id, "converged", "after 3 cycles").ok());
  }
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto job = (*store)->GetJob(job_id);
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->study, SampleJob().study);
  EXPECT_EQ(job->state, "CONVERGED");
  EXPECT_EQ(job->cycles, 3);
  EXPECT_EQ(job->analyses, 12);
  EXPECT_EQ(job->records, 2);
  auto cycles = (*store)->LoadCycles(job_id);
  ASSERT_TRUE(cycles.ok());
  ASSERT_EQ(cycles->size(), 2u);
  EXPECT_EQ((*cycles)[1].index, 1);
  EXPECT_EQ((*cycles)[1].attempt, 1);
  EXPECT_EQ((*cycles)[1].record, std::string("r\0 2", 4));
  auto analyses = (*store)->LoadAnalyses(job_id);
  ASSERT_TRUE(analyses.ok());
  ASSERT_EQ(analyses->size(), 1u);
  EXPECT_EQ((*analyses)[0].failure.reason, "integrator failed");
  EXPECT_EQ((*analyses)[0].failure.kind, spec::FailureKind::kIntegrator);
  auto events = (*store)->LoadEvents(job_id);
  ASSERT_TRUE(events.ok());
  ASSERT_EQ(events->size(), 1u);
  EXPECT_EQ((*events)[0].kind, "converged");
  auto second = (*store)->CreateJob(SampleJob());
  ASSERT_TRUE(second.ok());
  EXPECT_NE(second->id, job_id);
}

// A change of a job and its line in the event log commit together: one
// commit (one sync), and no event for a change that failed.
TEST_F(StoreTest, AChangeAndItsEventAreOneCommit) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  std::int64_t commits = (*store)->Commits();
  auto job = (*store)->CreateJob(SampleJob(), NewEvent{"submitted", "a.study.textproto"});
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ((*store)->Commits(), ++commits);
  ASSERT_TRUE((*store)->SetJobState(job->id, "CANCELLED", "on request", NewEvent{"cancelled", "on request"}).ok());
  EXPECT_EQ((*store)->Commits(), ++commits);
  JobWrite end;
  end.job_id = job->id;
  end.progress = JobProgress{"CONVERGED", "", 3, 12, 1.5};
  end.event = NewEvent{"ended", "CONVERGED after 3 cycles"};
  ASSERT_TRUE((*store)->Commit(end).ok());
  EXPECT_EQ((*store)->Commits(), ++commits);
  EXPECT_TRUE(absl::IsNotFound((*store)->SetJobState("job-404", "FAILED", "", NewEvent{"failed", "no such job"})));
  EXPECT_TRUE((*store)->LoadEvents("job-404")->empty()) << "the event of a failed change is rolled back with it";
  auto events = (*store)->LoadEvents(job->id);
  ASSERT_TRUE(events.ok()) << events.status();
  std::vector<std::string> logged;
  for (const EventRow& e : *events) logged.push_back(e.kind + ": " + e.message);
  EXPECT_EQ(logged, (std::vector<std::string>{"submitted: a.study.textproto", "cancelled: on request",
                                               "ended: CONVERGED after 3 cycles"}));
  EXPECT_EQ((*store)->GetJob(job->id)->state, "CONVERGED");
}

// A job with one analysis, two cycle records and an event.
std::string AddLoggedJob(Store& store, const JobRow& row) {
  auto job = store.CreateJob(row);
  EXPECT_TRUE(job.ok()) << job.status();
  if (!job.ok()) return "";
  jobs::AnalysisRecord a;
  a.request_id = 0;
  a.objective_terms = AwkwardDoubles();
  EXPECT_TRUE(store.AddAnalysis(job->id, a).ok());
  EXPECT_TRUE(store.CommitCycle(job->id, {{0, 1, 0, "r1"}, {0, 2, 0, "r2"}}, {"CONVERGED", "", 2, 1, 0.5}).ok());
  EXPECT_TRUE(store.AddEvent(job->id, "ended", "converged").ok());
  return job->id;
}

TEST_F(StoreTest, DeletedJobLeavesNoRowsAndItsIdIsNotGivenAgain) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  const std::string first = AddLoggedJob(**store, SampleJob());
  const std::string second = AddLoggedJob(**store, SampleJob());
  ASSERT_TRUE((*store)->DeleteJob(second).ok());
  EXPECT_TRUE(absl::IsNotFound((*store)->GetJob(second).status()));
  EXPECT_TRUE((*store)->LoadAnalyses(second)->empty());
  EXPECT_TRUE((*store)->LoadCycles(second)->empty());
  EXPECT_TRUE((*store)->LoadEvents(second)->empty());
  EXPECT_EQ((*store)->LoadCycles(first)->size(), 2u) << "the other job is untouched";
  EXPECT_TRUE(absl::IsNotFound((*store)->DeleteJob(second)));
  ASSERT_TRUE((*store)->Compact().ok());
  auto third = (*store)->CreateJob(SampleJob());
  ASSERT_TRUE(third.ok());
  EXPECT_NE(third->id, second) << "an id is never reused, even after the newest job was pruned";
  EXPECT_EQ(third->seq, 3);
}

TEST_F(StoreTest, ExportedJobsAreReadBackBitForBit) {
  const std::string export_path = (dir_ / "archive.db").string();
  std::string id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    id = AddLoggedJob(**store, SampleJob());
    ASSERT_TRUE((*store)->ExportJobs({id}, export_path).ok());
    const absl::Status again = (*store)->ExportJobs({id}, export_path);
    EXPECT_TRUE(absl::IsAlreadyExists(again)) << again;
    EXPECT_THAT(again.message(), HasSubstr(id));
  }
  auto archive = Store::Open(export_path);
  ASSERT_TRUE(archive.ok()) << archive.status();
  auto job = (*archive)->GetJob(id);
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->study, SampleJob().study);
  EXPECT_EQ(job->state, "CONVERGED");
  auto analyses = (*archive)->LoadAnalyses(id);
  ASSERT_TRUE(analyses.ok() && analyses->size() == 1u);
  EXPECT_TRUE(BitIdentical((*analyses)[0].objective_terms, AwkwardDoubles()));
  EXPECT_EQ((*archive)->LoadCycles(id)->size(), 2u);
  EXPECT_EQ((*archive)->LoadEvents(id)->size(), 1u);
  auto next = (*archive)->CreateJob(SampleJob());
  ASSERT_TRUE(next.ok());
  EXPECT_NE(next->id, id) << "the archive numbers its own jobs after the imported ones";
}

TEST_F(StoreTest, UnknownJobIsNotFoundNamingTheId) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok());
  absl::StatusOr<JobRow> job = (*store)->GetJob("job-42");
  EXPECT_EQ(job.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(job.status().message()), HasSubstr("job-42"));
}

void RunSql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

// Rewrites every analysis' values as schema versions before 7 stored them,
// 8 bytes each, and drops the columns of version 7 on (packed values, the
// token holder of version 8).
void UnpackValuesAsBeforeVersion7(const std::string& path) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* select = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT rowid, objective_terms, constraint_values FROM analyses", -1, &select,
                               nullptr),
            SQLITE_OK);
  std::vector<std::tuple<std::int64_t, std::string, std::string>> rows;
  while (sqlite3_step(select) == SQLITE_ROW) {
    auto blob = [&](int column) {
      const char* bytes = static_cast<const char*>(sqlite3_column_blob(select, column));
      const std::string packed_values(bytes == nullptr ? "" : bytes,
                                      static_cast<size_t>(sqlite3_column_bytes(select, column)));
      absl::StatusOr<std::vector<double>> values = packed::UnpackDoubles(packed_values, 1 << 20);
      EXPECT_TRUE(values.ok()) << values.status();
      return values.ok() ? EncodeDoubles(*values) : std::string();
    };
    rows.emplace_back(sqlite3_column_int64(select, 0), blob(1), blob(2));
  }
  sqlite3_finalize(select);
  for (const auto& [rowid, terms, values] : rows) {
    sqlite3_stmt* update = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(db, "UPDATE analyses SET objective_terms = ?, constraint_values = ? WHERE rowid = ?",
                                 -1, &update, nullptr),
              SQLITE_OK);
    sqlite3_bind_blob(update, 1, terms.data(), static_cast<int>(terms.size()), SQLITE_TRANSIENT);
    sqlite3_bind_blob(update, 2, values.data(), static_cast<int>(values.size()), SQLITE_TRANSIENT);
    sqlite3_bind_int64(update, 3, rowid);
    EXPECT_EQ(sqlite3_step(update), SQLITE_DONE);
    sqlite3_finalize(update);
  }
  sqlite3_close(db);
  RunSql(path, "ALTER TABLE analyses DROP COLUMN values_packed; ALTER TABLE analyses DROP COLUMN holder;");
}

TEST_F(StoreTest, NewerSchemaVersionIsRefused) {
  { ASSERT_TRUE(Store::Open(path_).ok()); }
  RunSql(path_, "UPDATE schema_version SET version = " + std::to_string(kSchemaVersion + 1));
  auto store = Store::Open(path_);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(store.status().message()), HasSubstr("newer"));
  EXPECT_THAT(std::string(store.status().message()), HasSubstr(path_));
}

std::int64_t SchemaVersionOf(const std::string& path) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) return -1;
  sqlite3_stmt* stmt = nullptr;
  std::int64_t version = -1;
  if (sqlite3_prepare_v2(db, "SELECT max(version) FROM schema_version", -1, &stmt, nullptr) == SQLITE_OK &&
      sqlite3_step(stmt) == SQLITE_ROW) {
    version = sqlite3_column_int64(stmt, 0);
  }
  sqlite3_finalize(stmt);
  sqlite3_close(db);
  return version;
}

// Who submitted a job is kept with it; a job from before owners (version 4)
// reads as having none.
TEST_F(StoreTest, JobOwnerIsKeptAndOlderJobsHaveNone) {
  std::string job_id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    JobRow owned = SampleJob();
    owned.owner = "alice";
    job_id = (*store)->CreateJob(owned)->id;
    EXPECT_EQ((*store)->GetJob(job_id)->owner, "alice");
  }
  // Exactly the version 4 layout.
  UnpackValuesAsBeforeVersion7(path_);
  RunSql(path_,
         "ALTER TABLE jobs DROP COLUMN owner; ALTER TABLE analyses DROP COLUMN latency_seconds;"
         "UPDATE schema_version SET version = 4;");
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  EXPECT_EQ((*store)->GetJob(job_id)->owner, "");
  JobRow again = SampleJob();
  again.owner = "bob";
  const std::string bob_id = (*store)->CreateJob(again)->id;
  EXPECT_EQ((*store)->GetJob(bob_id)->owner, "bob");
  EXPECT_EQ((*store)->ListJobs()->size(), 2u);
  store->reset();  // closes the database, which it holds locked
  EXPECT_EQ(SchemaVersionOf(path_), kSchemaVersion);
}

// A database written by the first release (schema version 1: analyses
// without gradient columns) opens, is migrated to the current version, keeps
// its analyses bit for bit (without gradients) and takes new ones with them.
TEST_F(StoreTest, VersionOneDatabaseIsMigratedKeepingItsAnalyses) {
  std::string job_id;
  jobs::AnalysisRecord old_row;
  std::string old_row_job;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    auto job = (*store)->CreateJob(SampleJob());
    ASSERT_TRUE(job.ok());
    job_id = job->id;
    old_row_job = job_id;
    old_row.request_id = 0;
    old_row.x_scaled = {1.0 / 3.0};
    old_row.objective_terms = AwkwardDoubles();
    old_row.constraint_values = {-0.0};
    ASSERT_TRUE((*store)->AddAnalysis(old_row_job, old_row).ok());
  }
  // Exactly the version 1 layout: the columns version 2 added are the last
  // three of `analyses`.
  UnpackValuesAsBeforeVersion7(path_);
  RunSql(path_,
         "ALTER TABLE analyses DROP COLUMN objective_gradients;"
         "ALTER TABLE analyses DROP COLUMN constraint_gradients;"
         "ALTER TABLE analyses DROP COLUMN gradients_unavailable;"
         "ALTER TABLE analyses DROP COLUMN failure_kind;"
         "DROP TABLE job_sequence;"
         "ALTER TABLE jobs DROP COLUMN owner;"
         "ALTER TABLE analyses DROP COLUMN latency_seconds;"
         "UPDATE schema_version SET version = 1;");
  ASSERT_EQ(SchemaVersionOf(path_), 1);

  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    auto rows = (*store)->LoadAnalyses(job_id);
    ASSERT_TRUE(rows.ok()) << rows.status();
    ASSERT_EQ(rows->size(), 1u);
    EXPECT_TRUE(BitIdentical((*rows)[0].objective_terms, old_row.objective_terms));
    EXPECT_TRUE(BitIdentical((*rows)[0].constraint_values, old_row.constraint_values));
    EXPECT_TRUE((*rows)[0].objective_gradients.empty());
    EXPECT_TRUE((*rows)[0].constraint_gradients.empty());
    EXPECT_EQ((*rows)[0].gradients_unavailable, "");
    jobs::AnalysisRecord with_gradients = old_row;
    with_gradients.request_id = 1;
    with_gradients.objective_gradients = {0.1, 0.2};
    ASSERT_TRUE((*store)->AddAnalysis(job_id, with_gradients).ok());
  }
  EXPECT_EQ(SchemaVersionOf(path_), kSchemaVersion);
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto rows = (*store)->LoadAnalyses(job_id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 2u);
  EXPECT_TRUE(BitIdentical((*rows)[1].objective_gradients, {0.1, 0.2}));
}

// A version 2 database (analyses without a failure kind) is migrated: its
// failed analyses become "unclassified", its successful ones stay ok.
TEST_F(StoreTest, VersionTwoFailuresBecomeUnclassified) {
  std::string job_id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    auto job = (*store)->CreateJob(SampleJob());
    ASSERT_TRUE(job.ok());
    job_id = job->id;
    jobs::AnalysisRecord ok;
    ok.request_id = 0;
    ok.objective_terms = {1.0};
    ASSERT_TRUE((*store)->AddAnalysis(job_id, ok).ok());
    jobs::AnalysisRecord failed;
    failed.request_id = 1;
    failed.failure = spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "integrator failed near t = 1");
    ASSERT_TRUE((*store)->AddAnalysis(job_id, failed).ok());
  }
  UnpackValuesAsBeforeVersion7(path_);
  RunSql(path_,
         "ALTER TABLE analyses DROP COLUMN failure_kind;"
         "DROP TABLE job_sequence;"
         "ALTER TABLE jobs DROP COLUMN owner;"
         "ALTER TABLE analyses DROP COLUMN latency_seconds;"
         "UPDATE schema_version SET version = 2;");
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto rows = (*store)->LoadAnalyses(job_id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 2u);
  EXPECT_TRUE((*rows)[0].ok());
  EXPECT_EQ((*rows)[1].failure.kind, spec::FailureKind::kUnclassified);
  EXPECT_EQ((*rows)[1].failure.reason, "integrator failed near t = 1");
}

TEST_F(StoreTest, FailureKindRoundTrips) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto job = (*store)->CreateJob(SampleJob());
  ASSERT_TRUE(job.ok());
  jobs::AnalysisRecord a;
  a.request_id = 4;
  a.failure = spec::AnalysisFailure::Of(spec::FailureKind::kAssembly, "joint B cannot close at t = 0.4 s");
  ASSERT_TRUE((*store)->AddAnalysis(job->id, a).ok());
  auto rows = (*store)->LoadAnalyses(job->id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 1u);
  EXPECT_EQ((*rows)[0].failure.kind, spec::FailureKind::kAssembly);
  EXPECT_EQ((*rows)[0].failure.reason, a.failure.reason);
}

// Each analysis names the token whose worker delivered it, and a job's
// analyses are counted by holder; a database of version 7 (before holders)
// opens, its analyses attributed to no token, and takes new ones with theirs.
TEST_F(StoreTest, AnalysesNameTheirTokenHolderAndVersionSevenRowsHaveNone) {
  std::string job_id;
  auto analysis = [](std::int64_t request_id, const std::string& holder) {
    jobs::AnalysisRecord a;
    a.request_id = request_id;
    a.x_scaled = {0.5};
    a.objective_terms = {1.0};
    a.worker = "w-1";
    a.holder = holder;
    return a;
  };
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok()) << store.status();
    job_id = (*store)->CreateJob(SampleJob())->id;
    ASSERT_TRUE((*store)->AddAnalysis(job_id, analysis(1, "rack1")).ok());
    ASSERT_TRUE((*store)->AddAnalysis(job_id, analysis(2, "rack2")).ok());
    ASSERT_TRUE((*store)->AddAnalysis(job_id, analysis(3, "rack1")).ok());
    EXPECT_EQ((*store)->LoadAnalyses(job_id)->at(1).holder, "rack2");
    absl::StatusOr<std::vector<AnalysesByHolder>> counts = (*store)->CountAnalysesByHolder(job_id);
    ASSERT_TRUE(counts.ok()) << counts.status();
    ASSERT_EQ(counts->size(), 2u);
    EXPECT_EQ((*counts)[0].holder, "rack1");
    EXPECT_EQ((*counts)[0].analyses, 2);
    EXPECT_EQ((*counts)[1].holder, "rack2");
    EXPECT_EQ((*counts)[1].analyses, 1);
  }
  // Exactly the version 7 layout.
  RunSql(path_, "ALTER TABLE analyses DROP COLUMN holder; UPDATE schema_version SET version = 7;");
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> rows = (*store)->LoadAnalyses(job_id);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 3u);
  for (const jobs::AnalysisRecord& row : *rows) EXPECT_EQ(row.holder, "") << row.request_id;
  ASSERT_TRUE((*store)->AddAnalysis(job_id, analysis(4, "rack3")).ok());
  absl::StatusOr<std::vector<AnalysesByHolder>> counts = (*store)->CountAnalysesByHolder(job_id);
  ASSERT_TRUE(counts.ok()) << counts.status();
  ASSERT_EQ(counts->size(), 2u);
  EXPECT_EQ((*counts)[0].holder, "");
  EXPECT_EQ((*counts)[0].analyses, 3);
  EXPECT_EQ((*counts)[1].holder, "rack3");
  EXPECT_EQ((*counts)[1].analyses, 1);
  store->reset();
  EXPECT_EQ(SchemaVersionOf(path_), kSchemaVersion);
}

TEST_F(StoreTest, NewDatabaseHasTheCurrentSchemaVersion) {
  { ASSERT_TRUE(Store::Open(path_).ok()); }
  EXPECT_EQ(SchemaVersionOf(path_), kSchemaVersion);
}

TEST_F(StoreTest, GarbageFileIsRefusedWithClearError) {
  {
    std::ofstream out(path_, std::ios::binary);
    for (int i = 0; i < 4096; ++i) out.put(static_cast<char>((i * 37 + 11) & 0xff));
  }
  auto store = Store::Open(path_);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(store.status().message()), HasSubstr("not a database"));
  EXPECT_THAT(std::string(store.status().message()), HasSubstr(path_));
}

TEST_F(StoreTest, ShortTextFileIsRefused) {
  { std::ofstream(path_) << "hello, I am a text file\n"; }
  auto store = Store::Open(path_);
  ASSERT_FALSE(store.ok());
  EXPECT_THAT(std::string(store.status().message()), HasSubstr(path_));
}

TEST_F(StoreTest, SqliteDatabaseOfAnotherApplicationIsRefused) {
  RunSql(path_, "CREATE TABLE customers(name TEXT)");
  auto store = Store::Open(path_);
  ASSERT_FALSE(store.ok());
  EXPECT_EQ(store.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(store.status().message()), HasSubstr("another application"));
}

TEST_F(StoreTest, UncommittedTransactionLeavesThePreviousState) {
  std::string job_id;
  {
    auto store = Store::Open(path_);
    ASSERT_TRUE(store.ok());
    auto job = (*store)->CreateJob(SampleJob());
    ASSERT_TRUE(job.ok());
    job_id = job->id;
    ASSERT_TRUE((*store)->CommitCycle(job_id, {{0, 1, 0, "first"}}, {"RUNNING", "", 1, 3, 0.1}).ok());
  }
  // Begin, write, close without commit.
  RunSql(path_, "BEGIN; INSERT INTO cycles(job_id, idx, cycle, attempt, record) VALUES ('" + job_id +
                    "', 1, 2, 0, x'00'); UPDATE jobs SET cycles = 2, records = 2;");
  // Begin, write, die without closing (a crash of the process).
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    sqlite3* db = nullptr;
    sqlite3_open(path_.c_str(), &db);
    sqlite3_exec(db, "BEGIN; UPDATE jobs SET state = 'CONVERGED', cycles = 9;", nullptr, nullptr, nullptr);
    ::_exit(0);
  }
  int wstatus = 0;
  ASSERT_EQ(::waitpid(child, &wstatus, 0), child);
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto job = (*store)->GetJob(job_id);
  ASSERT_TRUE(job.ok());
  EXPECT_EQ(job->state, "RUNNING");
  EXPECT_EQ(job->cycles, 1);
  EXPECT_EQ(job->records, 1);
  auto cycles = (*store)->LoadCycles(job_id);
  ASSERT_TRUE(cycles.ok());
  ASSERT_EQ(cycles->size(), 1u);
  EXPECT_EQ((*cycles)[0].record, "first");
}

TEST_F(StoreTest, CycleCommitOfUnknownJobChangesNothing) {
  auto store = Store::Open(path_);
  ASSERT_TRUE(store.ok());
  EXPECT_EQ((*store)->CommitCycle("job-9", {{0, 1, 0, "x"}}, {"RUNNING", "", 1, 1, 0}).code(),
            absl::StatusCode::kNotFound);
  auto cycles = (*store)->LoadCycles("job-9");
  ASSERT_TRUE(cycles.ok());
  EXPECT_TRUE(cycles->empty());
}

TEST_F(StoreTest, SecondOpenWhileTheFirstIsOpenIsRefused) {
  auto first = Store::Open(path_);
  ASSERT_TRUE(first.ok()) << first.status();
  auto second = Store::Open(path_);
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(std::string(second.status().message()), HasSubstr("another process"));
  first->reset();
  EXPECT_TRUE(Store::Open(path_).ok());
}

TEST_F(StoreTest, DurabilityLevelsSetTheSyncModeAndNamesRoundTrip) {
  for (const Durability d : {Durability::kFull, Durability::kCycles, Durability::kNormal}) {
    EXPECT_EQ(ParseDurability(DurabilityName(d)), d);
    {
      auto store = Store::Open(path_, d);
      ASSERT_TRUE(store.ok()) << store.status();
      ASSERT_TRUE((*store)->CreateJob(SampleJob()).ok());
    }
    auto reopened = Store::Open(path_, d);
    ASSERT_TRUE(reopened.ok()) << reopened.status();
    EXPECT_FALSE((*reopened)->ListJobs()->empty());
  }
  EXPECT_FALSE(ParseDurability("fast").has_value());
}

// Which commits are synced: at kCycles those with cycle records, not those
// of results alone; all at kFull, none at kNormal. Either way every row is
// there when the database is opened again.
TEST_F(StoreTest, CommitsWithCycleRecordsAreSyncedAtTheCyclesLevel) {
  for (const Durability d : {Durability::kFull, Durability::kCycles, Durability::kNormal}) {
    SCOPED_TRACE(DurabilityName(d));
    std::string job_id;
    {
      std::unique_ptr<Store> store = FreshStoreWithJob(d, &job_id);
      ASSERT_NE(store, nullptr);
      jobs::AnalysisRecord first;
      first.request_id = 0;
      first.objective_terms = AwkwardDoubles();
      ASSERT_TRUE(store->AddAnalysis(job_id, first).ok());
      jobs::AnalysisRecord second = first;
      second.request_id = 1;
      JobWrite with_cycle;
      with_cycle.job_id = job_id;
      with_cycle.analyses.push_back(&second);
      with_cycle.cycles.push_back(CycleRow{0, 1, 0, "record"});
      with_cycle.progress = JobProgress{"RUNNING", "", 1, 2, 0.5};
      ASSERT_TRUE(store->Commit(with_cycle).ok());
      EXPECT_EQ(store->AnalysisTransactions(), 2);
      EXPECT_EQ(store->SyncedTransactions(), d == Durability::kFull ? 2 : d == Durability::kCycles ? 1 : 0);
    }
    auto reopened = Store::Open(path_, d);
    ASSERT_TRUE(reopened.ok()) << reopened.status();
    EXPECT_EQ((*reopened)->LoadAnalyses(job_id)->size(), 2u);
    EXPECT_EQ((*reopened)->LoadCycles(job_id)->size(), 1u);
  }
}

// A write whose records the caller syncs later (the job manager's syncing
// thread) is not synced by its commit at the cycles level; SyncLog syncs the
// log, except at the normal level, which never syncs.
TEST_F(StoreTest, DeferredRecordsAreSyncedBySyncLogNotByTheirCommit) {
  for (const Durability d : {Durability::kFull, Durability::kCycles, Durability::kNormal}) {
    SCOPED_TRACE(DurabilityName(d));
    std::string job_id;
    {
      std::unique_ptr<Store> store = FreshStoreWithJob(d, &job_id);
      ASSERT_NE(store, nullptr);
      jobs::AnalysisRecord analysis;
      analysis.request_id = 0;
      analysis.objective_terms = AwkwardDoubles();
      JobWrite deferred;
      deferred.job_id = job_id;
      deferred.analyses.push_back(&analysis);
      deferred.cycles.push_back(CycleRow{0, 1, 0, "record"});
      deferred.progress = JobProgress{"RUNNING", "", 1, 1, 0.5};
      deferred.defer_sync = true;
      ASSERT_TRUE(store->Commit(deferred).ok());
      EXPECT_EQ(store->SyncedTransactions(), d == Durability::kFull ? 1 : 0);
      EXPECT_EQ(store->LogSyncs(), 0);
      ASSERT_TRUE(store->SyncLog().ok());
      EXPECT_EQ(store->LogSyncs(), d == Durability::kNormal ? 0 : 1);
    }
    auto reopened = Store::Open(path_, d);
    ASSERT_TRUE(reopened.ok()) << reopened.status();
    EXPECT_EQ((*reopened)->LoadCycles(job_id)->size(), 1u);
  }
}

// Group commit: results from many threads at once are all committed (each
// caller returns after its own row is in), a duplicate fails alone, and
// they share transactions.
TEST_F(StoreTest, ConcurrentAnalysesAreCommittedInGroups) {
  // Synced commits, so that commits take long enough for results to meet.
  auto store = Store::Open(path_, Durability::kFull);
  ASSERT_TRUE(store.ok()) << store.status();
  std::vector<std::string> job_ids;
  for (int j = 0; j < 4; ++j) {
    auto job = (*store)->CreateJob(SampleJob());
    ASSERT_TRUE(job.ok());
    job_ids.push_back(job->id);
  }
  constexpr int kThreads = 8, kPerThread = 40;
  std::atomic<int> failures{0}, duplicates{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kPerThread; ++i) {
        jobs::AnalysisRecord a;
        a.request_id = t * kPerThread + i;
        a.objective_terms = AwkwardDoubles();
        const std::string& job = job_ids[static_cast<size_t>(t % 4)];
        if (!(*store)->AddAnalysis(job, a).ok()) ++failures;
        // The same request again must fail, and fail alone.
        if (i % 10 == 0 && absl::IsAlreadyExists((*store)->AddAnalysis(job, a))) ++duplicates;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(duplicates.load(), kThreads * kPerThread / 10);
  std::size_t rows = 0;
  for (const std::string& job : job_ids) {
    auto analyses = (*store)->LoadAnalyses(job);
    ASSERT_TRUE(analyses.ok());
    for (const jobs::AnalysisRecord& a : *analyses) EXPECT_TRUE(BitIdentical(a.objective_terms, AwkwardDoubles()));
    rows += analyses->size();
  }
  EXPECT_EQ(rows, static_cast<std::size_t>(kThreads * kPerThread));
  const std::int64_t transactions = (*store)->AnalysisTransactions();
  EXPECT_LT(transactions, kThreads * kPerThread) << "results that arrive together share a transaction";
  std::cout << kThreads * kPerThread << " analyses (and " << kThreads * kPerThread / 10 << " duplicates) in "
            << transactions << " transactions\n";
}

TEST_F(StoreTest, DatabaseUsesWalJournal) {
  { ASSERT_TRUE(Store::Open(path_).ok()); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* stmt = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &stmt, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(stmt), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0)), "wal");
  sqlite3_finalize(stmt);
  sqlite3_close(db);
}

}  // namespace
}  // namespace mbopt::store
