#include "worker/solve/linkage_analysis.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <string>
#include <variant>

#include "absl/strings/str_format.h"
#include "worker/model/linkage_model.h"
#include "worker/solve/elastodynamic_solver.h"
#include "worker/solve/kinematic_solver.h"
#include "worker/solve/kinetostatic_solver.h"
#include "worker/solve/wall_time_budget.h"

namespace mbopt::solve {

namespace {

using spec::AnalysisReport;
using spec::FailureKind;
using spec::Formulation;
using spec::OutputValues;

// Wraps to (-pi, pi].
double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

std::vector<double> GridTimes(const spec::TimeGrid& grid) {
  if (grid.points <= 1) return {grid.end_s};
  std::vector<double> t(static_cast<size_t>(grid.points));
  for (int i = 0; i < grid.points; ++i) {
    t[static_cast<size_t>(i)] =
        grid.start_s + (grid.end_s - grid.start_s) * i / (grid.points - 1);
  }
  return t;
}

bool NeedsLoads(const spec::Output& o) {
  return std::holds_alternative<spec::BendingStressOutput>(o.kind) ||
         std::holds_alternative<spec::DriveTorqueOutput>(o.kind);
}

void Fail(AnalysisReport* report, const spec::AnalysisFailure& failure) {
  report->Fail(failure.kind, failure.reason);
}
void Fail(AnalysisReport* report, std::string why) { report->Fail(FailureKind::kInvalidModel, std::move(why)); }

// Checks that every output fits a linkage and refers to existing items.
std::string CheckOutputs(const spec::Scene& scene, const model::LinkageSystem& sys) {
  const int nl = static_cast<int>(sys.links.size());
  const int nj = static_cast<int>(sys.joints.size());
  for (const spec::Output& o : scene.outputs) {
    if (const auto* p = std::get_if<spec::PointPositionOutput>(&o.kind)) {
      if (p->joint >= 0) {
        if (p->joint >= nj) return absl::StrFormat("output '%s': unknown joint", o.name);
      } else if (p->link < 0 || p->link >= nl || p->point < 0 ||
                 p->point >= static_cast<int>(sys.links[static_cast<size_t>(p->link)].points.size())) {
        return absl::StrFormat("output '%s': unknown link point", o.name);
      }
    } else if (const auto* r = std::get_if<spec::LinkRotationOutput>(&o.kind)) {
      if (r->link < 0 || r->link >= nl) return absl::StrFormat("output '%s': unknown link", o.name);
    } else if (const auto* b = std::get_if<spec::BendingStressOutput>(&o.kind)) {
      if (b->link < 0 || b->link >= nl) return absl::StrFormat("output '%s': unknown link", o.name);
      if (!sys.links[static_cast<size_t>(b->link)].has_section) {
        return absl::StrFormat("output '%s': link '%s' has no section, so no stress", o.name,
                               sys.links[static_cast<size_t>(b->link)].name);
      }
    } else if (std::holds_alternative<spec::DriveTorqueOutput>(o.kind) ||
               std::holds_alternative<spec::MassOutput>(o.kind)) {
    } else {
      return absl::StrFormat("output '%s': not a linkage output", o.name);
    }
  }
  return {};
}

// Motion outputs at one instant, appended to the series.
void RecordMotion(const spec::Scene& scene, const model::LinkageSystem& sys,
                  const LinkageState& start, const LinkageState& s, size_t instant,
                  std::vector<OutputValues>* out) {
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    std::vector<double>& series = (*out)[k].series[0];  // motion outputs have one series
    if (const auto* p = std::get_if<spec::PointPositionOutput>(&o.kind)) {
      Eigen::Vector2d r;
      if (p->joint >= 0) {
        r = s.position_m[static_cast<size_t>(p->joint)];
      } else {
        const model::LinkageLink& l = sys.links[static_cast<size_t>(p->link)];
        const Eigen::Vector2d e = s.LinkVector(l).normalized();
        const Eigen::Vector2d n(-e.y(), e.x());
        const Eigen::Vector2d& local = l.points[static_cast<size_t>(p->point)].local_m;
        r = s.position_m[static_cast<size_t>(l.joint_a)] + local.x() * e + local.y() * n;
      }
      series[instant] = p->axis == spec::Axis::kX ? r.x() : r.y();
    } else if (const auto* rot = std::get_if<spec::LinkRotationOutput>(&o.kind)) {
      const model::LinkageLink& l = sys.links[static_cast<size_t>(rot->link)];
      series[instant] = WrapAngle(s.LinkAngle(l) - start.LinkAngle(l));
    }
  }
}

}  // namespace

