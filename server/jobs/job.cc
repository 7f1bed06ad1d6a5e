#include "server/jobs/job.h"

#include <cmath>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/check.h"
#include "common/packed_doubles/packed_doubles.h"
#include "common/status_macros.h"
#include "server/jobs/analysis_gradients.h"
#include "server/jobs/problem_from_study.h"
#include "server/jobs/record_codec.h"

namespace mbopt::jobs {
namespace {

bool SameBits(const Eigen::VectorXd& a, const std::vector<double>& b) {
  return static_cast<size_t>(a.size()) == b.size() &&
         (b.empty() || std::memcmp(a.data(), b.data(), b.size() * sizeof(double)) == 0);
}

Eigen::VectorXd ToEigen(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// "" when every value is finite, else which one is not.
std::string FirstNonFinite(const char* what, const std::vector<double>& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return absl::StrCat(what, " ", i, " is ", values[i]);
  }
  return "";
}

// A worker's packed values into the record's vectors, at most as many as the
// study has (so a hostile packing cannot make the server allocate more). The
// packed bytes stay: the store logs them as they came.
absl::Status UnpackOne(const char* what, size_t expected, const std::string& packed_values,
                       std::vector<double>& values) {
  if (packed_values.empty()) return absl::OkStatus();
  if (!values.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("result has its ", what, " both packed and unpacked"));
  }
  absl::StatusOr<std::vector<double>> unpacked = packed::UnpackDoubles(packed_values, expected);
  if (!unpacked.ok()) return absl::InvalidArgumentError(absl::StrCat(what, ": ", unpacked.status().message()));
  values = *std::move(unpacked);
  return absl::OkStatus();
}

absl::Status UnpackValues(size_t terms, size_t rows, AnalysisRecord& record) {
  MBOPT_RETURN_IF_ERROR(UnpackOne("objective terms", terms, record.objective_terms_packed, record.objective_terms));
  return UnpackOne("constraint values", rows, record.constraint_values_packed, record.constraint_values);
}

// The optimizer's view of a record: live delivery and replay give it exactly
// this, so a resumed job sees what the first run saw.
slp::AnalysisResult ResultOf(const AnalysisRecord& record, const slp::ProblemSpec& problem) {
  slp::AnalysisResult result;
  result.request_id = record.request_id;
  result.outcome = record.ok() ? slp::AnalysisOutcome::kOk : slp::AnalysisOutcome::kFailed;
  result.failure_reason = record.failure.reason;
  if (record.ok()) {
    result.objective_terms = ToEigen(record.objective_terms);
    result.constraint_values = ToEigen(record.constraint_values);
    AttachGradients(problem, record.objective_gradients, record.constraint_gradients, &result);
  }
  return result;
}

// Whether a front's log was written before its points' runs logged their
// cycles: it holds a point whose run has cycles, and none of them. (A log
// of points whose runs have no cycles, failed at their first analysis, is
// the same either way, and goes on with them.)
bool LogLacksRunCycles(const std::vector<std::string>& logged_records) {
  bool point_with_cycles = false;
  for (const std::string& bytes : logged_records) {
    absl::StatusOr<slp::CycleRecord> record = DecodeCycleRecord(bytes);
    if (!record.ok()) continue;  // the replay's comparison names it
    if (record->pareto_point > 0) return false;
    point_with_cycles |= record->pareto && record->pareto_cycles > 0;
  }
  return point_with_cycles;
}

}  // namespace

absl::StatusOr<std::unique_ptr<Job>> Job::Create(spec::Study study, std::unique_ptr<lp::LpSolver> lp_solver,
                                                 std::optional<slp::SlpOptions> options) {
  return Create(std::make_shared<const spec::Study>(std::move(study)), std::move(lp_solver), std::move(options));
}

absl::StatusOr<std::unique_ptr<Job>> Job::Create(std::shared_ptr<const spec::Study> study,
                                                 std::unique_ptr<lp::LpSolver> lp_solver,
                                                 std::optional<slp::SlpOptions> options) {
  MBOPT_CHECK(study != nullptr, "Job::Create needs a study");
  if (study->pareto.enabled()) {
    return absl::InvalidArgumentError(absl::StrCat(
        study->name, " asks for a Pareto front, which needs an LP solver for each point's run: create its job "
                     "with an LP solver factory"));
  }
  return CreateWith(std::move(study), std::move(lp_solver), nullptr, std::move(options));
}

absl::StatusOr<std::unique_ptr<Job>> Job::Create(std::shared_ptr<const spec::Study> study,
                                                 const LpSolverFactory& make_lp_solver,
                                                 std::optional<slp::SlpOptions> options) {
  MBOPT_CHECK(study != nullptr && make_lp_solver, "Job::Create needs a study and an LP solver factory");
  return CreateWith(std::move(study), make_lp_solver(), make_lp_solver, std::move(options));
}

