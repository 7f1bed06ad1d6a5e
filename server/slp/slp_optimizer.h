// The SLP optimizer core: a deterministic state machine for one optimization.
//
// It does no I/O, reads no clock and starts no thread. The caller asks it
// which analyses it needs (PendingRequests), runs them anywhere, and hands the
// results back in any order (SubmitResult). When a batch is complete the core
// runs the rest of the cycle (screening, LP, acceptance, move limits,
// convergence) and emits CycleRecords. Its whole state is a function of the
// ProblemSpec, the SlpOptions and the sequence of results it was given, keyed
// by request id: replaying the logged results into a fresh optimizer rebuilds
// it bit for bit (this is what the server's resume relies on). The order in
// which results of one batch arrive does not matter.
//
// Analyses: a request asks for F and g at one scaled design point. Request ids
// count up from 0 in the order the core creates them.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "server/lp/linear_program.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"

namespace mbopt::slp {

enum class RequestPurpose {
  kCycleStart,    // the design point x0 of a cycle
  kPerturbation,  // a finite-difference perturbation of x0
  kTrial,         // the LP optimum x*, to be accepted or rejected
};

struct AnalysisRequest {
  std::int64_t id = 0;
  int cycle = 0;                 // 1-based cycle number
  RequestPurpose purpose = RequestPurpose::kCycleStart;
  int perturbed_variable = -1;   // for kPerturbation
  double perturbation_step = 0;  // signed scaled step, for kPerturbation
  Eigen::VectorXd x;             // scaled design point
  // The analysis should also return the gradients of its values
  // (SlpOptions::analyses_provide_gradients): on kCycleStart, and on kTrial
  // because an accepted trial point becomes the next cycle's x0.
  bool want_gradients = false;
};

enum class AnalysisOutcome {
  kOk,
  kFailed,  // the analysis did not produce values (integrator failure,
            // mechanism cannot assemble, NaN, worker gave up, ...)
};

struct AnalysisResult {
  std::int64_t request_id = 0;
  AnalysisOutcome outcome = AnalysisOutcome::kOk;
  std::string failure_reason;        // for kFailed
  Eigen::VectorXd objective_terms;   // num_objective_terms, for kOk
  Eigen::VectorXd constraint_values; // num_constraints (g_h, not normalized), for kOk
  // Optional, for kOk: d(objective term)/dx (num_objective_terms x n) and
  // d(g_h)/dx (num_constraints x n), with respect to the SCALED variables.
  // Empty: none. A non-finite entry makes the pair unusable (the cycle then
  // uses finite differences); a wrong shape is InvalidArgument.
  Eigen::MatrixXd objective_gradients;
  Eigen::MatrixXd constraint_gradients;

  // Every problem has an objective term and a variable, so an empty
  // objective_gradients means "no gradients" (constraint_gradients may be
  // 0 x n).
  bool has_gradients() const { return objective_gradients.size() > 0; }
};

// A design and its values: x (scaled), F, maxg (normalized).
struct DesignPoint {
  Eigen::VectorXd x;
  double objective = 0;
  double max_violation = 0;
};

enum class RunState {
  kRunning,     // PendingRequests() is not empty
  kConverged,   // the convergence test of METHOD.md section 3 held, and the
                // KKT residual was below convergence_optimality_tolerance
  kMaxCycles,   // SlpOptions::max_cycles cycles were run
  kStalled,     // move limits collapsed, every trial point failed, or the
                // design stays infeasible with infeasible LPs (locally
                // infeasible; end_reason() names the rows)
  kFailed,      // x0 of the first cycle could not be analysed
};

const char* RunStateName(RunState state);

// One LP solve of a cycle and what became of its trial point. A cycle has one
// record per trial point: the rejected ones and finally the accepted one.
struct CycleRecord {
  int cycle = 0;          // 1-based
  int attempt = 0;        // 0-based index of the trial within the cycle
  bool accepted = false;
  std::string rejection_reason;   // empty when accepted

