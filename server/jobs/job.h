// One optimization: a study (or, for analytic test problems, a bare
// problem), its layout, and the SLP optimizer that runs it; or, for a study
// with a design set (a sweep or sample), the DesignSetRun that analyses its
// designs in the optimizer's place (design_set_run.h); or, for a study with
// a Pareto front, the ParetoRun (or, of three objectives, ParetoGridRun) of
// its points' SLP runs (pareto_run.h, pareto_grid_run.h);
// all behind the same calls. The Job is the only thing that drives the SLP core, in one of two
// ways that share every step that matters:
//  - Run(evaluator): the job asks, the evaluator answers each batch, and the
//    job goes on until the optimizer ends (in-process runs, tests, tools);
//  - the service's job manager asks PendingRequests(), hands them to the
//    scheduler, and gives each worker's result to Intake() and Apply() as
//    it arrives, logging in between.
// Either way a result is validated once, at Intake (shapes, finiteness,
// gradients), into the AnalysisRecord that is logged and replayed; Apply
// turns it into the core's AnalysisResult in one place. The LP solver is
// injected, so a job can be tested with a fake one.
//
// A Job does no I/O and takes no locks (the owner serializes calls).
//
// Resume: a fresh Job is given the logged records (Replay). It hands them to
// the optimizer in the order the optimizer asks for them, which rebuilds the
// optimizer's state bit for bit, and compares each cycle record the
// optimizer emits again with the logged one. Afterwards only analyses not in
// the log are pending.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/jobs/analysis_record.h"
#include "server/jobs/design_set_run.h"
#include "server/jobs/evaluator.h"
#include "server/jobs/job_state.h"
#include "server/jobs/pareto_grid_run.h"
#include "server/jobs/pareto_run.h"
#include "server/lp/linear_program.h"
#include "server/slp/slp_optimizer.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::jobs {

struct JobRunOptions {
  // Guard against a run that never ends: ResourceExhausted past this.
  std::int64_t max_analyses = 100'000;
  // Called with every record after intake, before the optimizer sees it
  // (where the service logs it).
  std::function<void(const AnalysisRecord&)> on_analysis;
  // Called with every cycle record as soon as the optimizer emits it.
  std::function<void(const slp::CycleRecord&)> on_record;
  // Permutes each batch of records before they are applied: results of a
  // batch may arrive in any order (tests use this to prove it).
  std::function<void(std::vector<AnalysisRecord>&)> reorder_batch;
};

class Job {
 public:
  // A study's job with the study's optimizer settings, or with `options`
  // replacing them. InvalidArgument (naming the study's file and field) when
  // the study cannot be laid out or gives an invalid problem or settings.
  static absl::StatusOr<std::unique_ptr<Job>> Create(spec::Study study, std::unique_ptr<lp::LpSolver> lp_solver,
                                                     std::optional<slp::SlpOptions> options = std::nullopt);
  // The same for a study that its holder shares with the job (the job
  // manager keeps one decoded copy of each study, not one per run).
  static absl::StatusOr<std::unique_ptr<Job>> Create(std::shared_ptr<const spec::Study> study,
                                                     std::unique_ptr<lp::LpSolver> lp_solver,
                                                     std::optional<slp::SlpOptions> options = std::nullopt);
  // The same with an LP solver made for each SLP run: a study with a Pareto
  // front has one run per point (the two calls above refuse such a study).
  static absl::StatusOr<std::unique_ptr<Job>> Create(std::shared_ptr<const spec::Study> study,
                                                     const LpSolverFactory& make_lp_solver,
                                                     std::optional<slp::SlpOptions> options = std::nullopt);
  // A job for a problem that has no study (analytic problems in tests).
  static absl::StatusOr<std::unique_ptr<Job>> CreateForProblem(slp::ProblemSpec problem, slp::SlpOptions options,
                                                               std::unique_ptr<lp::LpSolver> lp_solver);