absl::StatusOr<std::unique_ptr<Job>> Job::CreateWith(std::shared_ptr<const spec::Study> study,
                                                     std::unique_ptr<lp::LpSolver> lp_solver,
                                                     const LpSolverFactory& make_lp_solver,
                                                     std::optional<slp::SlpOptions> options) {
  MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(*study));
  MBOPT_ASSIGN_OR_RETURN(slp::ProblemSpec problem, ProblemSpecFromStudy(*study, layout));
  slp::SlpOptions settings;
  if (options.has_value()) {
    settings = *options;
    MBOPT_RETURN_IF_ERROR(settings.Validate());
  } else {
    MBOPT_ASSIGN_OR_RETURN(settings, SlpOptionsFromStudy(*study));
  }
  std::unique_ptr<DesignSetRun> design_set;
  if (!study->design_set.empty()) {
    std::vector<Eigen::VectorXd> designs;
    for (const std::vector<double>& x : spec::DesignSetPoints(*study)) designs.push_back(ToEigen(x));
    std::vector<int> row_constraints;
    row_constraints.reserve(layout.rows.size());
    for (const spec::ConstraintRow& row : layout.rows) row_constraints.push_back(row.constraint);
    design_set = std::make_unique<DesignSetRun>(problem, std::move(designs), std::move(row_constraints),
                                                static_cast<int>(study->constraints.size()));
  }
  std::unique_ptr<FrontRun> pareto;
  if (study->pareto.three_objectives()) {
    ParetoGridSetup setup;
    setup.problem = problem;
    setup.options = settings;
    for (const spec::ConstraintRow& row : layout.rows) setup.row_constraints.push_back(row.constraint);
    setup.num_constraints = static_cast<int>(study->constraints.size());
    setup.traded_constraints = {study->pareto.constraint, study->pareto.third_constraint};
    setup.levels = study->pareto.points;
    absl::StatusOr<std::unique_ptr<ParetoGridRun>> made = ParetoGridRun::Create(std::move(setup), make_lp_solver);
    if (!made.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(study->source_file, ": pareto: ", made.status().message()));
    }
    pareto = *std::move(made);
  } else if (study->pareto.enabled()) {
    ParetoSetup setup;
    setup.problem = problem;
    setup.options = settings;
    for (const spec::ConstraintRow& row : layout.rows) setup.row_constraints.push_back(row.constraint);
    setup.num_constraints = static_cast<int>(study->constraints.size());
    if (study->pareto.trades_objective) {
      setup.traded_constraint = spec::kSecondObjectiveRow;
      setup.traded_factors = layout.second_objective_factors;
      setup.traded_sum = layout.second_objective_sums;
    } else {
      setup.traded_constraint = study->pareto.constraint;
    }
    setup.points = study->pareto.points;
    setup.refine = study->pareto.refine;
    setup.refine_again = study->pareto.refine_again;
    absl::StatusOr<std::unique_ptr<ParetoRun>> made = ParetoRun::Create(std::move(setup), make_lp_solver);
    if (!made.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(study->source_file, ": pareto: ", made.status().message()));
    }
    pareto = *std::move(made);
  }
  auto optimizer = std::make_unique<slp::SlpOptimizer>(std::move(problem), settings, std::move(lp_solver));
  std::unique_ptr<Job> job(new Job(std::move(study), std::make_shared<const spec::StudyLayout>(std::move(layout)),
                                   settings, std::move(optimizer)));
  job->design_set_ = std::move(design_set);
  job->pareto_ = std::move(pareto);
  return job;
}

JobState Job::state() const {
  if (pareto_ != nullptr) return pareto_->done() ? JobState::kCompleted : JobState::kRunning;
  if (design_set_ == nullptr) return JobStateOf(optimizer_->state());
  return design_set_->done() ? JobState::kCompleted : JobState::kRunning;
}

int Job::cycles_completed() const {
  if (pareto_ != nullptr) return pareto_->points_done();
  return design_set_ == nullptr ? optimizer_->cycles_completed() : static_cast<int>(design_set_->designs_done());
}

std::int64_t Job::analyses_used() const {
  if (pareto_ != nullptr) return pareto_->analyses_used();
  return design_set_ == nullptr ? optimizer_->analyses_used() : design_set_->analyses_used();
}

std::string Job::end_reason() const { return is_design_set() ? "" : optimizer_->end_reason(); }

std::vector<std::string> Job::result_notes() const {
  return is_design_set() ? std::vector<std::string>{} : optimizer_->result_notes();
}

