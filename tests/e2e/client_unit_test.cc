// Unit tests of the CLI's and the worker's pure helpers: JSON writing,
// argument parsing, result formats, the server's readiness line, and the
// reconnection backoff.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <tuple>

#include <gtest/gtest.h>

#include "absl/strings/str_split.h"
#include "client/args.h"
#include "client/design_set_format.h"
#include "client/job_format.h"
#include "client/json_writer.h"
#include "client/local_cluster.h"
#include "client/pareto_format.h"
#include "worker/service/backoff.h"
#include "worker/service/batch_log_line.h"
#include "worker/service/result_size.h"

namespace mbopt {
namespace {

TEST(ResultSize, ResultOverTheServersLimitBecomesANamedServiceFailure) {
  v1::TaskResult result;
  result.set_task_id("job-1/0/1");
  result.set_job_id("job-1");
  result.set_request_id(0);
  result.set_ok(true);
  for (int i = 0; i < 200'000; ++i) result.add_constraint_values(0.5);  // 1.6 MB
  v1::TaskResult small = result;
  small.clear_constraint_values();
  EXPECT_FALSE(worker::FitResultToServerLimit(0, 0, &result)) << "no limit known";
  EXPECT_FALSE(worker::FitResultToServerLimit(4 << 20, 0, &result));
  EXPECT_TRUE(result.ok());
  EXPECT_FALSE(worker::FitResultToServerLimit(1 << 20, 0, &small));
  // Over the message limit but under the result limit: it goes in pieces.
  EXPECT_FALSE(worker::FitResultToServerLimit(1 << 20, 2 << 20, &result));
  EXPECT_FALSE(worker::FitsOneMessage(static_cast<std::int64_t>(result.ByteSizeLong()), 1 << 20));
  EXPECT_TRUE(worker::FitsOneMessage(static_cast<std::int64_t>(small.ByteSizeLong()), 1 << 20));
  EXPECT_TRUE(result.ok());
  v1::TaskResult over_pieces = result;
  ASSERT_TRUE(worker::FitResultToServerLimit(1 << 20, 1 << 20, &over_pieces));
  EXPECT_NE(over_pieces.failure_reason().find("more than the server takes (1.0 MB, mbopt-server --max-result-mb)"),
            std::string::npos)
      << over_pieces.failure_reason();
  // An older server takes no pieces: its message limit is the limit.
  ASSERT_TRUE(worker::FitResultToServerLimit(1 << 20, 0, &result));
  EXPECT_FALSE(result.ok());
  EXPECT_FALSE(result.retry()) << "another worker would send the same size";
  EXPECT_EQ(result.failure_kind(), v1::ANALYSIS_FAILURE_SERVICE);
  EXPECT_EQ(result.constraint_values_size(), 0);
  EXPECT_EQ(result.task_id(), "job-1/0/1");
  EXPECT_NE(result.failure_reason().find("the result is 1.5 MB, more than the server takes (1.0 MB"),
            std::string::npos)
      << result.failure_reason();
}

// The worker's line per batch names the jobs once each, counts what failed
// and adds up the analyses' time.
TEST(BatchLogLine, NamesJobsCountsFailuresAndSumsAnalysisTime) {
  v1::TaskResults batch;
  for (const auto& [job, ok, seconds] : {std::tuple{"job-2", true, 0.5}, std::tuple{"job-1", false, 0.25},
                                         std::tuple{"job-2", true, 0.5}}) {
    v1::TaskResult* r = batch.add_results();
    r->set_job_id(job);
    r->set_ok(ok);
    r->mutable_counters()->set_wall_seconds(seconds);
  }
  EXPECT_EQ(worker::BatchLogLine(batch, 57), "job-2, job-1: 3 results delivered (2 ok, 1 failed), 1.25 s of analysis; 57 in all");
  batch.mutable_results()->DeleteSubrange(1, 2);
  EXPECT_EQ(worker::BatchLogLine(batch, 1), "job-2: 1 result delivered (1 ok), 0.50 s of analysis; 1 in all");
}

TEST(JsonWriter, WritesNestedDocumentsWithCommas) {
  client::JsonWriter w(0);
  w.BeginObject();
  w.Field("a", 1);
  w.Key("b");
  w.BeginArray();
  w.Number(0.5);
  w.String("x\"y");
  w.EndArray();
  w.Key("c");
  w.BeginObject();
  w.EndObject();
  w.EndObject();
  EXPECT_EQ(w.str(), R"({"a":1,"b":[0.5,"x\"y"],"c":{}})");
}

TEST(JsonWriter, DoublesRoundTripBitForBitAndNonFiniteIsNull) {
  const double third = 1.0 / 3.0;
  const std::string text = client::JsonWriter::FormatDouble(third);
  EXPECT_EQ(std::strtod(text.c_str(), nullptr), third);  // bit identity is the point
  EXPECT_EQ(client::JsonWriter::FormatDouble(std::numeric_limits<double>::quiet_NaN()), "null");
  EXPECT_EQ(client::JsonWriter::FormatDouble(INFINITY), "null");
}

TEST(JsonWriter, EscapesControlCharacters) {
  EXPECT_EQ(client::JsonWriter::Quote("a\nb\x01"), "\"a\\nb\\u0001\"");
}

TEST(ParseArgs, SeparatesPositionalOptionsAndFlags) {
  auto parsed = client::ParseArgs({"file.textproto", "--workers", "3", "--json", "--db=x.db"},
                                  {{"--workers", "--db"}, {"--json"}});
  ASSERT_TRUE(parsed.ok()) << parsed.status();
  EXPECT_EQ(parsed->positional, std::vector<std::string>{"file.textproto"});
  EXPECT_EQ(parsed->Value("--db"), "x.db");
  EXPECT_TRUE(parsed->Has("--json"));
  auto workers = parsed->IntValue("--workers", 1);
  ASSERT_TRUE(workers.ok());
  EXPECT_EQ(workers->value(), 3);
}

TEST(ParseArgs, RejectsUnknownOptionsMissingValuesAndBadIntegers) {
  EXPECT_FALSE(client::ParseArgs({"--bogus"}, {}).ok());
  EXPECT_FALSE(client::ParseArgs({"--workers"}, {{"--workers"}, {}}).ok());
  auto parsed = client::ParseArgs({"--workers", "0"}, {{"--workers"}, {}});
  ASSERT_TRUE(parsed.ok());
  EXPECT_FALSE(parsed->IntValue("--workers", 1).ok());
}

TEST(ReadinessLine, GivesTheAddress) {
  auto address = client::ParseListeningLine("mbopt-server listening on 127.0.0.1:40123");
  ASSERT_TRUE(address.ok());
  EXPECT_EQ(*address, "127.0.0.1:40123");
  EXPECT_FALSE(client::ParseListeningLine("error: cannot open db").ok());
}

v1::GetJobResponse SampleJob() {
  v1::GetJobResponse job;
  auto* s = job.mutable_summary();
  s->set_job_id("j1");
  s->set_state(v1::JOB_STATE_CONVERGED);
  s->set_cycles(2);
  s->set_objective(6.4);
  s->set_objective_unit("m/s^2");
  s->add_design_names("x1");
  s->add_design(5.0);
  s->add_design_units("lbf/in");
  for (int c = 1; c <= 2; ++c) {
    auto* rejected = job.add_cycles();
    rejected->set_cycle(c);
    rejected->set_accepted(false);
    auto* r = job.add_cycles();
    r->set_cycle(c);
    r->set_attempt(1);
    r->set_accepted(true);
    r->set_objective_trial(7.0 - c);
    r->add_move_limits(0.2);
    r->add_x_trial_physical(5.0);
  }
  return job;
}

TEST(ResultsJson, HistoryHoldsOnlyAcceptedCyclesAndDesignIsByName) {
  const std::string json = client::ResultsJson(SampleJob());
  EXPECT_NE(json.find("\"status\": \"converged\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"x1\": 5"), std::string::npos) << json;
  size_t entries = 0;
  for (auto p = json.find("\"attempts\""); p != std::string::npos; p = json.find("\"attempts\"", p + 1)) {
    ++entries;
  }
  EXPECT_EQ(entries, 2u) << json;
}

// Which worker tokens computed a job's analyses: named in the table and
// the JSON; analyses no token delivered (a server without tokens) are not.
TEST(ResultsTable, ComputedBySaysWhichWorkerTokensDeliveredTheAnalyses) {
  v1::GetJobResponse job = SampleJob();
  EXPECT_EQ(client::ResultsTable(job).find("computed by"), std::string::npos);
  v1::AnalysesByHolder* unattributed = job.add_computed_by();
  unattributed->set_analyses(4);
  EXPECT_EQ(client::ResultsTable(job).find("computed by"), std::string::npos) << "no token, no name";
  EXPECT_EQ(client::ResultsJson(job).find("computed_by"), std::string::npos);
  v1::AnalysesByHolder* rack1 = job.add_computed_by();
  rack1->set_holder("rack1");
  rack1->set_analyses(12);
  v1::AnalysesByHolder* rack2 = job.add_computed_by();
  rack2->set_holder("rack2");
  rack2->set_analyses(1);
  const std::string table = client::ResultsTable(job);
  EXPECT_NE(table.find("computed by:   rack1 (12 analyses), rack2 (1 analysis)\n"), std::string::npos) << table;
  const std::string json = client::ResultsJson(job);
  EXPECT_NE(json.find("\"computed_by\": {"), std::string::npos) << json;
  EXPECT_NE(json.find("\"rack1\": 12"), std::string::npos) << json;
  EXPECT_NE(json.find("\"rack2\": 1"), std::string::npos) << json;
}

// `mbopt workers` names the token each worker registered with.
TEST(WorkersTable, EachWorkerShowsItsToken) {
  EXPECT_NE(client::WorkersHeader().find(" TOKEN "), std::string::npos);
  v1::WorkerSummary worker;
  worker.set_id("w-3");
  worker.set_name("node07");
  worker.set_holder("rack1");
  EXPECT_NE(client::WorkersRow(worker).find("node07                   rack1 "), std::string::npos)
      << client::WorkersRow(worker);
  worker.clear_holder();
  EXPECT_NE(client::WorkersRow(worker).find("node07                   -  "), std::string::npos)
      << client::WorkersRow(worker);
  EXPECT_EQ(client::WorkersRow(worker).find("QUARANTINED"), std::string::npos);
  worker.set_quarantined(true);
  EXPECT_NE(client::WorkersRow(worker).find("QUARANTINED"), std::string::npos) << client::WorkersRow(worker);
}

TEST(ResultsCsv, OneRowPerLpSolveWithDesignColumns) {
  const std::string csv = client::ResultsCsv(SampleJob());
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);  // header + 4 records
  EXPECT_NE(csv.find(",x1\n"), std::string::npos) << csv;
}

