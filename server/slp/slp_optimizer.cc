#include "server/slp/slp_optimizer.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "common/check.h"
#include "server/slp/best_design.h"
#include "server/slp/cycle_lp.h"
#include "server/slp/finite_difference.h"
#include "server/slp/flat_directions.h"
#include "server/slp/move_limit_strategy.h"
#include "server/slp/restoration_lp.h"

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
// Restoration steps after a converged design that violates a limit: each
// aims twice as far inside as the one before, from the same design, in a
// box twice as wide.
constexpr int kMaxRestorationSteps = 4;
// The first restoration step aims at least this far inside (normalized): a
// violation at the rounding level of the values (1e-16) would give a step
// that x cannot represent.
constexpr double kMinRestorationMargin = 1e-9;
// Locally infeasible: this many accepted cycles in a row whose LPs could not
// meet the linearized constraints, and the violation fell by less than this
// share of itself over them.
constexpr int kLocallyInfeasibleCycles = 6;
constexpr double kLocallyInfeasibleProgress = 0.01;
// Rows named in a message about violated constraints.
constexpr int kRowsNamed = 5;

// The values of one successful analysis and what the core derives from them.
struct PointValues {
  Eigen::VectorXd terms;
  Eigen::VectorXd constraints;
  double objective = 0;      // F (ObjectiveValue)
  double max_violation = 0;  // maxg; 0 without constraints
  int worst_constraint = -1;
};

