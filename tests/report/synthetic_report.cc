#include "tests/report/synthetic_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mbopt::report::testing {

ReportData SyntheticVehicleReport() {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  ReportData d;
  d.job_id = "job-0007";
  d.study_name = kSyntheticStudyName;
  d.description = "Seat acceleration, after Haug & Arora (1979)";
  d.state = "converged";
  d.objective_unit = "in/s^2";
  d.wall_seconds = 42.5;
  const char* names[] = {"k1", "k2", "k3", "c1", "c2", "c3"};
  const char* units[] = {"lb/in", "lb/in", "lb/in", "lb s/in", "lb s/in", "lb s/in"};
  const double scales[] = {10, 20, 20, 1, 2, 2};
  const double lower[] = {5, 10, 10, 1, 1, 1};
  const double upper[] = {30, 40, 40, 50, 50, 40};
  for (int i = 0; i < 6; ++i) d.variables.push_back({names[i], units[i], scales[i], true, lower[i], upper[i]});

  const std::vector<double> history = {333, 356, 313, 281, 272, 268, 263, 259, 254, 252, 252, 252};
  const std::vector<double> start = {10, 15, 15, 10, 12.5, 12.5};
  const std::vector<double> optimum = {5, 10, 10, 41.54, 38.53, 40.00};
  const int cycles = static_cast<int>(history.size()) - 1;
  auto design_after = [&](int k) {
    std::vector<double> x(6);
    const double t = std::min(1.0, static_cast<double>(k) / (cycles - 3));  // on the optimum for the last cycles
    for (int i = 0; i < 6; ++i) x[static_cast<std::size_t>(i)] = start[static_cast<std::size_t>(i)] + t * (optimum[static_cast<std::size_t>(i)] - start[static_cast<std::size_t>(i)]);
    return x;
  };
  auto violation_after = [&](int k) {
    // Violated at the start, feasible in the middle, slightly active at the end.
    if (k == 0) return 0.31;
    if (k < 4) return 0.12 / k;
    if (k < 7) return -0.04;
    return 0.0015 / (k - 5);
  };

  std::vector<double> f(6, 0.2);
  long analyses = 0;
  for (int k = 1; k <= cycles; ++k) {
    analyses += 7;  // x0 and six forward differences
    const std::vector<double> x0 = design_after(k - 1);
    const std::vector<double> x1 = design_after(k);
    auto base = [&]() {
      ReportCycle r;
      r.cycle = k;
      r.x0_scaled = x0;
      r.objective_x0 = history[static_cast<std::size_t>(k - 1)];
      r.max_violation_x0 = violation_after(k - 1);
      r.lp_status = "optimal";
      r.worst_constraint = "seat-chassis@t=0.42s upper";
      r.worst_approximation = "objective";
      r.move_limits = f;
      return r;
    };
    if (k == 2 || k == 5) {
      ReportCycle rejected = base();
      rejected.attempt = 0;
      rejected.x_trial_scaled = x1;
      for (double& v : rejected.x_trial_scaled) v *= 1.1;
      analyses += 1;
      rejected.analyses_total = analyses;
      if (k == 2) {
        rejected.objective_trial = 380;
        rejected.objective_predicted = 300;
        rejected.max_violation_trial = 0.2;
        rejected.objective_error = 0.21;
        rejected.max_approximation_error = 0.62;
        rejected.rejection_reason = "maxfout 0.62 > 0.40";
      } else {
        rejected.objective_trial = kNaN;
        rejected.objective_predicted = 270;
        rejected.max_violation_trial = kNaN;
        rejected.objective_error = kNaN;
        rejected.max_approximation_error = kNaN;
        rejected.worst_constraint.clear();
        rejected.worst_approximation.clear();
        rejected.rejection_reason = "trial analysis failed: integrator error at t=0.31 s";
      }
      for (double& v : f) v *= 0.75;
      rejected.move_limits_next = f;
      d.records.push_back(rejected);
    }
    ReportCycle r = base();
    r.attempt = (k == 2 || k == 5) ? 1 : 0;
    r.move_limits = f;
    r.accepted = true;
    r.x_trial_scaled = x1;
    r.objective_trial = history[static_cast<std::size_t>(k)];
    r.objective_predicted = r.objective_trial * 0.97;
    r.max_violation_trial = violation_after(k);
    r.objective_error = k == 6 ? 0.0 : 0.3 / (k * k);  // an exact prediction once
    r.max_approximation_error = 0.35 / k;
    r.lp_feasible = k != 1;
    r.infeasibility = k == 1 ? 0.013 : 0.0;
    analyses += 1;
    r.analyses_total = analyses;
    // Widen while the approximation is good, narrow near the optimum.
    for (std::size_t i = 0; i < f.size(); ++i) f[i] *= (k < 5 ? 4.0 / 3.0 : 0.5 + 0.05 * static_cast<double>(i));
    r.move_limits_next = f;
    r.converged = k == cycles;
    d.records.push_back(r);
  }
  d.cycles = cycles;
  d.analyses = analyses;
  d.objective = history.back();
  d.max_violation = violation_after(cycles);
  for (int i = 0; i < 6; ++i) d.final_design_physical.push_back(scales[i] * optimum[static_cast<std::size_t>(i)]);
  return d;
}

}  // namespace mbopt::report::testing