TEST(JobState, ExitCodesFollowTheOutcome) {
  EXPECT_EQ(client::ExitCodeForState(v1::JOB_STATE_CONVERGED), 0);
  EXPECT_EQ(client::ExitCodeForState(v1::JOB_STATE_STALLED), 1);
  EXPECT_EQ(client::ExitCodeForState(v1::JOB_STATE_MAX_CYCLES), 1);
  EXPECT_EQ(client::ExitCodeForState(v1::JOB_STATE_FAILED), 4);
  EXPECT_EQ(client::StateName(v1::JOB_STATE_INTERRUPTED), "interrupted");
  EXPECT_EQ(client::ExitCodeForState(v1::JOB_STATE_COMPLETED), 0);
  EXPECT_EQ(client::StateName(v1::JOB_STATE_COMPLETED), "completed");
  EXPECT_TRUE(client::IsTerminal(v1::JOB_STATE_COMPLETED));
}

// `watch` ends with the job's outcome; a front's has its points and no F,
// which would be one point's among many.
TEST(WatchEndLine, AnOptimizationHasItsFAndAFrontItsPoints) {
  v1::JobSummary s;
  s.set_state(v1::JOB_STATE_CONVERGED);
  s.set_cycles(10);
  s.set_analyses(71);
  s.set_objective(6.389035698);
  s.set_objective_unit("m/s^2");
  s.set_max_violation(-0.06324);
  EXPECT_EQ(client::WatchEndLine("job-1", s),
            "job-1: converged after 10 cycles, 71 analyses, F = 6.389035698 m/s^2, max violation -0.06324\n");
  s.set_state(v1::JOB_STATE_COMPLETED);
  s.set_pareto(true);
  s.set_design_set(true);
  s.set_cycles(5);
  s.set_max_cycles(5);
  s.set_analyses(234);
  EXPECT_EQ(client::WatchEndLine("job-2", s),
            "job-2: completed after 5 of 5 points, 234 analyses; `mbopt results job-2` lists the front\n");
}

