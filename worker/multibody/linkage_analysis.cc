#include "worker/multibody/linkage_analysis.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <variant>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/flexible_link.h"
#include "worker/multibody/floating_frame.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/linkage_front_end.h"
#include "worker/multibody/linkage_system.h"
#include "worker/multibody/mechanism.h"

namespace mbopt::multibody {

namespace {

using spec::AnalysisReport;
using spec::FailureKind;
using spec::Formulation;
using spec::OutputValues;

// The driver turns at most this much between two instants of the kinematic
// analysis, so that Newton starts from a close prediction and a change of
// branch is seen where it happens (the interval is halved where needed).
constexpr double kRigidStepRad = 2.0 * std::numbers::pi / 18.0;
// The floating-frame integration asks for the rigid motion at every one of
// its steps, solved from the nearest instant kept: finer, so that Newton
// closes in one or two iterations.
constexpr double kTrailStepRad = 2.0 * std::numbers::pi / 180.0;
// More instants than this means the time grid spans more turns of the
// driver than any analysis can follow (a hostile or mistyped scene): it is
// refused before any is solved.
constexpr double kMaxKinematicInstants = 1e6;
// Positions are closed to this per metre of the longest link (at least
// 1 m): a few units of round-off.
constexpr double kPositionToleranceM = 1e-14;

// Wraps to (-pi, pi].
double WrapAngle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

std::vector<double> GridTimes(const spec::TimeGrid& grid) {
  if (grid.points <= 1) return {grid.end_s};
  std::vector<double> t(static_cast<size_t>(grid.points));
  for (int i = 0; i < grid.points; ++i) {
    t[static_cast<size_t>(i)] = grid.start_s + (grid.end_s - grid.start_s) * i / (grid.points - 1);
  }
  return t;
}

// t = 0, then the grid's instants with enough in between that the driver
// turns at most `step_rad` from one to the next. Empty `why` on success.
std::vector<double> KinematicInstants(const std::vector<double>& grid, double omega, double step_rad,
                                      std::string* why) {
  double total = 0.0;
  double previous = 0.0;
  for (double t : grid) {
    total += std::ceil(std::abs(omega) * (t - previous) / step_rad) + 1.0;
    previous = t;
  }
  if (!(total <= kMaxKinematicInstants)) {
    *why = absl::StrFormat(
        "the driver turns %.3g rad (%.3g rad/s) by t = %.6g s: following it in steps of at most %.3g rad needs "
        "more than %.0f kinematic instants; shorten the time grid or slow the driver",
        std::abs(omega) * previous, omega, previous, step_rad, kMaxKinematicInstants);
    return {};
  }
  std::vector<double> instants{0.0};
  for (double t : grid) {
    const double from = instants.back();
    if (t <= from) continue;
    const int steps = static_cast<int>(std::ceil(std::abs(omega) * (t - from) / step_rad));
    for (int k = 1; k < steps; ++k) instants.push_back(from + (t - from) * k / steps);
    instants.push_back(t);
  }
  return instants;
}

bool OutputNeedsLoads(const spec::Output& o) {
  return std::holds_alternative<spec::BendingStressOutput>(o.kind) ||
         std::holds_alternative<spec::DriveTorqueOutput>(o.kind);
}

void Fail(AnalysisReport* report, const spec::AnalysisFailure& failure) { report->Fail(failure.kind, failure.reason); }
void Fail(AnalysisReport* report, std::string why) { report->Fail(FailureKind::kInvalidModel, std::move(why)); }

// Checks that every output fits a linkage and refers to existing items.
std::string CheckOutputs(const spec::Scene& scene, const LinkageSystem& sys) {
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
void RecordMotion(const spec::Scene& scene, const LinkageSystem& sys, const LinkageState& start,
                  const LinkageState& s, size_t instant, std::vector<OutputValues>* out) {
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    std::vector<double>& series = (*out)[k].series[0];  // motion outputs have one series
    if (const auto* p = std::get_if<spec::PointPositionOutput>(&o.kind)) {
      Eigen::Vector2d r;
      if (p->joint >= 0) {
        r = s.position_m[static_cast<size_t>(p->joint)];
      } else {
        const LinkageLink& l = sys.links[static_cast<size_t>(p->link)];
        const Eigen::Vector2d e = s.LinkVector(l).normalized();
        const Eigen::Vector2d n(-e.y(), e.x());
        const Eigen::Vector2d& local = l.points[static_cast<size_t>(p->point)].local_m;
        r = s.position_m[static_cast<size_t>(l.joint_a)] + local.x() * e + local.y() * n;
      }
      series[instant] = p->axis == spec::Axis::kX ? r.x() : r.y();
    } else if (const auto* rot = std::get_if<spec::LinkRotationOutput>(&o.kind)) {
      const LinkageLink& l = sys.links[static_cast<size_t>(rot->link)];
      series[instant] = WrapAngle(s.LinkAngle(l) - start.LinkAngle(l));
    }
  }
}

// Bending stresses and drive torque of instant `i` from node moments.
void RecordLoads(const spec::Scene& scene, const LinkageSystem& sys,
                 const std::vector<std::vector<double>>& node_moment_n_m, double drive_torque_n_m, size_t i,
                 std::vector<OutputValues>* out) {
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    if (const auto* b = std::get_if<spec::BendingStressOutput>(&o.kind)) {
      const LinkageLink& l = sys.links[static_cast<size_t>(b->link)];
      const std::vector<double>& m = node_moment_n_m[static_cast<size_t>(b->link)];
      for (size_t n = 0; n < m.size(); ++n) (*out)[k].series[n][i] = l.StressFromMoment(m[n]);
    } else if (std::holds_alternative<spec::DriveTorqueOutput>(o.kind)) {
      (*out)[k].series[0][i] = drive_torque_n_m;
    }
  }
}


// Bending moment at every node of every co-rotational link (the moment a
// node passes on: minus the end moment at a of the element after it, the
// end moment at b of the element before it, their mean at an inner node);
// false if an element's nodes coincide.
bool CorotationalMoments(const LinkageSystem& sys, const Mechanism& mech, const CompiledLinkage& c,
                         const MotionSample& s, std::vector<std::vector<double>>* moments) {
  moments->assign(sys.links.size(), {});
  for (size_t i = 0; i < sys.links.size(); ++i) {
    const int elements = sys.links[i].flexible_elements;
    std::vector<double>& out = (*moments)[i];
    out.assign(static_cast<size_t>(StressNodes(sys.links[i])), 0.0);
    if (c.link_first_element[i] < 0) continue;
    std::vector<int> count(out.size(), 0);
    for (int e = 0; e < elements; ++e) {
      BeamLoads loads;
      if (!mech.BeamEndLoads(c.link_first_element[i] + e, s.q, s.v, &loads)) return false;
      out[static_cast<size_t>(e)] -= loads.moment_a_n_m;
      out[static_cast<size_t>(e + 1)] += loads.moment_b_n_m;
      ++count[static_cast<size_t>(e)];
      ++count[static_cast<size_t>(e + 1)];
    }
    for (size_t k = 0; k < out.size(); ++k) out[k] /= count[k];
  }
  return true;
}

// The co-rotational formulation: forward dynamics (IDAS) of the linkage
// whose moving links are co-rotational beams, the driver turning the driven
// link's root. Positions and rotations are those of the deformed links'
// ends (a link's rotation: its chord's).
void AnalyzeCorotational(const spec::Scene& scene, const LinkageSystem& sys, budget::AnalysisBudget* budget,
                         AnalysisReport* report, LinkageDeflection* deflection) {
  report->formulation = Formulation::kDynamic;
  for (size_t i = 0; i < sys.links.size(); ++i) {
    if (!sys.links[i].both_ground && sys.links[i].flexible_elements <= 0) {
      Fail(report, absl::StrFormat("the co-rotational formulation needs every moving link flexible; %s is rigid",
                                   sys.LinkLabel(static_cast<int>(i))));
      return;
    }
  }
  const CompiledLinkage compiled = CompileCorotationalLinkage(sys);
  const Mechanism mechanism(compiled.model);
  // The links start with rigid-body velocities: v = T w, w holding per link
  // its end a's (x', y') and its angular rate.
  int moving = 0;
  for (const LinkageLink& l : sys.links) moving += l.both_ground ? 0 : 1;
  Eigen::MatrixXd velocity_basis = Eigen::MatrixXd::Zero(mechanism.num_coordinates(), 3 * moving);
  const Eigen::VectorXd q0 = mechanism.InitialGuess();
  int column = 0;
  for (size_t i = 0; i < sys.links.size(); ++i) {
    const int a = compiled.link_first_node[i];
    if (a < 0) continue;
    SetRigidLinkVelocityColumns(q0, a, sys.links[i].flexible_elements, column, &velocity_basis);
    column += 3;
  }
  AssemblyOptions assembly_options;
  assembly_options.velocity_basis = &velocity_basis;
  const Assembly assembled = Assemble(mechanism, 0.0, assembly_options);
  report->counters.position_solves += 1;
  report->counters.newton_iterations += assembled.newton_iterations;
  if (!assembled.failure.ok()) {
    report->Fail(FailureKind::kAssembly,
                 absl::StrFormat("the mechanism cannot assemble at t = 0 s (driver angle %.6g rad): %s",
                                 sys.driver.start_angle_rad, assembled.failure.reason));
    return;
  }
  if (!assembled.redundant.empty()) {
    Fail(report, absl::StrFormat("redundant constraints at joint(s) %s", absl::StrJoin(assembled.redundant, ", ")));
    return;
  }
  const MotionSample at_start{0.0, assembled.q, assembled.v, Eigen::VectorXd::Zero(assembled.q.size()), {}, {}, 0};
  LinkageState start, state;
  ToLinkageState(mechanism, compiled, at_start, &start);
  std::vector<double> times;
  if (report->times_s.empty() || report->times_s.front() > 0.0) times.push_back(0.0);
  for (double t : report->times_s) {
    if (times.empty() || t > times.back()) times.push_back(t);
  }
  const size_t nt = report->times_s.size();
  size_t next = 0;
  std::vector<std::vector<double>> moments;
  const MotionCallback record = [&](const MotionSample& s) {
    if (next < nt && report->times_s[next] == s.t_s) {
      ToLinkageState(mechanism, compiled, s, &state);
      if (!CorotationalMoments(sys, mechanism, compiled, s, &moments)) {
        return spec::AnalysisFailure::Of(FailureKind::kNonFiniteValue,
                                         absl::StrFormat("flexible link nodes coincide at t = %.6g s", s.t_s));
      }
    }
    for (; next < nt && report->times_s[next] == s.t_s; ++next) {
      RecordMotion(scene, sys, start, state, next, &report->outputs);
      RecordLoads(scene, sys, moments, -s.lambda[mechanism.row_of_driver(0)], next, &report->outputs);
      if (deflection != nullptr) deflection->corotational_q.push_back(s.q);
    }
    return spec::AnalysisFailure::Ok();
  };
  ForwardDynamicsOptions options = ForwardDynamicsOptions::Of(scene.integrator, budget);
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure outcome =
      IntegrateForward(mechanism, 0.0, assembled.q, assembled.v, times, options, record, &counters);
  report->counters.time_steps = counters.steps;
  report->counters.rhs_evaluations = counters.residual_evaluations;
  report->counters.jacobian_evaluations = counters.jacobian_evaluations;
  report->counters.newton_iterations += counters.nonlinear_iterations;
  if (!outcome.ok()) Fail(report, outcome);
}

}  // namespace

