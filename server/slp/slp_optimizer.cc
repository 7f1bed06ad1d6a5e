#include "server/slp/slp_optimizer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/check.h"
#include "server/slp/best_design.h"
#include "server/slp/cycle_lp.h"
#include "server/slp/finite_difference.h"
#include "server/slp/move_limit_strategy.h"

namespace mbopt::slp {

const char* RunStateName(RunState state) {
  switch (state) {
    case RunState::kRunning:
      return "running";
    case RunState::kConverged:
      return "converged";
    case RunState::kMaxCycles:
      return "max_cycles";
    case RunState::kStalled:
      return "stalled";
    case RunState::kFailed:
      return "failed";
  }
  return "unknown";
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A step counts as on its move limit within this fraction of the half-width
// (LP vertices sit on the limit up to rounding).
constexpr double kActivityRelativeTolerance = 1e-6;

// The values of one successful analysis and what the core derives from them.
struct PointValues {
  Eigen::VectorXd terms;
  Eigen::VectorXd constraints;
  double objective = 0;      // F = max_j f_j
  double max_violation = 0;  // maxg; 0 without constraints
  int worst_constraint = -1;
};

PointValues MakePointValues(const ProblemSpec& spec, const AnalysisResult& r) {
  PointValues v;
  v.terms = r.objective_terms;
  v.constraints = r.constraint_values;
  v.objective = ObjectiveValue(v.terms);
  for (int h = 0; h < spec.num_constraints(); ++h) {
    const double g =
        (v.constraints[h] - spec.constraint_limits[h]) / spec.constraint_scales[h];
    if (v.worst_constraint < 0 || g > v.max_violation) {
      v.max_violation = g;
      v.worst_constraint = h;
    }
  }
  return v;
}

Eigen::VectorXd Stack(const AnalysisResult& r) {
  Eigen::VectorXd v(r.objective_terms.size() + r.constraint_values.size());
  v << r.objective_terms, r.constraint_values;
  return v;
}

}  // namespace

class SlpOptimizer::Impl {
 public:
  Impl(ProblemSpec spec, SlpOptions options, std::unique_ptr<lp::LpSolver> lp_solver)
      : spec_(std::move(spec)),
        options_(options),
        lp_solver_(std::move(lp_solver)),
        best_(options_.convergence_violation_tolerance) {
    MBOPT_CHECK(spec_.Validate().ok(), "invalid ProblemSpec (call Validate first)");
    MBOPT_CHECK(options_.Validate().ok(), "invalid SlpOptions (call Validate first)");
    MBOPT_CHECK(lp_solver_ != nullptr, "no LP solver");
    const int n = spec_.num_variables();
    x0_ = spec_.initial;
    move_limits_ = Eigen::VectorXd::Constant(n, options_.initial_move_limit);
    cycle_ = 1;
    phase_ = Phase::kStartAndPerturb;
    start_request_id_ = Request(RequestPurpose::kCycleStart, -1, 0.0, x0_);
    if (!options_.analyses_provide_gradients) PlanPerturbations();
  }

  std::vector<AnalysisRequest> PendingRequests() const {
    std::vector<AnalysisRequest> out;
    for (const auto& [id, req] : outstanding_) out.push_back(req);
    return out;
  }
  bool IsPending(std::int64_t request_id) const { return outstanding_.count(request_id) != 0; }