// A sweep of k over two designs, the second failed: every format lists both,
// the failed one without values and with its kind and reason.
v1::GetJobResponse TwoDesignSweep() {
  v1::GetJobResponse job;
  v1::SweepAxis* axis = job.mutable_study()->mutable_sweep()->add_axis();
  axis->set_variable("x1");
  job.mutable_study()->add_constraints()->set_name("travel");
  v1::DesignVariable* v = job.mutable_study()->add_variables();
  v->set_name("x1");
  v->set_parameter("k");
  v->set_scale(10);
  v1::JobSummary* s = job.mutable_summary();
  s->set_job_id("job-4");
  s->set_state(v1::JOB_STATE_COMPLETED);
  s->set_design_set(true);
  s->set_cycles(2);
  s->set_max_cycles(2);
  s->set_objective(1.5);
  s->set_objective_unit("m/s^2");
  s->add_design_names("x1");
  s->add_design_units("N/m");
  s->add_design(20);
  v1::CycleRecord* ok = job.add_cycles();
  ok->set_cycle(1);
  ok->set_design_set(true);
  ok->add_x_trial_scaled(2);
  ok->add_x_trial_physical(20);
  ok->set_objective_trial(1.5);
  ok->set_max_violation_trial(-0.25);
  ok->add_constraint_violations(-0.25);
  v1::CycleRecord* failed = job.add_cycles();
  failed->set_cycle(2);
  failed->set_design_set(true);
  failed->add_x_trial_scaled(3);
  failed->add_x_trial_physical(30);
  failed->set_objective_trial(std::numeric_limits<double>::quiet_NaN());
  failed->set_max_violation_trial(std::numeric_limits<double>::quiet_NaN());
  failed->add_constraint_violations(std::numeric_limits<double>::quiet_NaN());
  failed->set_failure_kind("integrator");
  failed->set_rejection_reason("step \"too\" small");
  return job;
}