std::vector<slp::AnalysisRequest> Job::PendingRequests() const {
  if (pareto_ != nullptr) return pareto_->PendingRequests();
  return design_set_ == nullptr ? optimizer_->PendingRequests() : design_set_->PendingRequests();
}

bool Job::IsPending(std::int64_t request_id) const {
  if (pareto_ != nullptr) return pareto_->IsPending(request_id);
  return design_set_ == nullptr ? optimizer_->IsPending(request_id) : design_set_->IsPending(request_id);
}

absl::StatusOr<std::unique_ptr<Job>> Job::CreateForProblem(slp::ProblemSpec problem, slp::SlpOptions options,
                                                           std::unique_ptr<lp::LpSolver> lp_solver) {
  MBOPT_RETURN_IF_ERROR(problem.Validate());
  MBOPT_RETURN_IF_ERROR(options.Validate());
  auto optimizer = std::make_unique<slp::SlpOptimizer>(std::move(problem), options, std::move(lp_solver));
  return std::unique_ptr<Job>(
      new Job(std::make_shared<const spec::Study>(), std::make_shared<const spec::StudyLayout>(), options,
              std::move(optimizer)));
}

Job::Job(std::shared_ptr<const spec::Study> study, std::shared_ptr<const spec::StudyLayout> layout,
         slp::SlpOptions options, std::unique_ptr<slp::SlpOptimizer> optimizer)
    : study_(std::move(study)),
      layout_(std::move(layout)),
      options_(options),
      optimizer_(std::move(optimizer)) {}

absl::StatusOr<AnalysisRecord> Job::Intake(AnalysisRecord candidate) const {
  const std::vector<slp::AnalysisRequest> pending = PendingRequests();
  const slp::AnalysisRequest* request = nullptr;
  for (const slp::AnalysisRequest& r : pending) {
    if (r.id == candidate.request_id) request = &r;
  }
  if (request == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("request ", candidate.request_id, " is not pending in ", study_->name));
  }
  AnalysisRecord record = std::move(candidate);
  record.x_scaled.assign(request->x.data(), request->x.data() + request->x.size());
  const slp::ProblemSpec& problem = optimizer_->spec();
  if (record.ok()) {
    const size_t terms = static_cast<size_t>(problem.num_objective_terms);
    const size_t rows = static_cast<size_t>(problem.num_constraints());
    MBOPT_RETURN_IF_ERROR(UnpackValues(terms, rows, record));
    if (record.objective_terms.size() != terms || record.constraint_values.size() != rows) {
      return absl::InvalidArgumentError(absl::StrCat("result of request ", record.request_id, " has ",
                                                     record.objective_terms.size(), " objective terms and ",
                                                     record.constraint_values.size(), " constraint values; ",
                                                     study_->name, " needs ", terms, " and ", rows));
    }
    std::string non_finite = FirstNonFinite("objective term", record.objective_terms);
    if (non_finite.empty()) non_finite = FirstNonFinite("constraint value", record.constraint_values);
    if (!non_finite.empty()) {
      record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue,
                                                 absl::StrCat("non-finite result: ", non_finite));
    }
  }
  if (!record.ok()) {
    if (record.failure.reason.empty()) record.failure.reason = "the analysis failed";
    record.objective_terms.clear();
    record.constraint_values.clear();
    record.objective_terms_packed.clear();
    record.constraint_values_packed.clear();
    record.objective_gradients.clear();
    record.constraint_gradients.clear();
    record.gradients_unavailable.clear();
    return record;
  }
  if (!request->want_gradients) {
    record.objective_gradients.clear();
    record.constraint_gradients.clear();
    record.gradients_unavailable.clear();
    return record;
  }
  // Logged as the optimizer will get them: unusable gradients are none.
  const std::string defect = GradientDefect(problem, record.objective_gradients, record.constraint_gradients);
  if (!defect.empty()) {
    record.gradients_unavailable = absl::StrCat("unusable gradients: ", defect);
    record.objective_gradients.clear();
    record.constraint_gradients.clear();
  } else if (record.objective_gradients.empty()) {
    if (record.gradients_unavailable.empty()) record.gradients_unavailable = "no gradients were sent";
    record.constraint_gradients.clear();
  } else {
    record.gradients_unavailable.clear();
  }
  return record;
}

absl::StatusOr<std::vector<slp::CycleRecord>> Job::Apply(const AnalysisRecord& record) {
  if (pareto_ != nullptr) {
    MBOPT_RETURN_IF_ERROR(pareto_->Submit(record));
  } else if (design_set_ != nullptr) {
    MBOPT_RETURN_IF_ERROR(design_set_->Submit(record));
  } else {
    MBOPT_RETURN_IF_ERROR(optimizer_->SubmitResult(ResultOf(record, optimizer_->spec())));
  }
  if (!record.ok()) {
    ++failures_by_kind_[record.failure.kind];
    last_failure_ = record.failure;
  }
  if (pareto_ != nullptr) return pareto_->TakeNewRecords();
  return design_set_ != nullptr ? design_set_->TakeNewRecords() : optimizer_->TakeNewRecords();
}