  Eigen::VectorXd x0;             // scaled
  Eigen::VectorXd x_trial;        // scaled LP optimum x*
  double objective_x0 = 0;        // F(x0)
  double objective_trial = 0;     // F(x*), NaN if the trial analysis failed
  double objective_predicted = 0; // F~(x*)
  double max_violation_x0 = 0;    // maxg at x0 (normalized, > 0 violated)
  double max_violation_trial = 0; // maxg at x*
  int worst_constraint_trial = -1;  // row index of maxg at x*, -1 if none
  double objective_error = 0;       // e_o
  double max_approximation_error = 0;  // maxfout
  int worst_approximation_row = -1;    // -1: the objective
  // First-order optimality of this attempt's LP solution (cycle_lp.h,
  // OptimalityResidual); NaN when the LP was not solved.
  double optimality_residual = 0;
  bool lp_feasible = true;          // feas: infeasibility variable s == 0
  double infeasibility = 0;         // s at the LP optimum
  std::string lp_status;            // LpStatusName of the LP solve
  int lp_iterations = 0;
  int rows_screened_in = 0;         // constraint rows kept in this LP
  Eigen::VectorXd move_limits;      // f_i used for this LP
  Eigen::VectorXd move_limits_next; // f_i after the strategy
  std::vector<bool> on_move_limit;  // mvlimact(i)
  std::vector<bool> on_bound;       // boundact(i)
  std::int64_t analyses_total = 0;  // analyses consumed by the run so far
  // The convergence test held on this record, or (restoration) this record
  // ended the converged run.
  bool converged = false;
  // A feasibility restoration step after convergence (docs/method.md
  // section 7): x_trial is the smallest move from x0 that the linearization
  // says meets every constraint; accepted when its analysis does (maxg <= 0).
  // Such a record belongs to the cycle that converged and changes neither
  // the move limits nor the cycle count.
  bool restoration = false;
  // Set only in the records of a design set (a sweep or sample, which the
  // job runs without this core: server/jobs/design_set_run.h), one record
  // per design: the largest normalized value (g_h - c_h) / scale_h of each
  // of the study's constraints (NaN when the analysis failed), and the
  // failure kind's name of a failed analysis ("" when it succeeded).
  bool design_set = false;  // the record of one design of a design set
  std::vector<double> constraint_violations;
  std::string failure_kind;
  // Set only in the records of a Pareto front's points (one record per
  // point, design_set set as well: server/jobs/pareto_run.h): x0 is the
  // point's result, objective_x0 the study's F there, max_violation_x0 the
  // point's run's own maxg; the traded constraint's level for this point
  // and its largest value at the result (SI; NaN for an anchor's level and
  // where no design was analysed), the run's end (RunStateName, or
  // "not_run"), and the run's cycles and analyses.
  bool pareto = false;
  double pareto_level_si = 0;
  double pareto_value_si = 0;
  std::string pareto_state;
  int pareto_cycles = 0;
  std::int64_t pareto_analyses = 0;
  // A point of a front of three objectives (pareto set too): the third
  // objective's level and value, as pareto_level_si and pareto_value_si.
  bool pareto_three = false;
  double pareto_level3_si = 0;
  double pareto_value3_si = 0;
  // Set only in the cycle records of a Pareto front's point's run (its own
  // history, logged just before the point's record): the point's 1-based
  // number. The record is that run's as this core emitted it (its F, its
  // maxg against its own rows and level, its analyses_total counting its
  // own analyses), but for the row indices, which are the study's.
  int pareto_point = 0;
};

class SlpOptimizer {
 public:
  // `lp_solver` is owned; one per optimizer. Check the spec and options
  // before constructing (Validate); invalid ones are a bug here.
  SlpOptimizer(ProblemSpec spec, SlpOptions options,
               std::unique_ptr<lp::LpSolver> lp_solver);
  ~SlpOptimizer();
  SlpOptimizer(const SlpOptimizer&) = delete;
  SlpOptimizer& operator=(const SlpOptimizer&) = delete;

  // Analyses requested and not yet answered, ordered by id.
  std::vector<AnalysisRequest> PendingRequests() const;
  // Whether `request_id` is among them (without copying them).
  bool IsPending(std::int64_t request_id) const;

  // Hands in one result. InvalidArgument for an unknown or already answered
  // id, or value vectors of the wrong size. NaN or infinite values are
  // accepted and treated as a failed analysis. When the result completes a
  // batch, the cycle advances inside this call.
  absl::Status SubmitResult(const AnalysisResult& result);

  // Records emitted since the last call, in order.
  std::vector<CycleRecord> TakeNewRecords();

  RunState state() const;
  // Why the run ended stalled or failed (empty otherwise).
  const std::string& end_reason() const;
  // What a user should know about the result once the run has ended, one
  // sentence each, in a fixed order: that no design met every constraint
  // (with the least violation), and which variables change nothing at the
  // final design (flat directions). Empty while running.
  const std::vector<std::string>& result_notes() const;
  // The current design x0 (scaled): the last accepted trial point, or the
  // initial design before any acceptance. Its values: F (the maximum term
  // for min-max) and maxg (0 without constraints); NaN before x0 was
  // analysed.
  const Eigen::VectorXd& current_design() const;
  double current_objective() const;
  double current_max_violation() const;
  // The run's result: the best design analysed so far (best_design.h), or
  // the current design before any cycle record exists.
  DesignPoint best_design() const;
  int cycles_completed() const;
  std::int64_t analyses_used() const;
  const ProblemSpec& spec() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbopt::slp