TEST(DesignSetFormat, CsvHasOneRowPerDesignWithEmptyCellsForAFailure) {
  const v1::GetJobResponse job = TwoDesignSweep();
  ASSERT_TRUE(client::IsDesignSetJob(job));
  EXPECT_EQ(client::ResultsCsv(job),
            "design,x1,objective,max_violation,travel,status,failure_reason\n"
            "1,20,1.5,-0.25,-0.25,ok,\n"
            "2,30,,,,integrator,\"step \"\"too\"\" small\"\n");
}

TEST(DesignSetFormat, TableAndJsonListEveryDesign) {
  const v1::GetJobResponse job = TwoDesignSweep();
  const std::string table = client::ResultsTable(job);
  EXPECT_NE(table.find("designs:       2 of 2 analysed"), std::string::npos) << table;
  EXPECT_NE(table.find("best design:"), std::string::npos) << table;
  EXPECT_NE(table.find("x1 [N/m]"), std::string::npos) << table;
  EXPECT_NE(table.find("F [m/s^2]"), std::string::npos) << table;
  EXPECT_NE(table.find("-0.25   ok\n"), std::string::npos) << table;
  EXPECT_NE(table.find("-   integrator\n"), std::string::npos) << table;
  const std::string json = client::ResultsJson(job);
  EXPECT_NE(json.find("\"form\": \"sweep\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"designs_total\": 2"), std::string::npos) << json;
  EXPECT_NE(json.find("\"travel\": -0.25"), std::string::npos) << json;
  EXPECT_NE(json.find("\"travel\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"status\": \"integrator\""), std::string::npos) << json;
  EXPECT_EQ(json.find("\"history\""), std::string::npos) << "a sweep has no optimization history\n" << json;
  EXPECT_NE(client::DesignWatchRow(job.cycles(1)).find("integrator"), std::string::npos);
}

