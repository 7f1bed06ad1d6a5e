#include "bench/accuracy/sweep_plan.h"

#include "absl/strings/str_format.h"

namespace mbopt::accuracy {
namespace {

// The absolute tolerance follows the relative one at this ratio (the ratio of
// the example scenes' own settings).
constexpr double kAbsoluteOverRelative = 1e-3;

Setting Default() { return Setting{KnobKind::kDefault, "default", "study's own", {}, {}}; }

Setting Grid(int points) {
  Setting s{KnobKind::kModel, "time grid points", absl::StrFormat("%d", points), {}, {}};
  s.analysis.set_time_grid_points(points);
  return s;
}

Setting Tolerance(double rtol) {
  Setting s{KnobKind::kSolver, "relative tolerance", absl::StrFormat("%.0e", rtol), {}, {}};
  s.analysis.set_relative_tolerance(rtol);
  s.analysis.set_absolute_tolerance(kAbsoluteOverRelative * rtol);
  return s;
}

Setting Elements(int n) {
  Setting s{KnobKind::kModel, "elements per link", absl::StrFormat("%d", n), {}, {}};
  s.analysis.set_elements_per_flexible_link(n);
  return s;
}

Setting RigidLinks() {
  Setting s{KnobKind::kModel, "link model", "rigid (kinetostatic)", {}, {}};
  s.analysis.set_rigid_links(true);
  return s;
}

Setting Central() {
  Setting s{KnobKind::kSolver, "finite differences", "central", {}, {}};
  s.optimizer.set_finite_difference(v1::FINITE_DIFFERENCE_CENTRAL);
  return s;
}

Setting Step(double h) {
  Setting s{KnobKind::kSolver, "finite-difference step", absl::StrFormat("%.0e", h), {}, {}};
  s.optimizer.set_finite_difference_relative_step(h);
  return s;
}

// Gradients from CVODES forward sensitivities inside each analysis instead
// of perturbed analyses (lumped scenes only).
Setting Simulator() {
  Setting s{KnobKind::kSolver, "sensitivity", "simulator (CVODES)", {}, {}};
  s.optimizer.set_sensitivity(v1::SENSITIVITY_METHOD_SIMULATOR);
  return s;
}

void AddFiniteDifferenceKnobs(SweepPlan* p, const std::vector<double>& steps) {
  p->settings.push_back(Central());
  for (const double h : steps) p->settings.push_back(Step(h));
}

v1::AnalysisOverrides Overrides(int grid, double rtol, int elements) {
  v1::AnalysisOverrides a;
  if (grid > 0) a.set_time_grid_points(grid);
  if (rtol > 0) {
    a.set_relative_tolerance(rtol);
    a.set_absolute_tolerance(kAbsoluteOverRelative * rtol);
  }
  if (elements > 0) a.set_elements_per_flexible_link(elements);
  return a;
}

}  // namespace

std::vector<std::string> ProblemNames() {
  return {"vehicle", "fourbar_rigid", "fourbar_elastic", "landing_gear"};
}

bool MakeSweepPlan(const std::string& problem, SweepPlan* p) {
  *p = SweepPlan{};
  p->problem = problem;
  p->settings.push_back(Default());
  const std::vector<double> steps = {1e-2, 1e-3, 1e-5, 1e-6, 1e-7};
  if (problem == "vehicle") {
    p->study_file = "examples/vehicle/vehicle.study.textproto";
    for (const int n : {26, 51, 201, 401, 1001}) p->settings.push_back(Grid(n));
    for (const double r : {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-9, 1e-10}) p->settings.push_back(Tolerance(r));
    AddFiniteDifferenceKnobs(p, steps);
    p->settings.push_back(Simulator());
    p->reference = Setting{KnobKind::kDefault, "reference", "1001 points, rtol 1e-10", Overrides(1001, 1e-10, 0), {}};
    p->recheck = Overrides(1001, 1e-10, 0);
    p->recheck_note = "1001 points, rtol 1e-10";
    p->not_swept = {"elements per link, link model: no flexible links (lumped model)"};
    return true;
  }
  if (problem == "fourbar_rigid") {
    p->study_file = "examples/fourbar/fourbar_rigid.study.textproto";
    // The study's own grid is 1001 points; 101 is the report's.
    for (const int n : {26, 51, 101, 201, 401}) p->settings.push_back(Grid(n));
    AddFiniteDifferenceKnobs(p, steps);
    p->reference = Setting{KnobKind::kDefault, "reference", "2001 points", Overrides(2001, 0, 0), {}};
    p->recheck = Overrides(10001, 0, 0);
    p->recheck_note = "10001 points";
    p->not_swept = {
        "relative tolerance: kinetostatic analysis, no time integration (the motion is prescribed)",
        "elements per link: rigid links (stress stations fixed at 6 elements)"};
    return true;
  }
  if (problem == "fourbar_elastic") {
    // The expensive one (time integration of beam elements): a warm start
    // near the report's optimum, fewer settings. The study's own grid is
    // 1001 points; 101 is the report's.
    p->study_file = "examples/fourbar/fourbar_elastic.study.textproto";
    p->initial_override = {1.0, 0.5, 0.3};
    p->initial_note =
        "warm start at x = (1.0, 0.5, 0.3), i.e. A = (10, 5, 3) cm^2 (2.73 kg), near the report's "
        "optimum x = (0.965, 0.392, 0.269), "
        "instead of the study's x0 = 100, to keep the sweep short";
    for (const int n : {51, 101}) p->settings.push_back(Grid(n));
    p->settings.push_back(Tolerance(1e-4));
    for (const int e : {2, 4}) p->settings.push_back(Elements(e));
    p->settings.push_back(RigidLinks());
    p->reference = Setting{KnobKind::kDefault, "reference", "2001 points, rtol 1e-8, 8 elements",
                           Overrides(2001, 1e-8, 8), {}};
    p->recheck = Overrides(10001, 1e-8, 8);
    p->recheck_note = "10001 points, rtol 1e-8, 8 elements";
    p->not_swept = {"finite-difference scheme and step, finer meshes: left out to keep the sweep short"};
    return true;
  }
  if (problem == "landing_gear") {
    p->study_file = "examples/landing_gear/landing_gear.study.textproto";
    AddFiniteDifferenceKnobs(p, steps);
    Setting reference{KnobKind::kDefault, "reference", "central differences", {}, {}};
    reference.optimizer.set_finite_difference(v1::FINITE_DIFFERENCE_CENTRAL);
    p->reference = reference;
    p->reference_is_default_model = true;
    p->recheck = v1::AnalysisOverrides{};
    p->not_swept = {
        "time grid points: only the end position enters the objective (kinematic analysis, "
        "closed-loop Newton solve, no integrator)",
        "relative tolerance, elements per link: no integration, rigid links"};
    return true;
  }
  return false;
}

}  // namespace mbopt::accuracy