bool UsesFloatingFrame(const spec::Scene& scene, const LinkageSystem& sys) {
  const auto* linkage = std::get_if<spec::LinkageModel>(&scene.model);
  if (linkage == nullptr || !sys.AnyFlexible() ||
      linkage->flexible_formulation == spec::FlexibleFormulation::kCorotational) {
    return false;
  }
  return NeedsLoads(scene);
}

bool UsesCorotational(const spec::Scene& scene, const LinkageSystem& sys) {
  const auto* linkage = std::get_if<spec::LinkageModel>(&scene.model);
  return linkage != nullptr && sys.AnyFlexible() &&
         linkage->flexible_formulation == spec::FlexibleFormulation::kCorotational && NeedsLoads(scene);
}

bool NeedsLoads(const spec::Scene& scene) {
  return std::any_of(scene.outputs.begin(), scene.outputs.end(), OutputNeedsLoads);
}

AnalysisReport AnalyzeLinkageScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                   budget::AnalysisBudget* budget, LinkageDeflection* deflection) {
  AnalysisReport report;
  report.times_s = GridTimes(scene.time_grid);
  const auto* linkage = std::get_if<spec::LinkageModel>(&scene.model);
  if (!linkage) {
    Fail(&report, "the scene holds no linkage model");
    return report;
  }
  if (parameter_values_si.size() != scene.parameters.size()) {
    Fail(&report, absl::StrFormat("expected %d parameter values, got %d", scene.parameters.size(),
                                  parameter_values_si.size()));
    return report;
  }
  auto resolved = ResolveLinkage(*linkage, scene.effects, parameter_values_si);
  if (!resolved.ok()) {
    Fail(&report, std::string(resolved.status().message()));
    return report;
  }
  const LinkageSystem& sys = *resolved;
  if (std::string bad = CheckOutputs(scene, sys); !bad.empty()) {
    Fail(&report, bad);
    return report;
  }
  for (size_t i = 0; i < report.times_s.size(); ++i) {
    if (!(report.times_s[i] >= 0.0) || (i > 0 && report.times_s[i] < report.times_s[i - 1])) {
      Fail(&report, "the time grid must be non-negative and increasing");
      return report;
    }
  }

  const bool needs_loads = NeedsLoads(scene);
  report.formulation = !needs_loads        ? Formulation::kKinematic
                       : sys.AnyFlexible() ? Formulation::kElastodynamic
                                           : Formulation::kKinetostatic;
  const bool elastic = report.formulation == Formulation::kElastodynamic;

  const size_t nt = report.times_s.size();
  report.outputs.resize(scene.outputs.size());
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    OutputValues& v = report.outputs[k];
    v.name = o.name;
    if (const auto* b = std::get_if<spec::BendingStressOutput>(&o.kind)) {
      const int nodes = StressNodes(sys.links[static_cast<size_t>(b->link)]);
      for (int n = 0; n < nodes; ++n) {
        v.series_labels.push_back(absl::StrFormat("node %d", n));
        v.series.emplace_back(nt, 0.0);
      }
    } else if (std::holds_alternative<spec::MassOutput>(o.kind)) {
      double mass = 0.0;
      for (const LinkageLink& l : sys.links) {
        if (l.has_section) mass += l.density_kg_per_m3 * l.area_m2 * l.length_m;
      }
      v.series_labels.push_back("mass");
      v.series.push_back({mass});
    } else {
      v.series_labels.push_back(o.name);
      v.series.emplace_back(nt, 0.0);
    }
  }

  if (std::string why; LinkageDegreesOfFreedom(sys, &why) != 0) {
    Fail(&report, why);
    return report;
  }
  if (elastic && linkage->flexible_formulation == spec::FlexibleFormulation::kCorotational) {
    AnalyzeCorotational(scene, sys, budget, &report, deflection);
    return report;
  }
  const CompiledLinkage compiled = CompileLinkage(sys);
  const Mechanism mechanism(compiled.model);
  const Assembly assembled = Assemble(mechanism, 0.0);
  report.counters.position_solves += 1;
  report.counters.newton_iterations += assembled.newton_iterations;
  if (!assembled.failure.ok()) {
    report.Fail(FailureKind::kAssembly,
                absl::StrFormat("the mechanism cannot assemble at t = 0 s (driver angle %.6g rad): %s",
                                sys.driver.start_angle_rad, assembled.failure.reason));
    return report;
  }
  if (!assembled.redundant.empty()) {
    Fail(&report, absl::StrFormat("redundant constraints at joint(s) %s", absl::StrJoin(assembled.redundant, ", ")));
    return report;
  }
  std::string too_many;
  const std::vector<double> instants = KinematicInstants(
      report.times_s, sys.driver.angular_velocity_rad_per_s, elastic ? kTrailStepRad : kRigidStepRad, &too_many);
  if (!too_many.empty()) {
    Fail(&report, too_many);
    return report;
  }

  KinematicOptions options;
  options.budget = budget;
  options.inverse_dynamics = needs_loads && !elastic;
  // The floating-frame integration reads the motion at thousands of
  // instants: closed to round-off, not to the engine's default 1e-11 m, so
  // that its loads do not carry the noise of where Newton stopped.
  if (elastic) {
    double longest_m = 1.0;
    for (const LinkageLink& l : sys.links) longest_m = std::max(longest_m, l.length_m);
    options.assembly.position_tolerance = kPositionToleranceM * longest_m;
  }
  KinematicCounters counters;
  LinkageState start, state;
  bool started = false;
  size_t next = 0;
  std::vector<MotionSample> trail;  // the elastic analysis' rigid motion at `instants`
  RigidBarLoads loads;
  const MotionCallback record = [&](const MotionSample& s) {
    if (!started) {
      ToLinkageState(mechanism, compiled, s, &start);
      started = true;
    }
    if (elastic) {
      trail.push_back(s);
      return spec::AnalysisFailure::Ok();
    }
    if (next < nt && report.times_s[next] == s.t_s) {
      ToLinkageState(mechanism, compiled, s, &state);
      if (needs_loads) RigidBarMoments(sys, mechanism, compiled, s, state, &loads);
    }
    // Equal grid instants (a grid of zero span) share the one state.
    for (; next < nt && report.times_s[next] == s.t_s; ++next) {
      RecordMotion(scene, sys, start, state, next, &report.outputs);
      if (needs_loads) RecordLoads(scene, sys, loads.node_moment_n_m, loads.drive_torque_n_m, next, &report.outputs);
    }
    return spec::AnalysisFailure::Ok();
  };
  const spec::AnalysisFailure outcome = RunKinematics(mechanism, assembled.q, instants, options, record, &counters);
  if (!elastic || !outcome.ok()) {
    report.counters.position_solves += counters.position_solves;
    report.counters.newton_iterations += counters.newton_iterations;
    if (!outcome.ok()) Fail(&report, outcome);
    return report;
  }

  // The rigid motion at the integrator's instants, each solved from the
  // nearest kept instant.
  const RigidMotionAt rigid_motion = [&](double t, LinkageState* out) {
    auto it = std::lower_bound(trail.begin(), trail.end(), t,
                               [](const MotionSample& s, double v) { return s.t_s < v; });
    const MotionSample* near = nullptr;
    if (it == trail.end()) {
      near = &trail.back();
    } else if (it == trail.begin()) {
      near = &*it;
    } else {
      near = (t - std::prev(it)->t_s < it->t_s - t) ? &*std::prev(it) : &*it;
    }
    MotionSample at;
    if (spec::AnalysisFailure f = SolveMotionNear(mechanism, *near, t, options, &at, &counters); !f.ok()) return f;
    ToLinkageState(mechanism, compiled, at, out);
    return spec::AnalysisFailure::Ok();
  };
  FloatingFrameResult result;
  const spec::AnalysisFailure o =
      RunFloatingFrame(sys, scene.integrator, report.times_s, rigid_motion, budget, &result, deflection != nullptr);
  if (deflection != nullptr) {
    deflection->rigid_states = result.rigid_states;
    deflection->node_displacement_m = std::move(result.node_displacement_m);
  }
  report.counters.position_solves += counters.position_solves;
  report.counters.newton_iterations += counters.newton_iterations;
  report.counters.time_steps = result.counters.steps;
  report.counters.rhs_evaluations = result.counters.rhs_evaluations;
  report.counters.jacobian_evaluations = result.counters.jacobian_evaluations;
  report.counters.newton_iterations += result.counters.nonlinear_iterations;
  if (!o.ok()) {
    Fail(&report, o);
    return report;
  }
  for (size_t i = 0; i < nt; ++i) {
    RecordMotion(scene, sys, start, result.rigid_states[i], i, &report.outputs);
    RecordLoads(scene, sys, result.node_moment_n_m[i], result.drive_torque_n_m[i], i, &report.outputs);
  }
  return report;
}

}  // namespace mbopt::multibody