// A front of four points against "travel" (in mm): 1 and 4 the ends, 2
// dominated by 3 (worse in both), 3 on the front; or 2 infeasible.
v1::GetJobResponse FourPointFront(bool infeasible_second = false) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  v1::GetJobResponse job;
  job.mutable_study()->mutable_pareto()->add_against("travel");
  v1::Constraint* travel = job.mutable_study()->add_constraints();
  travel->set_name("travel");
  travel->set_unit("mm");
  job.mutable_study()->add_constraints()->set_name("stroke");
  v1::JobSummary* s = job.mutable_summary();
  s->set_job_id("job-5");
  s->set_state(v1::JOB_STATE_COMPLETED);
  s->set_design_set(true);
  s->set_pareto(true);
  s->set_cycles(4);
  s->set_max_cycles(4);
  s->set_objective_unit("m/s^2");
  s->add_design_names("x1");
  s->add_design_units("N/m");
  const double objective[] = {1.0, 1.6, 1.5, 2.0};
  const double value_m[] = {0.004, 0.003, 0.0025, 0.001};
  const double level_m[] = {kNaN, 0.003, 0.002, kNaN};
  for (int k = 0; k < 4; ++k) {
    v1::CycleRecord* r = job.add_cycles();
    r->set_cycle(k + 1);
    r->set_design_set(true);
    r->set_pareto(true);
    r->set_accepted(!(infeasible_second && k == 1));
    if (!r->accepted()) r->set_rejection_reason("no feasible design: maxg 0.2 at the best design");
    r->add_x_trial_physical(10.0 * (k + 1));
    r->set_objective_trial(objective[k]);
    r->set_max_violation_trial(r->accepted() ? -0.01 : 0.2);
    r->set_pareto_value_si(value_m[k]);
    r->set_pareto_level_si(level_m[k]);
    r->set_pareto_state("converged");
    r->set_pareto_cycles(3);
    r->add_constraint_violations(0.1);
    r->add_constraint_violations(-0.5);
  }
  return job;
}

TEST(ParetoFormat, CsvListsThePointsInTheConstraintsUnitWithDominanceDecided) {
  const v1::GetJobResponse job = FourPointFront();
  ASSERT_TRUE(client::IsParetoJob(job));
  EXPECT_EQ(client::ResultsCsv(job),
            "point,level,objective,travel,max_violation,run_state,cycles,analyses,x1,status,reason\n"
            "1,,1,4,-0.01,converged,3,0,10,front,\n"
            "2,3,1.6000000000000001,3,-0.01,converged,3,0,20,dominated,\n"
            "3,2,1.5,2.5,-0.01,converged,3,0,30,front,\n"
            "4,,2,1,-0.01,converged,3,0,40,front,\n");
}

TEST(ParetoFormat, AnInfeasiblePointIsNeitherOnTheFrontNorDominated) {
  const v1::GetJobResponse job = FourPointFront(/*infeasible_second=*/true);
  const std::string table = client::ResultsTable(job);
  EXPECT_NE(table.find("points:        4 of 4 on the Pareto front computed"), std::string::npos) << table;
  EXPECT_NE(table.find("level [mm]"), std::string::npos) << table;
  EXPECT_NE(table.find("travel [mm]"), std::string::npos) << table;
  EXPECT_NE(table.find("  infeasible\n"), std::string::npos) << table;
  EXPECT_EQ(table.find("dominated"), std::string::npos) << table;
  EXPECT_NE(table.find("point 2: no feasible design"), std::string::npos) << table;
}

TEST(ParetoFormat, OnePointInFullOrWhichPointsThereAre) {
  const v1::GetJobResponse job = FourPointFront();
  absl::StatusOr<std::string> point = client::ParetoPointText(job, 3);
  ASSERT_TRUE(point.ok()) << point.status();
  EXPECT_NE(point->find("point 3 of 4 (front)"), std::string::npos) << *point;
  EXPECT_NE(point->find("level:       travel <= 2 mm"), std::string::npos) << *point;
  EXPECT_NE(point->find("  stroke       -0.5"), std::string::npos) << *point;
  absl::StatusOr<std::string> json = client::ParetoPointJson(job, 3);
  ASSERT_TRUE(json.ok());
  EXPECT_NE(json->find("\"status\": \"front\""), std::string::npos) << *json;
  absl::StatusOr<std::string> missing = client::ParetoPointText(job, 5);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().message(), "--point 5: job job-5 has points 1 to 4 (of 4)");
}

// The same four points with the front's second objective a maximized
// output in mm (`pareto { objective { maximize: "x" unit: "mm" } }`): the
// records hold it as the runs minimize it, its negative, in its unit.
v1::GetJobResponse FourPointFrontOfAMaximizedValue() {
  v1::GetJobResponse job = FourPointFront();
  v1::Pareto* pareto = job.mutable_study()->mutable_pareto();
  pareto->clear_against();
  pareto->mutable_objective()->set_maximize("x");
  pareto->mutable_objective()->set_unit("mm");
  const double minimized[] = {-1.0, -2.5, -3.0, -4.0};
  const double level[] = {std::numeric_limits<double>::quiet_NaN(), -2.0, -3.5,
                          std::numeric_limits<double>::quiet_NaN()};
  for (int k = 0; k < 4; ++k) {
    job.mutable_cycles(k)->set_pareto_value_si(minimized[k]);
    job.mutable_cycles(k)->set_pareto_level_si(level[k]);
  }
  return job;
}