  const spec::Study& study() const { return *study_; }
  const spec::StudyLayout& layout() const { return *layout_; }
  // The same layout, for holders that outlive the job (the job manager's
  // views): shared, never copied, since its rows' names are most of a large
  // study's memory.
  std::shared_ptr<const spec::StudyLayout> shared_layout() const { return layout_; }
  const slp::ProblemSpec& problem() const { return optimizer_->spec(); }
  const slp::SlpOptions& options() const { return options_; }
  // The SLP core; for a design set it is made but never driven (what the
  // job tells goes through the calls below, which know both).
  const slp::SlpOptimizer& optimizer() const { return *optimizer_; }
  // Whether the job's records are designs, one each (a sweep, a sample or
  // the points of a Pareto front) rather than an optimizer's cycles.
  bool is_design_set() const { return design_set_ != nullptr || pareto_ != nullptr; }
  bool is_pareto() const { return pareto_ != nullptr; }
  bool running() const { return state() == JobState::kRunning; }
  // kRunning, or how the run ended (a design set: kCompleted).
  JobState state() const;
  // SLP cycles completed; a design set's designs whose records are out.
  int cycles_completed() const;
  std::int64_t analyses_used() const;
  // Why a stalled run stopped, and what the user should know of its result.
  std::string end_reason() const;
  std::vector<std::string> result_notes() const;

  std::vector<slp::AnalysisRequest> PendingRequests() const;
  bool IsPending(std::int64_t request_id) const;

  // Validates a candidate record for a pending request into the record to
  // log and apply: x_scaled is the request's; a failed record loses its
  // values and gets a reason if it had none; values that are NaN or
  // infinite make it a kNonFiniteValue failure naming the first one;
  // gradients the request did not ask for are dropped, and gradients that do
  // not fit (size, non-finite) become none with the reason in
  // gradients_unavailable. InvalidArgument for a request that is not
  // pending or values of the wrong size (the reporter's defect, not the
  // design's).
  absl::StatusOr<AnalysisRecord> Intake(AnalysisRecord candidate) const;

  // Hands one record (from Intake, or from the log) to the optimizer and
  // returns the cycle records it emitted. InvalidArgument for an unknown or
  // answered request.
  absl::StatusOr<std::vector<slp::CycleRecord>> Apply(const AnalysisRecord& record);

  // Replays `logged` (any order; each applied when the optimizer asks for
  // its request id) and checks the re-emitted records against
  // `logged_records` (encoded, record_codec.h). Returns the records emitted
  // beyond the logged ones (a crash between an analysis commit and its cycle
  // commit leaves those): the caller logs them now. DataLoss if a logged
  // design point or record differs from what the optimizer produces now
  // (non-determinism, or a database from another build), or if the log
  // holds more records than the replay produces.
  absl::StatusOr<std::vector<slp::CycleRecord>> Replay(const std::vector<AnalysisRecord>& logged,
                                                       const std::vector<std::string>& logged_records);

  // Drives the optimizer to its end with `evaluator`. Whatever state the
  // optimizer ends in is OK; InvalidArgument when the evaluator's records do
  // not fit the requests, ResourceExhausted past options.max_analyses.
  absl::Status Run(Evaluator& evaluator, const JobRunOptions& options = {});

  // Failed analyses applied so far (replayed ones included), by kind, and
  // the latest one.
  const std::map<spec::FailureKind, std::int64_t>& failures_by_kind() const { return failures_by_kind_; }
  const spec::AnalysisFailure& last_failure() const { return last_failure_; }

  // Physical design values (parameter value = scale * x, in the parameter's
  // unit) of a scaled design.
  std::vector<double> PhysicalDesign(const Eigen::VectorXd& x_scaled) const;

 private:
  Job(std::shared_ptr<const spec::Study> study, std::shared_ptr<const spec::StudyLayout> layout,
      slp::SlpOptions options, std::unique_ptr<slp::SlpOptimizer> optimizer);
  // `lp_solver` for the optimizer of the study's problem; `make_lp_solver`
  // (null unless the study has a Pareto front) for the runs of its points.
  static absl::StatusOr<std::unique_ptr<Job>> CreateWith(std::shared_ptr<const spec::Study> study,
                                                         std::unique_ptr<lp::LpSolver> lp_solver,
                                                         const LpSolverFactory& make_lp_solver,
                                                         std::optional<slp::SlpOptions> options);

  std::shared_ptr<const spec::Study> study_;  // never null
  std::shared_ptr<const spec::StudyLayout> layout_;
  slp::SlpOptions options_;
  std::unique_ptr<slp::SlpOptimizer> optimizer_;
  std::unique_ptr<DesignSetRun> design_set_;  // null: an optimization
  std::unique_ptr<FrontRun> pareto_;         // null: not a Pareto front
  std::map<spec::FailureKind, std::int64_t> failures_by_kind_;
  spec::AnalysisFailure last_failure_;
};

}  // namespace mbopt::jobs