PointValues MakePointValues(const ProblemSpec& spec, const AnalysisResult& r) {
  PointValues v;
  v.terms = r.objective_terms;
  v.constraints = r.constraint_values;
  v.objective = ObjectiveValue(spec, v.terms);
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

// A record whose trial point has no values (its analysis failed, or there
// was none): every measure of the trial is NaN.
void MarkTrialWithoutValues(CycleRecord* r) {
  r->objective_trial = kNaN;
  r->max_violation_trial = kNaN;
  r->objective_error = kNaN;
  r->max_approximation_error = kNaN;
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
        lp_solver_(std::move(lp_solver)) {
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
  const std::vector<std::string>& result_notes() const { return result_notes_; }
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
  enum class Phase { kStartAndPerturb, kPerturb, kTrial, kRestoration };

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
          End(RunState::kFailed, "analysis of the initial design failed: " + start.failure_reason);
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
      case Phase::kRestoration: {
        MBOPT_CHECK(results.size() == 1, "a restoration batch has one analysis");
        EvaluateRestoration(results.begin()->second);
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
           v.max_violation <= 0;
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

  // `x0_constraints` and `trial_constraints`: g_h at the record's x0 and
  // x_trial (empty when not analysed), so that the end notes can name the
  // violated rows of the best design without keeping every design's rows.
  void Emit(CycleRecord record, const Eigen::VectorXd& x0_constraints,
            const Eigen::VectorXd& trial_constraints) {
    switch (best_.OfferRecord(record)) {
      case BestDesign::Taken::kX0: best_violation_values_ = x0_constraints; break;
      case BestDesign::Taken::kTrial: best_violation_values_ = trial_constraints; break;
      case BestDesign::Taken::kNone: break;
    }
    new_records_.push_back(std::move(record));
  }

  void Stall(const std::string& why) { Finish(RunState::kStalled, why); }

  // The run would end in `state`. If its design x0 is a little outside a
  // limit (0 < maxg < convergence_violation_tolerance) and would be the
  // result but for that, it first takes restoration steps (section 7 of
  // docs/method.md); a converged x0 always does. `x0_result` brings x0's
  // own gradients when the analyses provide them.
  void Finish(RunState state, std::string reason = "",
              const AnalysisResult* x0_result = nullptr) {
    if (WantsRestoration(state)) {
      restoration_end_state_ = state;
      restoration_end_reason_ = std::move(reason);
      BeginRestoration(x0_result);
      return;
    }
    End(state, std::move(reason));
  }

  bool WantsRestoration(RunState state) const {
    if (spec_.num_constraints() == 0 || !have_x0_ || AllFrozen()) return false;
    if (!(v0_.max_violation > 0 &&
          v0_.max_violation < options_.convergence_violation_tolerance)) {
      return false;
    }
    if (state == RunState::kConverged) return true;
    const std::optional<DesignPoint>& best = best_.best();
    return !best.has_value() || best->max_violation > 0 || v0_.objective < best->objective;
  }

  // Every end of the run comes here, so that the notes on its result are
  // made once, from the state the run ended in.
  void End(RunState state, std::string reason = "") {
    state_ = state;
    failure_reason_ = std::move(reason);
    result_notes_.clear();
    const DesignPoint best = best_design();
    if (spec_.num_constraints() > 0 && std::isfinite(best.max_violation) &&
        best.max_violation > 0) {
      result_notes_.push_back(absl::StrCat(
          "no feasible design found; the least violation is maxg = ", Number(best.max_violation),
          " (normalized)", ViolatedRowsText(best_violation_values_, " at that design: ")));
    }
    for (int i : FlatVariables(spec_, options_, lin_)) {
      result_notes_.push_back(absl::StrCat(
          VariableText(i), " changes nothing here: its derivatives of the objective and of "
          "the active constraints are all below ", kFlatRelativeSensitivity,
          " relative at the final design; fix it or leave it out of the study"));
    }
  }

  static std::string Number(double v) { return absl::StrFormat("%.4g", v); }

  std::string VariableText(int i) const {
    return absl::StrCat("x", i + 1, " '", spec_.variable_names[i], "'");
  }

  // "'row' (+0.012), ..." for the most violated rows of `constraints` (g_h
  // values), most violated first; empty without violated rows.
  std::string ViolatedRowsText(const Eigen::VectorXd& constraints,
                               const std::string& lead) const {
    if (constraints.size() != spec_.num_constraints()) return "";
    std::vector<std::pair<double, int>> violated;
    for (int h = 0; h < spec_.num_constraints(); ++h) {
      const double g =
          (constraints[h] - spec_.constraint_limits[h]) / spec_.constraint_scales[h];
      if (g > 0) violated.emplace_back(-g, h);
    }
    if (violated.empty()) return "";
    std::sort(violated.begin(), violated.end());
    std::string out = lead;
    const int named = std::min<int>(kRowsNamed, static_cast<int>(violated.size()));
    for (int k = 0; k < named; ++k) {
      const int h = violated[k].second;
      absl::StrAppend(&out, k == 0 ? "" : ", ", "'", spec_.constraint_names[h], "' (+",
                      Number(-violated[k].first), ")");
    }
    if (static_cast<int>(violated.size()) > named) {
      absl::StrAppend(&out, " and ", violated.size() - named, " more rows");
    }
    return out;
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
      Emit(std::move(r), v0_.constraints, {});
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
    r.objective_predicted = PredictedObjective(spec_, lin_, d, &cycle_lp_);

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
      MarkTrialWithoutValues(&r);
    } else {
      trial = MakePointValues(spec_, *result);
      r.objective_trial = trial.objective;
      r.max_violation_trial = trial.max_violation;
      r.worst_constraint_trial = trial.worst_constraint;
      r.objective_error = std::abs(r.objective_predicted - trial.objective) /
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
      Emit(std::move(r), v0_.constraints, trial.constraints);
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
    // maxg before each of the last accepted cycles in a row whose LPs were
    // infeasible, oldest first.
    if (!r.lp_feasible) {
      infeasible_lp_violations_.push_back(v0_.max_violation);
      if (static_cast<int>(infeasible_lp_violations_.size()) > kLocallyInfeasibleCycles) {
        infeasible_lp_violations_.pop_front();
      }
    } else {
      infeasible_lp_violations_.clear();
    }
    // x0's values are replaced below: moved, not copied (a million rows on
    // a fine grid).
    const Eigen::VectorXd x0_constraints = std::move(v0_.constraints);
    dx_old_ = d;
    dF_old_ = trial.objective - v0_.objective;
    x0_ = x_trial_;
    v0_ = trial;
    ++cycles_completed_;
    previous_rejection_at_min_ = false;
    r.converged = converged;
    Emit(std::move(r), x0_constraints, trial.constraints);
    if (converged) {
      Finish(RunState::kConverged, "", result);
      return;
    }
    if (static_cast<int>(infeasible_lp_violations_.size()) == kLocallyInfeasibleCycles &&
        v0_.max_violation >
            (1 - kLocallyInfeasibleProgress) * infeasible_lp_violations_.front()) {
      Stall(LocallyInfeasibleReason());
      return;
    }
    if (cycle_ >= options_.max_cycles) {
      Finish(RunState::kMaxCycles, "", result);
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

  // Why a run whose LPs stay infeasible stops: the rows still violated at
  // its design, and what to try.
  std::string LocallyInfeasibleReason() const {
    std::string out = absl::StrCat(
        "locally infeasible: ", kLocallyInfeasibleCycles,
        " cycles in a row found no step that meets the linearized constraints, and the "
        "violation stayed at maxg = ",
        Number(v0_.max_violation), " (", Number(infeasible_lp_violations_.front()),
        " before them)");
    absl::StrAppend(&out, ViolatedRowsText(v0_.constraints, "; rows still violated: "));
    std::vector<std::string> on_bound;
    for (int i = 0; i < spec_.num_variables(); ++i) {
      if (x0_[i] <= spec_.lower[i]) on_bound.push_back(VariableText(i) + " at its lower bound");
      if (x0_[i] >= spec_.upper[i]) on_bound.push_back(VariableText(i) + " at its upper bound");
    }
    absl::StrAppend(&out, "; try another starting design");
    if (!on_bound.empty()) {
      absl::StrAppend(&out, " or wider bounds (", absl::StrJoin(on_bound, ", "), ")");
    } else {
      absl::StrAppend(&out, ", or check that the limits can be met together");
    }
    return out;
  }

  // The converged design x0 violates a limit by less than the violation
  // tolerance. Its linearization is the cycle's gradients moved to x0 (the
  // analysis of x0 brought its own with simulator sensitivities).
  void BeginRestoration(const AnalysisResult* x0_result) {
    lin_.x0 = x0_;
    lin_.terms0 = v0_.terms;
    lin_.constraints0 = v0_.constraints;
    if (x0_result != nullptr && x0_result->has_gradients()) {
      lin_.terms_gradient = x0_result->objective_gradients;
      if (x0_result->constraint_gradients.size() > 0) {
        lin_.constraints_gradient = x0_result->constraint_gradients;
      }
    }
    restoration_steps_ = 0;
    restoration_from_violation_ = v0_.max_violation;
    lp_solver_->ResetWarmStart();
    SolveRestoration();
  }

  void EndRestoration() {
    End(restoration_end_state_, std::move(restoration_end_reason_));
  }

  void SolveRestoration() {
    ++attempt_;
    const double widen = std::ldexp(1.0, restoration_steps_);
    const double margin =
        std::max(restoration_from_violation_, kMinRestorationMargin) * widen;
    const Eigen::VectorXd limits =
        (move_limits_ * widen).cwiseMin(options_.max_move_limit);
    box_ = ComputeMoveBox(spec_, options_, x0_, limits, lin_.frozen);
    const RestorationLp rlp = BuildRestorationLp(spec_, options_, lin_, box_, margin);
    lp::LpSolution sol = lp_solver_->Solve(rlp.lp);
    const int n = spec_.num_variables();
    CycleRecord r = NewRecord();
    r.restoration = true;
    r.move_limits = limits;
    r.move_limits_next = move_limits_;
    r.lp_status = lp::LpStatusName(sol.status);
    r.lp_iterations = sol.iterations;
    r.rows_screened_in = static_cast<int>(rlp.kept_constraints.size());
    r.optimality_residual = kNaN;
    r.on_move_limit.assign(n, false);
    r.on_bound.assign(n, false);
    x_trial_ = x0_;
    if (sol.status == lp::LpStatus::kOptimal) {
      const Eigen::VectorXd d = RestorationStep(rlp, sol.x);
      for (int i = 0; i < n; ++i) {
        x_trial_[i] = std::clamp(x0_[i] + d[i], spec_.lower[i], spec_.upper[i]);
      }
      r.infeasibility = sol.x[rlp.s_column] * margin;
      r.lp_feasible = r.infeasibility <= options_.infeasibility_tolerance;
    }
    if (sol.status != lp::LpStatus::kOptimal || x_trial_ == x0_) {
      // Nothing to analyse: the linearization offers no move.
      r.accepted = false;
      r.rejection_reason =
          sol.status != lp::LpStatus::kOptimal
              ? absl::StrCat("restoration LP not solved: ", lp::LpStatusName(sol.status))
              : "restoration: the linearization offers no move that meets the limits";
      r.x_trial = x0_;
      MarkTrialWithoutValues(&r);
      r.objective_predicted = kNaN;
      r.analyses_total = analyses_used_;
      r.converged = restoration_end_state_ == RunState::kConverged;  // it ends the run
      Emit(std::move(r), v0_.constraints, {});
      EndRestoration();
      return;
    }
    pending_restoration_record_ = std::move(r);
    phase_ = Phase::kRestoration;
    Request(RequestPurpose::kTrial, -1, 0.0, x_trial_);
  }

  void EvaluateRestoration(const AnalysisResult& result) {
    CycleRecord r = std::move(pending_restoration_record_);
    const Eigen::VectorXd d = x_trial_ - x0_;
    r.x_trial = x_trial_;
    r.objective_predicted = PredictedObjective(spec_, lin_, d, nullptr);
    r.max_approximation_error = kNaN;
    r.analyses_total = analyses_used_;
    PointValues trial;
    if (result.outcome != AnalysisOutcome::kOk) {
      MarkTrialWithoutValues(&r);
      r.rejection_reason = absl::StrCat("restoration analysis failed: ", result.failure_reason);
    } else {
      trial = MakePointValues(spec_, result);
      r.objective_trial = trial.objective;
      r.max_violation_trial = trial.max_violation;
      r.worst_constraint_trial = trial.worst_constraint;
      r.objective_error = std::abs(r.objective_predicted - trial.objective) /
                          std::max(std::abs(trial.objective), options_.objective_magnitude_floor);
      r.accepted = trial.max_violation <= 0;
      if (!r.accepted) {
        r.rejection_reason = absl::StrCat("restoration: maxg = ", Number(trial.max_violation),
                                          " still above 0");
      }
    }
    if (r.accepted) {
      r.converged = restoration_end_state_ == RunState::kConverged;
      const Eigen::VectorXd x0_constraints = std::move(v0_.constraints);
      x0_ = x_trial_;
      v0_ = trial;
      Emit(std::move(r), x0_constraints, trial.constraints);
      EndRestoration();
      return;
    }
    ++restoration_steps_;
    const bool last = restoration_steps_ >= kMaxRestorationSteps;
    r.converged = last && restoration_end_state_ == RunState::kConverged;
    Emit(std::move(r), v0_.constraints, trial.constraints);
    if (last) {
      EndRestoration();
      return;
    }
    SolveRestoration();
  }

  ProblemSpec spec_;
  SlpOptions options_;
  std::unique_ptr<lp::LpSolver> lp_solver_;

  RunState state_ = RunState::kRunning;
  std::string failure_reason_;
  std::vector<std::string> result_notes_;
  Eigen::VectorXd best_violation_values_;  // g_h at best_'s design

  std::deque<double> infeasible_lp_violations_;

  int restoration_steps_ = 0;
  RunState restoration_end_state_ = RunState::kConverged;
  std::string restoration_end_reason_;
  double restoration_from_violation_ = 0;  // maxg of the converged design
  CycleRecord pending_restoration_record_;
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
const std::vector<std::string>& SlpOptimizer::result_notes() const {
  return impl_->result_notes();
}
const Eigen::VectorXd& SlpOptimizer::current_design() const { return impl_->current_design(); }
double SlpOptimizer::current_objective() const { return impl_->current_objective(); }
double SlpOptimizer::current_max_violation() const { return impl_->current_max_violation(); }
DesignPoint SlpOptimizer::best_design() const { return impl_->best_design(); }
int SlpOptimizer::cycles_completed() const { return impl_->cycles_completed(); }
std::int64_t SlpOptimizer::analyses_used() const { return impl_->analyses_used(); }
const ProblemSpec& SlpOptimizer::spec() const { return impl_->spec(); }

}  // namespace mbopt::slp