TEST(ParetoFormat, ASecondObjectiveIsNamedByWhatItIsAndAMaximizedOneShownAsItself) {
  const v1::GetJobResponse job = FourPointFrontOfAMaximizedValue();
  // Point 2 (F 1.6, x 2.5 mm) is beaten by point 3 (F 1.5, x 3 mm): the
  // larger x is the better one.
  EXPECT_EQ(client::ResultsCsv(job),
            "point,level,objective,second_objective,max_violation,run_state,cycles,analyses,x1,status,reason\n"
            "1,,1,1,-0.01,converged,3,0,10,front,\n"
            "2,2,1.6000000000000001,2.5,-0.01,converged,3,0,20,dominated,\n"
            "3,3.5,1.5,3,-0.01,converged,3,0,30,front,\n"
            "4,,2,4,-0.01,converged,3,0,40,front,\n");
  const std::string table = client::ResultsTable(job);
  EXPECT_NE(table.find("F2: x (maximized) [mm]"), std::string::npos) << table;
  absl::StatusOr<std::string> point = client::ParetoPointText(job, 3);
  ASSERT_TRUE(point.ok()) << point.status();
  EXPECT_NE(point->find("level:       F2: x (maximized) >= 3.5 mm"), std::string::npos) << *point;
  v1::Objective largest;
  largest.set_minimize_max_of("acc");
  largest.set_reduction(v1::REDUCTION_MAX_ABS);
  EXPECT_EQ(client::SecondObjectiveLabel(largest), "F2: max |acc|");
  v1::Objective sum;
  sum.mutable_minimize_sum()->add_terms()->set_output("x");
  sum.mutable_minimize_sum()->add_terms()->set_output("acc");
  EXPECT_EQ(client::SecondObjectiveLabel(sum), "F2: sum of 2 terms");
}

// A largest of terms may not state a unit of its own; when every term is
// taken in one unit and none is weighted, the front's columns carry it.
TEST(ParetoFormat, ALargestOfTermsInOneUnitIsShownInIt) {
  v1::Study study;
  v1::MaxOver* over = study.mutable_pareto()->mutable_objective()->mutable_minimize_max_over();
  for (const char* output : {"s2", "s3"}) {
    v1::WeightedTerm* t = over->add_terms();
    t->set_output(output);
    t->set_reduction(v1::REDUCTION_MAX_ABS);
    t->set_unit("in");
  }
  EXPECT_EQ(client::ShowSecondObjective(study).unit, "in");
  EXPECT_NE(client::ParetoWatchHeader(&study).find("F2: largest of 2 terms [in]"), std::string::npos)
      << client::ParetoWatchHeader(&study);
  over->mutable_terms(1)->set_weight(2.0);  // a weighted term: the largest is in no one unit
  EXPECT_EQ(client::ShowSecondObjective(study).unit, "");
  over->mutable_terms(1)->set_weight(0.0);
  over->mutable_terms(1)->set_unit("mm");
  EXPECT_EQ(client::ShowSecondObjective(study).unit, "");
}