  absl::Status SubmitResult(const AnalysisResult& result) {
    auto it = outstanding_.find(result.request_id);
    if (it == outstanding_.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat("analysis result for request ", result.request_id,
                       " which is not pending (unknown or already answered)"));
    }
    AnalysisResult stored = result;
    if (stored.outcome == AnalysisOutcome::kOk) {
      if (stored.objective_terms.size() != spec_.num_objective_terms ||
          stored.constraint_values.size() != spec_.num_constraints()) {
        return absl::InvalidArgumentError(absl::StrCat(
            "analysis result for request ", result.request_id, " has ",
            stored.objective_terms.size(), " objective terms and ",
            stored.constraint_values.size(), " constraint values; expected ",
            spec_.num_objective_terms, " and ", spec_.num_constraints()));
      }
      if (!stored.objective_terms.allFinite() || !stored.constraint_values.allFinite()) {
        stored.outcome = AnalysisOutcome::kFailed;
        stored.failure_reason = "non-finite value in the analysis result";
      }
      if (stored.has_gradients()) {
        const int n = spec_.num_variables();
        if (stored.objective_gradients.rows() != spec_.num_objective_terms ||
            stored.objective_gradients.cols() != n ||
            stored.constraint_gradients.rows() != spec_.num_constraints() ||
            (stored.constraint_gradients.size() > 0 && stored.constraint_gradients.cols() != n)) {
          return absl::InvalidArgumentError(absl::StrCat(
              "analysis result for request ", result.request_id, " has gradients of shape ",
              stored.objective_gradients.rows(), "x", stored.objective_gradients.cols(), " and ",
              stored.constraint_gradients.rows(), "x", stored.constraint_gradients.cols(),
              "; expected ", spec_.num_objective_terms, "x", n, " and ",
              spec_.num_constraints(), "x", n));
        }
        if (!stored.objective_gradients.allFinite() || !stored.constraint_gradients.allFinite()) {
          // Unusable, not a failed analysis: the values are fine.
          stored.objective_gradients.resize(0, 0);
          stored.constraint_gradients.resize(0, 0);
        }
      }
    }
    if (stored.outcome != AnalysisOutcome::kOk) {
      stored.objective_terms.resize(0);
      stored.constraint_values.resize(0);
      stored.objective_gradients.resize(0, 0);
      stored.constraint_gradients.resize(0, 0);
    }
    outstanding_.erase(it);
    received_.emplace(stored.request_id, std::move(stored));
    ++analyses_used_;
    if (outstanding_.empty()) ProcessBatch();
    return absl::OkStatus();
  }

  std::vector<CycleRecord> TakeNewRecords() { return std::exchange(new_records_, {}); }

  RunState state() const { return state_; }
  const std::string& end_reason() const { return failure_reason_; }
  const Eigen::VectorXd& current_design() const { return x0_; }
  double current_objective() const { return have_x0_ ? v0_.objective : kNaN; }
  double current_max_violation() const { return have_x0_ ? v0_.max_violation : kNaN; }
  DesignPoint best_design() const {
    if (best_.best().has_value()) return *best_.best();
    return DesignPoint{x0_, current_objective(), current_max_violation()};
  }
  int cycles_completed() const { return cycles_completed_; }
  std::int64_t analyses_used() const { return analyses_used_; }
  const ProblemSpec& spec() const { return spec_; }

 private:
  enum class Phase { kStartAndPerturb, kPerturb, kTrial };

  struct Perturbation {
    std::vector<Sample> samples;         // successful ones
    std::vector<double> failed_steps;    // in request order
    std::vector<std::int64_t> request_ids;
    bool retried = false;
  };

  std::int64_t Request(RequestPurpose purpose, int variable, double step,
                       const Eigen::VectorXd& x) {
    AnalysisRequest r;
    r.id = next_id_++;
    r.cycle = cycle_;
    r.purpose = purpose;
    r.perturbed_variable = variable;
    r.perturbation_step = step;
    r.x = x;
    r.want_gradients = options_.analyses_provide_gradients && purpose != RequestPurpose::kPerturbation;
    outstanding_.emplace(r.id, r);
    batch_.emplace(r.id, std::move(r));
    return batch_.rbegin()->first;
  }

  void RequestPerturbation(int i, double step) {
    Eigen::VectorXd x = x0_;
    x[i] += step;
    const std::int64_t id = Request(RequestPurpose::kPerturbation, i, step, x);
    perturbations_[i].request_ids.push_back(id);
  }

  void PlanPerturbations() {
    const int n = spec_.num_variables();
    perturbations_.assign(n, Perturbation{});
    for (int i = 0; i < n; ++i) {
      for (double step : PlanSteps(x0_[i], spec_.lower[i], spec_.upper[i], options_)) {
        RequestPerturbation(i, step);
      }
    }
  }

