#include "worker/multibody/linkage_geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <variant>

#include "absl/strings/str_format.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/beam_shape.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/linkage_analysis.h"
#include "worker/multibody/linkage_front_end.h"
#include "worker/multibody/linkage_system.h"
#include "worker/multibody/mechanism.h"

namespace mbopt::multibody {
namespace {

// Small enough that Newton, started from the previous instant, stays on the
// assembly branch between two drawn instants however coarse the grid.
constexpr double kDrawStepRad = std::numbers::pi / 18.0;
// A grid that needs more solved instants than this is drawn only up to
// there: a drawing has no use for millions of frames.
constexpr int kMaxSolvedInstants = 200000;
// A co-rotational element is drawn through this many points of its cubic
// shape between its nodes: with 6 elements a link reads as a smooth curve
// even magnified (mbopt draw --deflection-scale).
constexpr int kShapePointsPerElement = 3;

// A link point is carried in the link's frame: origin at joint a, x
// towards joint b.
void AppendLinkPoints(const LinkageSystem& sys, const std::vector<Eigen::Vector2d>& pins,
                      std::vector<spec::DrawingPosition>* at) {
  for (const LinkageLink& l : sys.links) {
    const Eigen::Vector2d a = pins[static_cast<size_t>(l.joint_a)];
    const Eigen::Vector2d e = (pins[static_cast<size_t>(l.joint_b)] - a).normalized();
    const Eigen::Vector2d n(-e.y(), e.x());
    for (const LinkagePoint& point : l.points) {
      const Eigen::Vector2d r = a + point.local_m.x() * e + point.local_m.y() * n;
      at->push_back(spec::DrawingPosition{r.x(), r.y()});
    }
  }
}

// One instant of a deflected linkage: each node where the rigid pins
// `rigid_m` put it on its link's chord, moved by its elastic displacement
// (`displacement_m[link][node]`, none when empty); a pin moves with the
// joint nodes there (shared by the links it joins), and the links' own
// points ride on the chord between the moved pins.
void AppendDeflectedInstant(const LinkageSystem& sys, const std::vector<Eigen::Vector2d>& rigid_m,
                            const std::vector<std::vector<Eigen::Vector2d>>& displacement_m,
                            std::vector<spec::DrawingPosition>* at) {
  const auto moved = [&](size_t link, int node) -> Eigen::Vector2d {
    if (displacement_m.empty() || displacement_m[link].empty()) return Eigen::Vector2d::Zero();
    return displacement_m[link][static_cast<size_t>(node)];
  };
  std::vector<Eigen::Vector2d> pins = rigid_m;
  for (size_t k = 0; k < sys.links.size(); ++k) {
    const LinkageLink& l = sys.links[k];
    if (l.both_ground) continue;
    pins[static_cast<size_t>(l.joint_a)] = rigid_m[static_cast<size_t>(l.joint_a)] + moved(k, 0);
    pins[static_cast<size_t>(l.joint_b)] = rigid_m[static_cast<size_t>(l.joint_b)] + moved(k, l.flexible_elements);
  }
  for (const Eigen::Vector2d& pin : pins) at->push_back(spec::DrawingPosition{pin.x(), pin.y()});
  AppendLinkPoints(sys, pins, at);
  for (size_t k = 0; k < sys.links.size(); ++k) {
    const LinkageLink& l = sys.links[k];
    if (l.both_ground) continue;
    const Eigen::Vector2d a = rigid_m[static_cast<size_t>(l.joint_a)], b = rigid_m[static_cast<size_t>(l.joint_b)];
    for (int node = 1; node < l.flexible_elements; ++node) {
      const Eigen::Vector2d r = a + (b - a) * (static_cast<double>(node) / l.flexible_elements) + moved(k, node);
      at->push_back(spec::DrawingPosition{r.x(), r.y()});
    }
  }
}

// The floating-frame analysis' own motion, every instant it solved.
void DrawDeflectedMotion(const spec::Scene& scene, const LinkageSystem& sys, const std::vector<double>& p,
                         budget::AnalysisBudget* budget, spec::SceneDrawing* d) {
  LinkageDeflection deflection;
  const spec::AnalysisReport report = AnalyzeLinkageScene(scene, p, budget, &deflection);
  for (size_t i = 0; i < deflection.rigid_states.size(); ++i) {
    d->times_s.push_back(report.times_s[i]);
    AppendDeflectedInstant(sys, deflection.rigid_states[i].position_m, deflection.node_displacement_m[i],
                           &d->points_m.emplace_back());
  }
  if (d->points_m.empty()) {
    // Nothing solved (it does not assemble, a moving link is rigid): the
    // pins as given, and why.
    std::vector<Eigen::Vector2d> pins;
    for (const LinkageJoint& j : sys.joints) pins.push_back(j.position_m);
    d->times_s.push_back(report.times_s.empty() ? 0.0 : report.times_s.front());
    AppendDeflectedInstant(sys, pins, {}, &d->points_m.emplace_back());
  }
  if (!report.ok()) d->failure = report.failure.reason;
}

// The points a co-rotational link's centre line holds between its pins:
// per element its shape points, then its end node unless that is joint b.
int CorotationalInnerPoints(const LinkageLink& l) {
  return l.flexible_elements * (kShapePointsPerElement + 1) - 1;
}

// One instant of a co-rotational analysis, its coordinates `q` (model
// `compiled`): each pin where the analysis puts it (the end nodes it
// joins), the links' own points on the chord between the pins, then each
// moving link's centre line between its pins: every element's cubic shape
// (beam_shape.h) and its inner nodes, the nodes the analysis' own
// coordinates.
void AppendCorotationalInstant(const LinkageSystem& sys, const CompiledLinkage& compiled, const Mechanism& mechanism,
                               const Eigen::VectorXd& q, std::vector<spec::DrawingPosition>* at) {
  std::vector<Eigen::Vector2d> pins;
  for (const Point& p : compiled.joint_point) {
    pins.push_back(p.body == kGround ? p.local_m : mechanism.PointPosition(p, q));
    at->push_back(spec::DrawingPosition{pins.back().x(), pins.back().y()});
  }
  AppendLinkPoints(sys, pins, at);
  std::vector<Eigen::Vector2d> shape;
  for (size_t k = 0; k < sys.links.size(); ++k) {
    const LinkageLink& l = sys.links[k];
    if (l.both_ground) continue;
    for (int e = 0; e < l.flexible_elements; ++e) {
      shape.clear();
      if (!AppendBeamInnerPoints(mechanism, compiled.link_first_element[k] + e, q, kShapePointsPerElement, &shape)) {
        // Coincident nodes (the analysis fails there): the node itself.
        shape.assign(kShapePointsPerElement, q.segment<2>(3 * (compiled.link_first_node[k] + e)));
      }
      for (const Eigen::Vector2d& r : shape) at->push_back(spec::DrawingPosition{r.x(), r.y()});
      if (e + 1 == l.flexible_elements) break;
      const Eigen::Index node = 3 * (compiled.link_first_node[k] + e + 1);
      at->push_back(spec::DrawingPosition{q[node], q[node + 1]});
    }
  }
}

// The co-rotational analysis' own motion, every instant it solved.
void DrawCorotationalMotion(const spec::Scene& scene, const LinkageSystem& sys, const std::vector<double>& p,
                            budget::AnalysisBudget* budget, spec::SceneDrawing* d) {
  LinkageDeflection deflection;
  const spec::AnalysisReport report = AnalyzeLinkageScene(scene, p, budget, &deflection);
  if (!deflection.corotational_q.empty()) {
    const CompiledLinkage compiled = CompileCorotationalLinkage(sys);
    const Mechanism mechanism(compiled.model);
    for (size_t i = 0; i < deflection.corotational_q.size(); ++i) {
      d->times_s.push_back(report.times_s[i]);
      AppendCorotationalInstant(sys, compiled, mechanism, deflection.corotational_q[i], &d->points_m.emplace_back());
    }
  } else {
    // Nothing solved (it does not assemble, a moving link is rigid): the
    // pins as given, the links straight between them, and why.
    std::vector<Eigen::Vector2d> pins;
    std::vector<spec::DrawingPosition>& at = d->points_m.emplace_back();
    for (const LinkageJoint& j : sys.joints) {
      pins.push_back(j.position_m);
      at.push_back(spec::DrawingPosition{j.position_m.x(), j.position_m.y()});
    }
    AppendLinkPoints(sys, pins, &at);
    for (const LinkageLink& l : sys.links) {
      if (l.both_ground) continue;
      const Eigen::Vector2d a = pins[static_cast<size_t>(l.joint_a)], b = pins[static_cast<size_t>(l.joint_b)];
      const int inner = CorotationalInnerPoints(l);
      for (int k = 1; k <= inner; ++k) {
        const Eigen::Vector2d r = a + (b - a) * (static_cast<double>(k) / (inner + 1));
        at.push_back(spec::DrawingPosition{r.x(), r.y()});
      }
    }
    d->times_s.push_back(report.times_s.empty() ? 0.0 : report.times_s.front());
  }
  if (!report.ok()) d->failure = report.failure.reason;
}

}  // namespace

spec::SceneDrawing DrawLinkageScene(const spec::Scene& scene, const std::vector<double>& p,
                                    budget::AnalysisBudget* budget) {
  spec::SceneDrawing d;
  d.scene_name = scene.name;
  const auto* linkage = std::get_if<spec::LinkageModel>(&scene.model);
  if (linkage == nullptr) {
    d.failure = "expected a linkage scene";
    return d;
  }
  absl::StatusOr<LinkageSystem> resolved = ResolveLinkage(*linkage, scene.effects, p);
  if (!resolved.ok()) {
    d.failure = std::string(resolved.status().message());
    return d;
  }
  const LinkageSystem& sys = *resolved;
  if (std::string why; LinkageDegreesOfFreedom(sys, &why) != 0) {
    d.failure = why;
    return d;
  }
  // A linkage the analysis follows elastically is drawn with its links'
  // deflection: the analysis' own motion, each moving link as its centre
  // line through its nodes (as a multibody scene's flexible links; in the
  // co-rotational formulation through its elements' cubic shapes too).
  const bool floating = UsesFloatingFrame(scene, sys);
  const bool corotational = UsesCorotational(scene, sys);
  const bool deflected = floating || corotational;
  // Points: the pins, then every link's own points, then the inner nodes of
  // the links drawn deflected.
  for (const LinkageJoint& j : sys.joints) {
    const int point = d.AddPoint(j.name);
    d.joints.push_back(spec::SceneDrawing::Joint{j.name, spec::SceneDrawing::JointKind::kPin, point, {}});
    if (j.ground) d.ground_points.push_back(point);
  }
  for (const LinkageLink& l : sys.links) {
    spec::SceneDrawing::Body body;
    body.name = l.name;
    if (!deflected || l.both_ground) body.points = {l.joint_a, l.joint_b};
    for (const LinkagePoint& point : l.points) body.points.push_back(d.AddPoint(l.name + "." + point.name));
    if (!body.points.empty()) d.bodies.push_back(std::move(body));
  }
  if (corotational) {
    for (const LinkageLink& l : sys.links) {
      if (l.both_ground) continue;
      spec::SceneDrawing::Line line;
      line.name = l.name;
      line.points.push_back(l.joint_a);
      for (int e = 0; e < l.flexible_elements; ++e) {
        for (int k = 1; k <= kShapePointsPerElement; ++k) {
          line.points.push_back(d.AddPoint(absl::StrFormat("%s.element %d.%d", l.name, e, k)));
        }
        if (e + 1 < l.flexible_elements) line.points.push_back(d.AddPoint(absl::StrFormat("%s.node %d", l.name, e + 1)));
      }
      line.points.push_back(l.joint_b);
      d.lines.push_back(std::move(line));
    }
    DrawCorotationalMotion(scene, sys, p, budget, &d);
    return d;
  }
  if (floating) {
    for (const LinkageLink& l : sys.links) {
      if (l.both_ground) continue;
      spec::SceneDrawing::Line line;
      line.name = l.name;
      line.points.push_back(l.joint_a);
      for (int k = 1; k < l.flexible_elements; ++k) {
        line.points.push_back(d.AddPoint(absl::StrFormat("%s.node %d", l.name, k)));
      }
      line.points.push_back(l.joint_b);
      d.lines.push_back(std::move(line));
    }
    DrawDeflectedMotion(scene, sys, p, budget, &d);
    return d;
  }

  // Flexible links in a linkage whose outputs are all positions and
  // rotations: its analysis is kinematic by design (the cheapest
  // formulation, docs/physics.md) and computes no deflection to draw.
  if (sys.AnyFlexible()) {
    d.note = "the flexible links are drawn rigid, as the analysis moves them: every output of the scene is a "
             "position or a rotation, so its analysis is kinematic and computes no deflection (a bending stress "
             "or drive torque output makes it elastic)";
  }
  const CompiledLinkage compiled = CompileLinkage(sys);
  const Mechanism mechanism(compiled.model);
  AssemblyOptions assembly_options;
  assembly_options.budget = budget;
  const Assembly assembled = Assemble(mechanism, 0.0, assembly_options);
  const auto append = [&](double t_s, const Eigen::VectorXd& q) {
    d.times_s.push_back(t_s);
    std::vector<spec::DrawingPosition>& at = d.points_m.emplace_back();
    std::vector<Eigen::Vector2d> pins;
    for (size_t j = 0; j < sys.joints.size(); ++j) {
      pins.push_back(mechanism.PointPosition(compiled.joint_point[j], q, t_s));
      at.push_back(spec::DrawingPosition{pins.back().x(), pins.back().y()});
    }
    AppendLinkPoints(sys, pins, &at);
  };
  if (!assembled.failure.ok()) {
    append(0.0, mechanism.InitialGuess());
    d.failure = "does not assemble (the pins as given are drawn): " + assembled.failure.reason;
    return d;
  }
  const std::vector<double> grid = scene.time_grid.Instants();
  const double omega = std::abs(sys.driver.angular_velocity_rad_per_s);
  std::vector<double> instants{0.0};
  for (const double t : grid) {
    const double from = instants.back();
    if (t <= from) continue;
    const int steps = std::max(1, static_cast<int>(std::ceil(omega * (t - from) / kDrawStepRad)));
    if (static_cast<double>(instants.size()) + steps > kMaxSolvedInstants) break;
    for (int k = 1; k < steps; ++k) instants.push_back(from + (t - from) * k / steps);
    instants.push_back(t);
  }
  size_t next = 0;
  const MotionCallback record = [&](const MotionSample& s) {
    if (budget != nullptr) {
      if (spec::AnalysisFailure f = budget->Check(s.t_s); !f.ok()) return f;
    }
    for (; next < grid.size() && grid[next] <= s.t_s; ++next) {
      if (grid[next] == s.t_s) append(s.t_s, s.q);
    }
    return spec::AnalysisFailure::Ok();
  };
  KinematicOptions options;
  options.budget = budget;
  KinematicCounters counters;
  const spec::AnalysisFailure outcome = RunKinematics(mechanism, assembled.q, instants, options, record, &counters);
  if (!outcome.ok()) {
    d.failure = outcome.reason;
  } else if (d.times_s.size() < grid.size()) {
    d.failure = absl::StrFormat("drawn up to t = %.6g s: the driver turns too often over the time grid to follow",
                                d.times_s.empty() ? 0.0 : d.times_s.back());
  }
  return d;
}

}  // namespace mbopt::multibody