// A point's run's cycle records (pareto_point set, just before the point's
// record) are its history: `--point K` lists them as a cycle table and the
// JSON has them per point; they are no points of the front.
TEST(ParetoFormat, APointListsItsRunsCyclesAndTheyAreNoPoints) {
  v1::GetJobResponse job = FourPointFront();
  v1::GetJobResponse with_history;
  *with_history.mutable_study() = job.study();
  with_history.mutable_study()->mutable_pareto()->set_points(4);
  *with_history.mutable_summary() = job.summary();
  for (const v1::CycleRecord& point : job.cycles()) {
    for (int cycle = 1; cycle <= 2; ++cycle) {
      v1::CycleRecord* r = with_history.add_cycles();
      r->set_pareto_point(point.cycle());
      r->set_cycle(cycle);
      r->set_accepted(true);
      r->set_objective_trial(10.0 * point.cycle() + cycle);
      r->set_analyses_total(7 * cycle);
    }
    *with_history.add_cycles() = point;
  }
  EXPECT_EQ(client::ResultsCsv(with_history), client::ResultsCsv(job));
  EXPECT_EQ(client::PointRunCycles(with_history, 3).size(), 2u);
  absl::StatusOr<std::string> text = client::ParetoPointText(with_history, 3);
  ASSERT_TRUE(text.ok()) << text.status();
  const size_t table = text->find("cycles of its run (F: the study's objective;");
  ASSERT_NE(table, std::string::npos) << *text;
  EXPECT_NE(text->find("           31", table), std::string::npos) << *text;
  EXPECT_NE(text->find("           32", table), std::string::npos) << *text;
  EXPECT_EQ(text->find("           21", table), std::string::npos) << *text;
  absl::StatusOr<std::string> far_end = client::ParetoPointText(with_history, 4);
  ASSERT_TRUE(far_end.ok());
  EXPECT_NE(far_end->find("cycles of its run (F: the second objective travel [mm], which the run optimizes"),
            std::string::npos)
      << *far_end;
  const std::string json = client::ResultsJson(with_history);
  EXPECT_NE(json.find("\"history\": ["), std::string::npos) << json;
  EXPECT_NE(json.find("\"objective\": 32"), std::string::npos) << json;
  // Without the runs' cycles (a front logged before them) a point has no table.
  absl::StatusOr<std::string> bare = client::ParetoPointText(job, 3);
  ASSERT_TRUE(bare.ok());
  EXPECT_EQ(bare->find("cycles of its run"), std::string::npos) << *bare;
}

// `mbopt watch` prints each point as it arrives: with the study, the
// second objective as the tables show it (a maximized one as itself, in
// its unit); without it, the records' raw values.
TEST(ParetoFormat, TheWatchShowsAMaximizedSecondObjectiveAsItself) {
  const v1::GetJobResponse job = FourPointFrontOfAMaximizedValue();
  const std::string header = client::ParetoWatchHeader(&job.study());
  EXPECT_NE(header.find("F2: x (maximized) [mm]"), std::string::npos) << header;
  EXPECT_NE(header.find("level [mm]"), std::string::npos) << header;
  const std::string row = client::ParetoWatchRow(job.cycles(1), &job.study());
  EXPECT_NE(row.find(" 2.5 "), std::string::npos) << row;
  EXPECT_NE(row.find(" 2 "), std::string::npos) << row;
  EXPECT_EQ(row.find("-2"), std::string::npos) << row;
  const std::string raw = client::ParetoWatchRow(job.cycles(1), nullptr);
  EXPECT_NE(raw.find("-2.5"), std::string::npos) << raw;
  EXPECT_NE(client::ParetoWatchHeader(nullptr).find("value (raw)"), std::string::npos);
  // A traded constraint's values in its unit (the records hold SI).
  const v1::GetJobResponse against = FourPointFront();
  const std::string in_mm = client::ParetoWatchRow(against.cycles(2), &against.study());
  EXPECT_NE(in_mm.find(" 2.5 "), std::string::npos) << in_mm;
  EXPECT_NE(client::ParetoWatchHeader(&against.study()).find("travel [mm]"), std::string::npos);
}

// A front of three objectives against "travel" and "reach" (both in mm):
// anchors 1 to 3, then grid points 4 to 6. Point 5 is beaten by point 4 in
// F and travel but not in reach, so it is on the front in 3-D; point 6 is
// beaten by point 4 in all three.
v1::GetJobResponse SixPointFrontOfThree() {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  v1::GetJobResponse job = FourPointFront();
  job.mutable_study()->mutable_pareto()->add_against("reach");
  v1::Constraint* reach = job.mutable_study()->add_constraints();
  reach->set_name("reach");
  reach->set_unit("mm");
  job.mutable_summary()->set_cycles(6);
  job.mutable_summary()->set_max_cycles(6);
  job.clear_cycles();
  const double objective[] = {1.0, 3.0, 3.0, 2.0, 2.5, 2.75};
  const double travel_mm[] = {4, 1, 3, 2, 2.5, 2.5};
  const double reach_mm[] = {4, 3, 1, 3.5, 2, 3.75};
  for (int k = 0; k < 6; ++k) {
    v1::CycleRecord* r = job.add_cycles();
    r->set_cycle(k + 1);
    r->set_design_set(true);
    r->set_pareto(true);
    r->set_pareto_three(true);
    r->set_accepted(true);
    r->add_x_trial_physical(10.0 * (k + 1));
    r->set_objective_trial(objective[k]);
    r->set_max_violation_trial(-0.01);
    r->set_pareto_value_si(travel_mm[k] / 1000);
    r->set_pareto_value3_si(reach_mm[k] / 1000);
    r->set_pareto_level_si(k < 3 ? kNaN : 0.0025);
    r->set_pareto_level3_si(k < 3 ? kNaN : 0.004);
    r->set_pareto_state("converged");
    r->set_pareto_cycles(3);
    for (int c = 0; c < 3; ++c) r->add_constraint_violations(-0.5);
  }
  return job;
}