  // Called when every request of the current batch has an answer. Results are
  // taken in id order, whatever order they arrived in.
  void ProcessBatch() {
    std::map<std::int64_t, AnalysisRequest> requests = std::exchange(batch_, {});
    std::map<std::int64_t, AnalysisResult> results = std::exchange(received_, {});
    switch (phase_) {
      case Phase::kStartAndPerturb: {
        const AnalysisResult& start = results.at(start_request_id_);
        if (start.outcome != AnalysisOutcome::kOk) {
          state_ = RunState::kFailed;
          failure_reason_ = "analysis of the initial design failed: " + start.failure_reason;
          return;
        }
        v0_ = MakePointValues(spec_, start);
        have_x0_ = true;
        if (options_.analyses_provide_gradients) {
          StartCycleFrom(start);
          return;
        }
        CollectPerturbations(requests, results);
        return;
      }
      case Phase::kPerturb:
        CollectPerturbations(requests, results);
        return;
      case Phase::kTrial: {
        MBOPT_CHECK(results.size() == 1, "a trial batch has one analysis");
        EvaluateTrial(&results.begin()->second);
        return;
      }
    }
  }

  void CollectPerturbations(const std::map<std::int64_t, AnalysisRequest>& requests,
                            const std::map<std::int64_t, AnalysisResult>& results) {
    for (const auto& [id, result] : results) {
      const AnalysisRequest& req = requests.at(id);
      if (req.purpose != RequestPurpose::kPerturbation) continue;
      Perturbation& p = perturbations_[req.perturbed_variable];
      if (result.outcome == AnalysisOutcome::kOk) {
        p.samples.push_back(Sample{req.perturbation_step, Stack(result)});
      } else {
        p.failed_steps.push_back(req.perturbation_step);
      }
    }
    // Variables without a usable sample get one retry on the other side.
    bool retrying = false;
    for (int i = 0; i < spec_.num_variables(); ++i) {
      Perturbation& p = perturbations_[i];
      if (!p.samples.empty() || p.retried) continue;
      MBOPT_CHECK(!p.failed_steps.empty(), "perturbation without outcome");
      p.retried = true;
      RequestPerturbation(i, RetryStep(x0_[i], spec_.lower[i], spec_.upper[i],
                                       p.failed_steps.front()));
      retrying = true;
    }
    if (retrying) {
      phase_ = Phase::kPerturb;
      return;
    }
    BuildLinearization();
    attempt_ = 0;
    SolveAndRequestTrial();
  }

  // With analyses_provide_gradients: the cycle's linearization from x0's
  // own gradients, or finite differences when it brought none.
  void StartCycleFrom(const AnalysisResult& x0_result) {
    if (!x0_result.has_gradients()) {
      phase_ = Phase::kPerturb;
      PlanPerturbations();
      return;
    }
    const int n = spec_.num_variables();
    lin_.x0 = x0_;
    lin_.terms0 = v0_.terms;
    lin_.constraints0 = v0_.constraints;
    lin_.terms_gradient = x0_result.objective_gradients;
    lin_.constraints_gradient = x0_result.constraint_gradients;
    if (lin_.constraints_gradient.size() == 0) {
      lin_.constraints_gradient = Eigen::MatrixXd::Zero(spec_.num_constraints(), n);
    }
    lin_.frozen.assign(n, false);
    attempt_ = 0;
    SolveAndRequestTrial();
  }

  void BuildLinearization() {
    const int n = spec_.num_variables();
    const int k = spec_.num_objective_terms;
    const int m = spec_.num_constraints();
    lin_.x0 = x0_;
    lin_.terms0 = v0_.terms;
    lin_.constraints0 = v0_.constraints;
    lin_.terms_gradient = Eigen::MatrixXd::Zero(k, n);
    lin_.constraints_gradient = Eigen::MatrixXd::Zero(m, n);
    lin_.frozen.assign(n, false);
    Eigen::VectorXd values0(k + m);
    values0 << v0_.terms, v0_.constraints;
    for (int i = 0; i < n; ++i) {
      const std::optional<Eigen::VectorXd> d =
          DerivativeFromSamples(values0, perturbations_[i].samples);
      if (!d.has_value()) {
        // No trustworthy derivative: hold the variable rather than guess.
        lin_.frozen[i] = true;
        continue;
      }
      lin_.terms_gradient.col(i) = d->head(k);
      lin_.constraints_gradient.col(i) = d->tail(m);
    }
  }

  // A feasible design at or below the user's objective target.
  bool MeetsObjectiveTarget(const PointValues& v) const {
    return options_.objective_target.has_value() && v.objective <= *options_.objective_target &&
           v.max_violation < options_.convergence_violation_tolerance;
  }
  bool AnyFrozen() const {
    return std::find(lin_.frozen.begin(), lin_.frozen.end(), true) != lin_.frozen.end();
  }
  bool AllFrozen() const {
    return std::find(lin_.frozen.begin(), lin_.frozen.end(), false) == lin_.frozen.end();
  }

