// A study as domain types: what spec/io makes of a .study.textproto. Field
// meanings are documented in proto/mbopt/v1/study.proto.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "spec/design_set.h"
#include "spec/expression.h"
#include "spec/pareto.h"
#include "spec/scene.h"
#include "spec/units.h"

namespace mbopt::spec {

struct DesignVariable {
  std::string name;
  int parameter = -1;     // index into scene.parameters
  std::vector<int> also_sets;  // further parameters given the same SI value
  double scale = 1.0;     // parameter value (in the parameter's unit) = scale * x
  double initial = 0.0;   // scaled
  double lower = 0.0;     // scaled
  double upper = 0.0;     // scaled
};

enum class Reduction { kMax, kMaxAbs, kMin, kFinal, kRms, kIntegral, kRange, kMean };

// A term of a weighted sum whose value is the largest of a family of values
// (REDUCTION_MAX, REDUCTION_MAX_ABS, or REDUCTION_MIN with a negative
// weight, which is |weight| times the largest of -f).
inline bool IsPeakReduction(Reduction r) { return r == Reduction::kMax || r == Reduction::kMaxAbs || r == Reduction::kMin; }

// FINAL and the reductions over a window give one value per series; the
// others one per instant.
inline bool IsWholeSeriesReduction(Reduction r) {
  return r == Reduction::kFinal || r == Reduction::kRms || r == Reduction::kIntegral || r == Reduction::kRange ||
         r == Reduction::kMean;
}

// Instants with from_s <= t <= to_s; an absent end is open.
struct TimeWindow {
  std::optional<double> from_s;
  std::optional<double> to_s;
  bool whole_grid() const { return !from_s.has_value() && !to_s.has_value(); }
};

struct TargetTerm {
  int output = -1;
  double target = 0.0;       // in `unit`
  double weight = 1.0;
  double si_per_unit = 1.0;  // output value in unit = value_si / si_per_unit
  std::string unit;
};

// A term of a weighted-sum objective: weight * (reduced output / unit).
struct WeightedTerm {
  int output = -1;  // a signal: a scene output or a response (Study::SignalName)
  Reduction reduction = Reduction::kFinal;
  TimeWindow window;
  double weight = 1.0;
  std::string unit;
  double si_per_unit = 1.0;
};

struct Objective {
  // kMaxOver: F = the largest of several terms (min-max over responses).
  // kFeasible: no objective (the study file has none): F = 0 at every
  // design, and the run ends at the first accepted design that meets every
  // constraint (SlpOptionsFromStudy sets the objective target 0).
  enum class Form { kMinimizeMaxOf, kMinimize, kTargetDistance, kWeightedSum, kMaxOver, kFeasible } form =
      Form::kMinimize;
  // kWeightedSum: the terms summed; a peak term (IsPeakTerm) is its maximum
  // over its window, taken through a bound variable of its own.
  // kMaxOver: the terms whose largest value
  // is F; MAX and MAX_ABS give a term per instant of the window, the
  // whole-series reductions one; weights are positive.
  std::vector<WeightedTerm> sum_terms;
  int output = -1;                 // kMinimizeMaxOf, kMinimize
  Reduction reduction = Reduction::kMax;
  std::vector<TargetTerm> terms;   // kTargetDistance
  std::string unit;
  double si_per_unit = 1.0;
  TimeWindow window;
  // kMinimize only: maximize the value instead. The optimizer minimizes
  // F = -value; what the service reports is ReportedSign() * F, the value.
  bool maximize = false;
  double ReportedSign() const { return maximize ? -1.0 : 1.0; }
};

// The band of `equals: v` written without a tolerance: +- this share of |v|
// (of one unit when |v| is below one unit).
inline constexpr double kDefaultEqualityRelativeTolerance = 1e-4;

struct Constraint {
  std::string name;
  int output = -1;
  Reduction reduction = Reduction::kMaxAbs;
  double limit = 0.0;        // in `unit`; MAX, MAX_ABS, MIN
  // Whole-series reductions: the bounds of the value, in `unit` (at least
  // one; `limit` and `equals` +- tolerance are written as these at load).
  std::optional<double> lower;
  std::optional<double> upper;
  // Written as `equals` (in `unit`): the value the band [lower, upper] is
  // centred on. Its rows are scaled by the size of this value, not by their
  // bounds (EqualityRowScale in spec/layout.h).
  std::optional<double> equals;
  std::string unit;
  double si_per_unit = 1.0;
  TimeWindow window;
};

// What the study file sets of the optimizer. An unset value is the method's
// default, which is written once, in slp::SlpOptions (server/slp/options.h).
struct OptimizerSettings {
  std::optional<double> initial_move_limit;
  std::optional<int> max_cycles;
  std::optional<double> convergence_objective_tolerance;
  std::optional<double> convergence_violation_tolerance;
  std::optional<double> convergence_optimality_tolerance;
  std::optional<double> screening_threshold;
  bool central_differences = false;
  std::optional<double> finite_difference_relative_step;
  // Gradients from the simulator's forward sensitivity analysis instead of
  // finite differences (lumped and multibody scenes; not linkage scenes
  // or static multibody analyses).
  bool simulator_sensitivities = false;
  // Stop, converged, at a feasible design whose objective is this good (at
  // or below it; at or above it when maximizing).
  std::optional<double> objective_target;
};

struct AnalysisOverrides {
  int time_grid_points = 0;
  double relative_tolerance = 0.0;
  double absolute_tolerance = 0.0;
  int elements_per_flexible_link = 0;
  bool rigid_links = false;
};

// A named response: a series computed at every instant from the scene's
// outputs, the responses before it, the scene's parameters and the time t
// (SI throughout). Objectives and constraints name it like an output.
//
// Its expression's names are numbered as Study::ResponseNameIndex says:
// signals (the scene's outputs, then the responses), then parameters, then t.
struct Response {
  std::string name;
  std::shared_ptr<const Expression> expression;
  Dimension dimension = Dimension::kAny;  // from the study's `unit`, for unit checks
  std::string unit;                       // as written
};

// A load case: the scene analysed with some of its parameters set otherwise
// (another road, another payload), at every design point. A study with
// cases analyses each; its outputs are named "<case>.<output>".
struct LoadCase {
  std::string name;
  std::vector<std::pair<int, double>> parameter_values_si;  // parameter index, SI value
};

// A plot of signal `y` against signal `x` for the report (not used by the
// optimization), each axis in its unit.
struct XyPlot {
  int x = -1;  // a signal (Study::SignalName)
  int y = -1;
  std::string x_unit, y_unit;  // empty: SI
  double x_si_per_unit = 1.0, y_si_per_unit = 1.0;
};

struct Study {
  std::string name;
  std::string source_file;
  Scene scene;  // with the study's AnalysisOverrides already applied
  std::vector<DesignVariable> variables;
  std::vector<LoadCase> cases;  // empty: one analysis of the scene as it is
  std::vector<Response> responses;
  Objective objective;
  std::vector<Constraint> constraints;
  OptimizerSettings optimizer;
  AnalysisOverrides analysis;
  // Analyses at these designs instead of an optimization (empty: optimize).
  DesignSet design_set;
  // A Pareto front instead of one optimum (spec/pareto.h).
  Pareto pareto;
  // The front's second objective when pareto.trades_objective (any form
  // but kFeasible and kTargetDistance, and no peaks in a kWeightedSum).
  Objective second_objective;
  std::vector<XyPlot> plots;