TEST(ParetoFormat, AFrontOfThreeObjectivesListsBothValuesAndDecidesDominanceInThreeDimensions) {
  const v1::GetJobResponse job = SixPointFrontOfThree();
  const std::string csv = client::ResultsCsv(job);
  const std::vector<std::string> lines = absl::StrSplit(csv, '\n', absl::SkipEmpty());
  ASSERT_EQ(lines.size(), 7u) << csv;
  EXPECT_EQ(lines[0],
            "point,level,level3,objective,travel,reach,max_violation,run_state,cycles,analyses,x1,status,reason");
  EXPECT_EQ(lines[1], "1,,,1,4,4,-0.01,converged,3,0,10,front,");
  EXPECT_EQ(lines[4], "4,2.5,4,2,2,3.5,-0.01,converged,3,0,40,front,");
  EXPECT_EQ(lines[5], "5,2.5,4,2.5,2.5,2,-0.01,converged,3,0,50,front,");
  EXPECT_EQ(lines[6], "6,2.5,4,2.75,2.5,3.75,-0.01,converged,3,0,60,dominated,");
  const std::string table = client::ResultsTable(job);
  EXPECT_NE(table.find("level3 [mm]"), std::string::npos) << table;
  EXPECT_NE(table.find("reach [mm]"), std::string::npos) << table;
  EXPECT_NE(table.find("level, level3: the limits on travel and reach"), std::string::npos) << table;
  const std::string json = client::ResultsJson(job);
  EXPECT_NE(json.find("\"against3\": \"reach\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"value3\": 3.5"), std::string::npos) << json;
  absl::StatusOr<std::string> point = client::ParetoPointText(job, 5);
  ASSERT_TRUE(point.ok()) << point.status();
  EXPECT_NE(point->find("level3:      reach <= 4 mm"), std::string::npos) << *point;
  EXPECT_NE(point->find("reach:       2 mm"), std::string::npos) << *point;
  const std::string header = client::ParetoWatchHeader(&job.study());
  EXPECT_NE(header.find("reach [mm]"), std::string::npos) << header;
  const std::string row = client::ParetoWatchRow(job.cycles(3), &job.study());
  EXPECT_NE(row.find(" 3.5 "), std::string::npos) << row;
  EXPECT_TRUE(client::IsFarEnd(job.study(), 2));
  EXPECT_TRUE(client::IsFarEnd(job.study(), 3));
  EXPECT_FALSE(client::IsFarEnd(job.study(), 6));
}

TEST(Backoff, GrowsGeometricallyUpToTheCapWithBoundedJitter) {
  worker::BackoffOptions options;
  options.initial = std::chrono::milliseconds(100);
  options.max = std::chrono::milliseconds(1000);
  options.multiplier = 2.0;
  options.jitter = 0.5;
  worker::Backoff backoff(options, 42);
  const double expected_base_ms[] = {100, 200, 400, 800, 1000, 1000, 1000};
  for (double base : expected_base_ms) {
    const double ms = static_cast<double>(backoff.Next().count());
    EXPECT_GE(ms, 0.5 * base - 1) << base;  // 1 ms: rounding to whole milliseconds
    EXPECT_LE(ms, base + 1) << base;
  }
  backoff.Reset();
  EXPECT_LE(backoff.Next().count(), 101);
}

TEST(Backoff, SameSeedGivesSameDelays) {
  worker::Backoff a({}, 7), b({}, 7);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a.Next(), b.Next());
}

}  // namespace
}  // namespace mbopt