  CycleRecord NewRecord() const {
    CycleRecord r;
    r.cycle = cycle_;
    r.attempt = attempt_;
    r.x0 = x0_;
    r.objective_x0 = v0_.objective;
    r.max_violation_x0 = v0_.max_violation;
    r.move_limits = move_limits_;
    return r;
  }

  void Emit(CycleRecord record) {
    best_.OfferRecord(record);
    new_records_.push_back(std::move(record));
  }

  void Stall(const std::string& why) {
    state_ = RunState::kStalled;
    failure_reason_ = why;
  }

  // Solves this attempt's LP and asks for the analysis of its optimum. An LP
  // that fails even cold is recorded as a rejection with smaller move limits.
  void SolveAndRequestTrial() {
    if (AllFrozen()) {
      Stall("no variable has a usable finite-difference derivative");
      return;
    }
    while (true) {
      const MoveBox box = ComputeMoveBox(spec_, options_, x0_, move_limits_, lin_.frozen);
      cycle_lp_ = BuildCycleLp(spec_, options_, lin_, box);
      box_ = box;
      lp::LpSolution sol = lp_solver_->Solve(cycle_lp_.lp);
      if (sol.status != lp::LpStatus::kOptimal) {
        lp_solver_->ResetWarmStart();
        sol = lp_solver_->Solve(cycle_lp_.lp);
      }
      lp_solution_ = sol;
      if (sol.status == lp::LpStatus::kOptimal) break;

      CycleRecord r = NewRecord();
      r.accepted = false;
      r.rejection_reason = absl::StrCat("LP not solved: ", lp::LpStatusName(sol.status),
                                        sol.message.empty() ? "" : ": ", sol.message);
      r.x_trial = x0_;
      r.objective_trial = kNaN;
      r.objective_predicted = kNaN;
      r.max_violation_trial = kNaN;
      r.optimality_residual = kNaN;
      r.lp_status = lp::LpStatusName(sol.status);
      r.lp_iterations = sol.iterations;
      r.rows_screened_in = static_cast<int>(cycle_lp_.kept_constraints.size());
      MoveLimitInput in;
      in.trial_failed = true;
      in.move_limits = move_limits_;
      const MoveLimitDecision decision = ApplyMoveLimitStrategy(options_, in);
      move_limits_ = decision.move_limits_next;
      r.move_limits_next = move_limits_;
      r.on_move_limit.assign(spec_.num_variables(), false);
      r.on_bound.assign(spec_.num_variables(), false);
      r.analyses_total = analyses_used_;
      Emit(std::move(r));
      if (!NextAttempt()) return;
    }

    const int n = spec_.num_variables();
    Eigen::VectorXd x_trial(n);
    for (int i = 0; i < n; ++i) {
      const double xi = lin_.frozen[i] ? x0_[i] : x0_[i] + lp_solution_.x[i];
      x_trial[i] = std::clamp(xi, spec_.lower[i], spec_.upper[i]);
    }
    x_trial_ = x_trial;
    phase_ = Phase::kTrial;
    if (x_trial == x0_) {
      // The LP does not move: x0's analysis is the trial's.
      AnalysisResult same;
      same.outcome = AnalysisOutcome::kOk;
      same.objective_terms = v0_.terms;
      same.constraint_values = v0_.constraints;
      if (options_.analyses_provide_gradients && !AnyFrozen()) {
        same.objective_gradients = lin_.terms_gradient;
        same.constraint_gradients = lin_.constraints_gradient;
      }
      EvaluateTrial(&same);
      return;
    }
    Request(RequestPurpose::kTrial, -1, 0.0, x_trial);
  }

  // After a rejection: false (and the run stalls) when the cycle has used up
  // its rejections or the move limits cannot shrink any further.
  bool NextAttempt() {
    ++attempt_;
    if (attempt_ >= options_.max_rejections_per_cycle) {
      Stall(absl::StrCat(attempt_, " trial points of cycle ", cycle_, " rejected"));
      return false;
    }
    if ((move_limits_.array() <= options_.min_move_limit).all() &&
        previous_rejection_at_min_) {
      Stall("move limits collapsed to min_move_limit");
      return false;
    }
    previous_rejection_at_min_ = (move_limits_.array() <= options_.min_move_limit).all();
    return true;
  }