AnalysisReport AnalyzeLinkage(const spec::Scene& scene,
                              const std::vector<double>& parameter_values_si) {
  const auto wall_start = std::chrono::steady_clock::now();
  AnalysisReport report;
  report.times_s = GridTimes(scene.time_grid);
  auto finish = [&]() {
    report.counters.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    return report;
  };
  const auto* linkage = std::get_if<spec::LinkageModel>(&scene.model);
  if (!linkage) {
    Fail(&report, "the scene holds no linkage model");
    return finish();
  }
  if (parameter_values_si.size() != scene.parameters.size()) {
    Fail(&report, absl::StrFormat("expected %d parameter values, got %d",
                                  scene.parameters.size(), parameter_values_si.size()));
    return finish();
  }
  auto resolved = model::ResolveLinkage(*linkage, scene.effects, parameter_values_si);
  if (!resolved.ok()) {
    Fail(&report, std::string(resolved.status().message()));
    return finish();
  }
  const model::LinkageSystem& sys = *resolved;
  if (std::string bad = CheckOutputs(scene, sys); !bad.empty()) {
    Fail(&report, bad);
    return finish();
  }
  for (size_t i = 0; i < report.times_s.size(); ++i) {
    if (!(report.times_s[i] >= 0.0) || (i > 0 && report.times_s[i] < report.times_s[i - 1])) {
      Fail(&report, "the time grid must be non-negative and increasing");
      return finish();
    }
  }

  bool needs_loads = false;
  for (const spec::Output& o : scene.outputs) needs_loads = needs_loads || NeedsLoads(o);
  report.formulation = !needs_loads      ? Formulation::kKinematic
                       : sys.AnyFlexible() ? Formulation::kElastodynamic
                                           : Formulation::kKinetostatic;

  const size_t nt = report.times_s.size();
  report.outputs.resize(scene.outputs.size());
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    OutputValues& v = report.outputs[k];
    v.name = o.name;
    if (const auto* b = std::get_if<spec::BendingStressOutput>(&o.kind)) {
      const int nodes = KinetostaticSolver::NumNodes(sys.links[static_cast<size_t>(b->link)]);
      for (int n = 0; n < nodes; ++n) {
        v.series_labels.push_back(absl::StrFormat("node %d", n));
        v.series.emplace_back(nt, 0.0);
      }
    } else if (std::holds_alternative<spec::MassOutput>(o.kind)) {
      double mass = 0.0;
      for (const model::LinkageLink& l : sys.links) {
        if (l.has_section) mass += l.density_kg_per_m3 * l.area_m2 * l.length_m;
      }
      v.series_labels.push_back("mass");
      v.series.push_back({mass});
    } else {
      v.series_labels.push_back(o.name);
      v.series.emplace_back(nt, 0.0);
    }
  }

  KinematicSolver kinematics(sys);
  auto count = [&]() {
    report.counters.position_solves += kinematics.position_solves();
    report.counters.newton_iterations += kinematics.newton_iterations();
  };
  if (KinematicOutcome o = kinematics.Start(); !o.ok()) {
    count();
    Fail(&report, o);
    return finish();
  }
  const LinkageState start = kinematics.state();

  if (report.formulation == Formulation::kElastodynamic) {
    ElastodynamicResult elastic;
    const KinematicOutcome o =
        RunElastodynamic(sys, scene.integrator, report.times_s, &kinematics, &elastic);
    count();
    report.counters.time_steps = elastic.counters.steps;
    report.counters.rhs_evaluations = elastic.counters.rhs_evaluations;
    report.counters.jacobian_evaluations = elastic.counters.jacobian_evaluations;
    report.counters.newton_iterations += elastic.counters.nonlinear_iterations;
    if (!o.ok()) {
      Fail(&report, o);
      return finish();
    }
    for (size_t i = 0; i < nt; ++i) {
      RecordMotion(scene, sys, start, elastic.rigid_states[i], i, &report.outputs);
      for (size_t k = 0; k < scene.outputs.size(); ++k) {
        const spec::Output& out = scene.outputs[k];
        if (const auto* b = std::get_if<spec::BendingStressOutput>(&out.kind)) {
          const model::LinkageLink& l = sys.links[static_cast<size_t>(b->link)];
          const std::vector<double>& m = elastic.node_moment_n_m[i][static_cast<size_t>(b->link)];
          for (size_t n = 0; n < m.size(); ++n) {
            report.outputs[k].series[n][i] = l.StressFromMoment(m[n]);
          }
        } else if (std::holds_alternative<spec::DriveTorqueOutput>(out.kind)) {
          report.outputs[k].series[0][i] = elastic.drive_torque_n_m[i];
        }
      }
    }
    return finish();
  }

  KinetostaticSolver statics(sys);
  KinetostaticLoads loads;
  const WallTimeBudget budget(scene.integrator.max_wall_seconds);
  for (size_t i = 0; i < nt; ++i) {
    if (budget.Exceeded()) {
      count();
      Fail(&report, budget.Failure(report.times_s[i]));
      return finish();
    }
    if (KinematicOutcome o = kinematics.AdvanceTo(report.times_s[i]); !o.ok()) {
      count();
      Fail(&report, o);
      return finish();
    }
    const LinkageState& s = kinematics.state();
    RecordMotion(scene, sys, start, s, i, &report.outputs);
    if (!needs_loads) continue;
    if (KinematicOutcome o = statics.Solve(s, &loads); !o.ok()) {
      count();
      Fail(&report, o);
      return finish();
    }
    for (size_t k = 0; k < scene.outputs.size(); ++k) {
      const spec::Output& out = scene.outputs[k];
      if (const auto* b = std::get_if<spec::BendingStressOutput>(&out.kind)) {
        const model::LinkageLink& l = sys.links[static_cast<size_t>(b->link)];
        const std::vector<double>& m = loads.node_moment_n_m[static_cast<size_t>(b->link)];
        for (size_t n = 0; n < m.size(); ++n) {
          report.outputs[k].series[n][i] = l.StressFromMoment(m[n]);
        }
      } else if (std::holds_alternative<spec::DriveTorqueOutput>(out.kind)) {
        report.outputs[k].series[0][i] = loads.drive_torque_n_m;
      }
    }
  }
  count();
  return finish();
}

}  // namespace mbopt::solve
