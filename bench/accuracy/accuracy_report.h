// The Markdown section of one problem in docs/accuracy.md: the table of the
// sweep, the Pareto plot's data, and a recommended default derived from the
// measurements.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "bench/accuracy/pareto_svg.h"
#include "bench/accuracy/sweep_plan.h"
#include "bench/accuracy/sweep_run.h"

namespace mbopt::accuracy {

// What counts as good enough: the SLP's own convergence tolerances
// (METHOD.md section 3), so a setting is acceptable when its error is not
// larger than what the optimizer already tolerates.
struct Acceptance {
  double objective_error = 0.005;
  double true_violation = 0.005;
};

struct ProblemSweep {
  SweepPlan plan;
  double initial_objective = 0;  // F(x0) on the re-check model
  SettingResult reference;
  std::vector<SettingResult> results;  // plan.settings order
  std::optional<SettingResult> recommended;  // the verified combination
  // Run when the combination fails and changes solver knobs: the model
  // knobs' values alone.
  std::optional<SettingResult> fallback;
};

// Model knobs: error vs F_ref and true violation within the tolerances.
// Solver knobs: change vs the default run's F within the objective
// tolerance and the true violation not more than the tolerance above the
// default's.
bool Acceptable(const ProblemSweep& sweep, const SettingResult& r, const Acceptance& acceptance);
// Against the reference only, whatever the knob: the re-check succeeded, the
// objective is within the tolerance of F_ref and the true violation within
// its own. How a recommended combination is judged.
bool WithinReferenceTolerances(const ProblemSweep& sweep, const SettingResult& r,
                               const Acceptance& acceptance);

// The combination to verify: per model knob the fastest acceptable value
// (the reference's value when none is acceptable), per solver knob the
// fastest acceptable value if it is faster than the default. `why` gets one
// line per knob.
// `model_only` gets the same choice restricted to the model knobs.
Setting RecommendedSetting(const ProblemSweep& sweep, const Acceptance& acceptance,
                           std::vector<std::string>* why, Setting* model_only);

// |F - F_ref| / max(|F_ref|, 1 % |F(x0)|): relative, with a floor for
// problems whose optimum is near zero.
double ObjectiveError(const ProblemSweep& sweep, double objective);
// The same measure against the default run's F instead of F_ref.
double ChangeVsDefault(const ProblemSweep& sweep, double objective);

std::vector<PlotPoint> PlotPoints(const ProblemSweep& sweep, const Acceptance& acceptance);

// `svg_link` is the plot's path relative to the Markdown file (empty: none).
std::string ProblemMarkdown(const ProblemSweep& sweep, const Acceptance& acceptance,
                            const std::string& svg_link,
                            const std::vector<std::string>& recommendation_why);

}  // namespace mbopt::accuracy