  void EvaluateTrial(AnalysisResult* result) {
    const int n = spec_.num_variables();
    const lp::LpSolution& sol = lp_solution_;
    const Eigen::VectorXd d = x_trial_ - x0_;

    CycleRecord r = NewRecord();
    r.x_trial = x_trial_;
    r.lp_status = lp::LpStatusName(sol.status);
    r.lp_iterations = sol.iterations;
    r.rows_screened_in = static_cast<int>(cycle_lp_.kept_constraints.size());
    r.infeasibility = sol.x[cycle_lp_.s_column];
    r.lp_feasible = r.infeasibility <= options_.infeasibility_tolerance;
    r.optimality_residual = OptimalityResidual(spec_, options_, lin_, box_, cycle_lp_, sol);
    r.on_move_limit.assign(n, false);
    r.on_bound.assign(n, false);
    for (int i = 0; i < n; ++i) {
      const double w = box_.half_width[i];
      r.on_move_limit[i] = w > 0 && std::abs(d[i]) >= w * (1 - kActivityRelativeTolerance);
      const double tol = kActivityRelativeTolerance * std::max(w, 1e-12 * (spec_.upper[i] -
                                                                          spec_.lower[i]));
      r.on_bound[i] =
          x_trial_[i] <= spec_.lower[i] + tol || x_trial_[i] >= spec_.upper[i] - tol;
    }
    // Linear predictions at x*.
    double predicted = -std::numeric_limits<double>::infinity();
    for (int j : cycle_lp_.kept_terms) {
      predicted = std::max(predicted, lin_.terms0[j] + lin_.terms_gradient.row(j).dot(d));
    }
    r.objective_predicted = predicted;

    MoveLimitInput in;
    in.move_limits = move_limits_;
    in.lp_feasible = r.lp_feasible;
    in.objective_x0 = v0_.objective;
    in.previous_objective_change = dF_old_;
    in.dx_new = d;
    in.dx_old = dx_old_;
    in.on_move_limit = r.on_move_limit;
    in.on_bound = r.on_bound;

    PointValues trial;
    if (result->outcome != AnalysisOutcome::kOk) {
      in.trial_failed = true;
      r.objective_trial = kNaN;
      r.max_violation_trial = kNaN;
      r.objective_error = kNaN;
      r.max_approximation_error = kNaN;
    } else {
      trial = MakePointValues(spec_, *result);
      r.objective_trial = trial.objective;
      r.max_violation_trial = trial.max_violation;
      r.worst_constraint_trial = trial.worst_constraint;
      r.objective_error = std::abs(predicted - trial.objective) /
                          std::max(std::abs(trial.objective), options_.objective_magnitude_floor);
      r.max_approximation_error = r.objective_error;
      r.worst_approximation_row = -1;
      // Every constraint counts, screened in or not, so that screening
      // changes only the LP's size and never the strategy's decisions.
      for (int h = 0; h < spec_.num_constraints(); ++h) {
        const double g_pred =
            lin_.constraints0[h] + lin_.constraints_gradient.row(h).dot(d);
        const double g = trial.constraints[h];
        const double denom = std::max({std::abs(g), std::abs(spec_.constraint_limits[h]),
                                       spec_.constraint_scales[h]});
        const double e = std::abs(g_pred - g) / denom;
        if (e > r.max_approximation_error) {
          r.max_approximation_error = e;
          r.worst_approximation_row = h;
        }
      }
      in.max_approximation_error = r.max_approximation_error;
      in.max_violation = trial.max_violation;
      in.objective_trial = trial.objective;
    }
    MoveLimitDecision decision = ApplyMoveLimitStrategy(options_, in);
    // A feasible trial that meets the user's objective target ends the run
    // whatever the strategy thinks of its approximation: the run has what
    // was asked for.
    if (!in.trial_failed && MeetsObjectiveTarget(trial)) {
      decision.accept = true;
      decision.rejection_reason.clear();
    }
    r.accepted = decision.accept;
    r.rejection_reason = decision.rejection_reason;
    if (in.trial_failed) {
      r.rejection_reason =
          absl::StrCat("trial analysis failed: ", result->failure_reason);
    }
    move_limits_ = decision.move_limits_next;
    r.move_limits_next = move_limits_;
    r.analyses_total = analyses_used_;

    if (!decision.accept) {
      Emit(std::move(r));
      if (NextAttempt()) SolveAndRequestTrial();
      return;
    }

    // Accepted: x* becomes the next x0.
    const double relative_change = RelativeObjectiveChange(
        v0_.objective, trial.objective, options_.objective_magnitude_floor);
    const bool converged = MeetsObjectiveTarget(trial) ||
                           (relative_change < options_.convergence_objective_tolerance &&
                            trial.max_violation < options_.convergence_violation_tolerance &&
                            r.optimality_residual < options_.convergence_optimality_tolerance && !AnyFrozen());
    dx_old_ = d;
    dF_old_ = trial.objective - v0_.objective;
    x0_ = x_trial_;
    v0_ = trial;
    ++cycles_completed_;
    previous_rejection_at_min_ = false;
    r.converged = converged;
    Emit(std::move(r));
    if (converged) {
      state_ = RunState::kConverged;
      return;
    }
    if (cycle_ >= options_.max_cycles) {
      state_ = RunState::kMaxCycles;
      return;
    }
    ++cycle_;
    attempt_ = 0;
    if (options_.analyses_provide_gradients) {
      StartCycleFrom(*result);
      return;
    }
    phase_ = Phase::kPerturb;
    PlanPerturbations();
  }