  // SI parameter values of the scene at scaled design x (others at default).
  std::vector<double> ParameterValuesAt(const std::vector<double>& x_scaled) const;

  // The SI parameter values of load case `c` given the design's
  // (`parameter_values_si`, from ParameterValuesAt); without cases, those.
  std::vector<double> CaseParameterValues(int c, std::vector<double> parameter_values_si) const;
  int num_cases() const { return cases.empty() ? 1 : static_cast<int>(cases.size()); }

  // Signals are what objectives and constraints name: the scene's outputs
  // (once per load case, case by case), then the responses.
  int num_case_signals() const { return num_cases() * static_cast<int>(scene.outputs.size()); }
  int num_signals() const { return num_case_signals() + static_cast<int>(responses.size()); }
  // "<output>", "<case>.<output>" with load cases, or the response's name.
  std::string SignalName(int signal) const;
  // -1 if no output or response has this name.
  int FindSignal(const std::string& name) const;
  // A response expression's index of signal k is k; of parameter p,
  // num_signals() + p; of the time t, num_signals() + parameters.
  int ParameterNameIndex(int parameter) const { return num_signals() + parameter; }
  int TimeNameIndex() const { return num_signals() + static_cast<int>(scene.parameters.size()); }
};

}  // namespace mbopt::spec