absl::StatusOr<std::vector<slp::CycleRecord>> Job::Replay(const std::vector<AnalysisRecord>& logged,
                                                          const std::vector<std::string>& logged_records) {
  if (pareto_ != nullptr) pareto_->LogRunCycles(!LogLacksRunCycles(logged_records));
  std::map<std::int64_t, const AnalysisRecord*> by_id;
  for (const AnalysisRecord& a : logged) by_id[a.request_id] = &a;
  size_t next_record = 0;
  std::vector<slp::CycleRecord> unlogged;
  size_t used = 0;
  // One result at a time, re-asking the optimizer each time: a result that
  // completes a batch changes what is pending.
  while (true) {
    const AnalysisRecord* next = nullptr;
    const std::vector<slp::AnalysisRequest> pending = PendingRequests();
    const slp::AnalysisRequest* request = nullptr;
    for (const slp::AnalysisRequest& r : pending) {
      auto found = by_id.find(r.id);
      if (found != by_id.end()) {
        next = found->second;
        request = &r;
        break;
      }
    }
    if (next == nullptr) break;
    if (!SameBits(request->x, next->x_scaled)) {
      return absl::DataLossError(absl::StrCat(
          "replay of ", study_->name, ": request ", request->id,
          " asks for a different design point than the logged analysis; the optimizer is not "
          "deterministic or the database comes from another build"));
    }
    MBOPT_ASSIGN_OR_RETURN(std::vector<slp::CycleRecord> records, Apply(*next));
    ++used;
    for (slp::CycleRecord& record : records) {
      if (next_record < logged_records.size()) {
        if (EncodeCycleRecord(record) != logged_records[next_record]) {
          return absl::DataLossError(absl::StrCat("replay of ", study_->name, ": cycle record ", next_record,
                                                  " (cycle ", record.cycle, ", attempt ", record.attempt,
                                                  ") differs from the logged one; the optimizer is not "
                                                  "deterministic or the database comes from another build"));
        }
      } else {
        unlogged.push_back(std::move(record));
      }
      ++next_record;
    }
  }
  if (next_record < logged_records.size()) {
    return absl::DataLossError(absl::StrCat("replay of ", study_->name, " produced ", next_record,
                                            " cycle records but the log holds ", logged_records.size()));
  }
  if (used != logged.size()) {
    return absl::DataLossError(absl::StrCat("replay of ", study_->name, " used ", used, " of ", logged.size(),
                                            " logged analyses; the others were never asked for"));
  }
  return unlogged;
}

absl::Status Job::Run(Evaluator& evaluator, const JobRunOptions& options) {
  while (running()) {
    const std::vector<slp::AnalysisRequest> pending = PendingRequests();
    if (pending.empty()) return absl::InternalError("the optimizer is running but requests no analysis");
    if (analyses_used() + static_cast<std::int64_t>(pending.size()) > options.max_analyses) {
      return absl::ResourceExhaustedError(
          absl::StrCat(study_->name.empty() ? "the run" : study_->name, " needs more than ", options.max_analyses,
                       " analyses"));
    }
    std::vector<AnalysisRecord> batch = evaluator.Evaluate(pending);
    if (batch.size() != pending.size()) {
      return absl::InvalidArgumentError(absl::StrCat("the evaluator answered ", batch.size(), " of ",
                                                     pending.size(), " requests"));
    }
    if (options.reorder_batch) options.reorder_batch(batch);
    for (AnalysisRecord& candidate : batch) {
      MBOPT_ASSIGN_OR_RETURN(AnalysisRecord record, Intake(std::move(candidate)));
      if (options.on_analysis) options.on_analysis(record);
      MBOPT_ASSIGN_OR_RETURN(std::vector<slp::CycleRecord> records, Apply(record));
      if (options.on_record) {
        for (const slp::CycleRecord& r : records) options.on_record(r);
      }
    }
  }
  return absl::OkStatus();
}

std::vector<double> Job::PhysicalDesign(const Eigen::VectorXd& x_scaled) const {
  std::vector<double> design(static_cast<size_t>(x_scaled.size()));
  for (Eigen::Index i = 0; i < x_scaled.size() && static_cast<size_t>(i) < study_->variables.size(); ++i) {
    design[static_cast<size_t>(i)] = study_->variables[static_cast<size_t>(i)].scale * x_scaled[i];
  }
  return design;
}

}  // namespace mbopt::jobs