  ProblemSpec spec_;
  SlpOptions options_;
  std::unique_ptr<lp::LpSolver> lp_solver_;

  RunState state_ = RunState::kRunning;
  std::string failure_reason_;
  std::int64_t next_id_ = 0;
  std::int64_t analyses_used_ = 0;
  std::map<std::int64_t, AnalysisRequest> outstanding_;  // asked, not answered
  std::map<std::int64_t, AnalysisRequest> batch_;        // every request of the batch
  std::map<std::int64_t, AnalysisResult> received_;      // answers of the batch
  std::vector<CycleRecord> new_records_;
  BestDesign best_;

  Phase phase_ = Phase::kStartAndPerturb;
  int cycle_ = 1;
  int attempt_ = 0;
  int cycles_completed_ = 0;
  std::int64_t start_request_id_ = -1;
  bool previous_rejection_at_min_ = false;

  Eigen::VectorXd x0_;
  PointValues v0_;
  bool have_x0_ = false;
  Eigen::VectorXd move_limits_;
  std::vector<Perturbation> perturbations_;
  Linearization lin_;

  MoveBox box_;
  CycleLp cycle_lp_;
  lp::LpSolution lp_solution_;
  Eigen::VectorXd x_trial_;

  Eigen::VectorXd dx_old_;        // empty before the first accepted cycle
  std::optional<double> dF_old_;  // likewise
};

SlpOptimizer::SlpOptimizer(ProblemSpec spec, SlpOptions options,
                           std::unique_ptr<lp::LpSolver> lp_solver)
    : impl_(std::make_unique<Impl>(std::move(spec), options, std::move(lp_solver))) {}
SlpOptimizer::~SlpOptimizer() = default;

std::vector<AnalysisRequest> SlpOptimizer::PendingRequests() const {
  return impl_->PendingRequests();
}
bool SlpOptimizer::IsPending(std::int64_t request_id) const { return impl_->IsPending(request_id); }
absl::Status SlpOptimizer::SubmitResult(const AnalysisResult& result) {
  return impl_->SubmitResult(result);
}
std::vector<CycleRecord> SlpOptimizer::TakeNewRecords() { return impl_->TakeNewRecords(); }
RunState SlpOptimizer::state() const { return impl_->state(); }
const std::string& SlpOptimizer::end_reason() const { return impl_->end_reason(); }
const Eigen::VectorXd& SlpOptimizer::current_design() const { return impl_->current_design(); }
double SlpOptimizer::current_objective() const { return impl_->current_objective(); }
double SlpOptimizer::current_max_violation() const { return impl_->current_max_violation(); }
DesignPoint SlpOptimizer::best_design() const { return impl_->best_design(); }
int SlpOptimizer::cycles_completed() const { return impl_->cycles_completed(); }
std::int64_t SlpOptimizer::analyses_used() const { return impl_->analyses_used(); }
const ProblemSpec& SlpOptimizer::spec() const { return impl_->spec(); }

}  // namespace mbopt::slp
