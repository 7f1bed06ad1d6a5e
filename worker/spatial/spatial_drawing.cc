#include "worker/spatial/spatial_drawing.h"

#include <algorithm>
#include <string>
#include <utility>
#include <variant>

#include "absl/strings/str_format.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/spatial/redundant_constraints.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_kinematics.h"
#include "worker/spatial/spatial_scene_analysis.h"
#include "worker/spatial/spatial_static_equilibrium.h"

namespace mbopt::spatial {
namespace {

using Eigen::Vector3d;
using DrawingKind = spec::SceneDrawing::JointKind;

// The drawing point that follows `p`: an existing one at the same place of
// the same body, else a new one named `name`.
int PointIndex(const Point& p, const std::string& name, SpatialDrawingLayout* layout) {
  for (size_t k = 0; k < layout->points.size(); ++k) {
    if (layout->points[k].body == p.body && layout->points[k].position_m == p.position_m) return static_cast<int>(k);
  }
  layout->points.push_back(p);
  return layout->drawing.AddPoint(name);
}

// A drawn joint's kind, and which of frame a's axes is its axis (-1: none).
// Universal joints: frame a's x axis, the second arm frame b's y axis.
struct JointSymbol {
  DrawingKind kind;
  int axis_of_a;
};
JointSymbol SymbolOf(Joint::Kind kind) {
  switch (kind) {
    case Joint::Kind::kSpherical: return {DrawingKind::kSpherical, -1};
    case Joint::Kind::kRevolute: return {DrawingKind::kPin, 2};
    case Joint::Kind::kUniversal: return {DrawingKind::kUniversal, 0};
    case Joint::Kind::kFixed: return {DrawingKind::kFixed, -1};
    case Joint::Kind::kPrismatic: return {DrawingKind::kSlider, 2};
    case Joint::Kind::kCylindrical: return {DrawingKind::kCylindrical, 2};
    case Joint::Kind::kPlanar: return {DrawingKind::kPlanar, 2};
    case Joint::Kind::kPointOnLine: return {DrawingKind::kPinInSlot, 2};
    case Joint::Kind::kPointOnPlane: return {DrawingKind::kPointOnPlane, 2};
  }
  return {DrawingKind::kSpherical, -1};
}

// `direction` (body axes) in world axes at q, unit. The Euler parameters
// hold their unit norm only to the integrator's tolerance, so the rotated
// vector is normalized rather than trusted.
spec::DrawingDirection WorldDirection(const SpatialSystem& system, int body, const Vector3d& direction,
                                      const Eigen::VectorXd& q) {
  Vector3d d = body == kGround ? direction : Vector3d(system.BodyRotation(body, q) * direction);
  const double norm = d.norm();
  if (norm > 0.0) d /= norm;
  return spec::DrawingDirection{d.x(), d.y(), d.z()};
}

}  // namespace

SpatialDrawingLayout LayoutSpatialDrawing(const spec::Scene& scene, const std::vector<double>& p, const Model& model) {
  const auto& sm = std::get<spec::SpatialModel>(scene.model);
  SpatialDrawingLayout layout;
  spec::SceneDrawing& d = layout.drawing;
  d.scene_name = scene.name;
  d.spatial = true;
  for (const Body& b : model.bodies) d.bodies.push_back(spec::SceneDrawing::Body{b.name, {}});
  auto add = [&](const Point& point, const std::string& name) {
    const int index = PointIndex(point, name, &layout);
    std::vector<int>& list =
        point.body == kGround ? d.ground_points : d.bodies[static_cast<size_t>(point.body)].points;
    if (std::find(list.begin(), list.end(), index) == list.end()) list.push_back(index);
    return index;
  };
  auto marker_name = [&](const spec::MarkerRef& ref) {
    if (ref.body < 0) return sm.ground_markers[static_cast<size_t>(ref.marker)].name;
    const spec::SpatialBody& body = sm.bodies[static_cast<size_t>(ref.body)];
    return body.name + "." + body.markers[static_cast<size_t>(ref.marker)].name;
  };
  // Every declared marker is drawn, used or not (a hardpoint left where it
  // was not meant to be is what a drawing should show), at the place
  // CompileSpatialModel resolves for it: a joint's or an element's point
  // is then the marker's own.
  for (size_t k = 0; k < sm.ground_markers.size(); ++k) {
    const spec::Vec3& at = sm.ground_markers[k].position_m;
    add(Point{kGround, Vector3d(at.x.Resolve(p), at.y.Resolve(p), at.z.Resolve(p))},
        marker_name(spec::MarkerRef{-1, static_cast<int>(k)}));
  }
  for (size_t b = 0; b < sm.bodies.size(); ++b) {
    for (size_t k = 0; k < sm.bodies[b].markers.size(); ++k) {
      const spec::Vec3& at = sm.bodies[b].markers[k].position_m;
      add(Point{static_cast<int>(b), Vector3d(at.x.Resolve(p), at.y.Resolve(p), at.z.Resolve(p))},
          marker_name(spec::MarkerRef{static_cast<int>(b), static_cast<int>(k)}));
    }
  }
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const Joint& joint = model.joints[j];
    add(Point{joint.a.body, joint.a.position_m}, marker_name(sm.joints[j].a));
    const int at = add(Point{joint.b.body, joint.b.position_m}, marker_name(sm.joints[j].b));
    const JointSymbol symbol = SymbolOf(joint.kind);
    spec::SceneDrawing::Joint drawn;
    drawn.name = joint.name;
    drawn.kind = symbol.kind;
    drawn.point = at;
    d.joints.push_back(std::move(drawn));
    SpatialDrawingLayout::Axis axis, second;
    if (symbol.axis_of_a >= 0) axis = {joint.a.body, joint.a.axes.col(symbol.axis_of_a)};
    if (joint.kind == Joint::Kind::kUniversal) second = {joint.b.body, joint.b.axes.col(1)};
    layout.axes.push_back(axis);
    layout.second_axes.push_back(second);
  }
  for (const RotationalSpringDamper& r : model.rotational_springs) {
    if (r.joint < 0 || r.joint >= static_cast<int>(d.joints.size())) continue;
    spec::SceneDrawing::Joint& joint = d.joints[static_cast<size_t>(r.joint)];
    joint.rotational_spring = joint.rotational_spring || r.stiffness_n_m_per_rad != 0.0;
    joint.rotational_damper = joint.rotational_damper || r.damping_n_m_s_per_rad != 0.0;
  }
  for (size_t k = 0; k < model.springs.size(); ++k) {
    const SpringDamper& s = model.springs[k];
    spec::SceneDrawing::Element element;
    element.name = s.name;
    element.a = add(s.a, marker_name(sm.springs[k].a));
    element.b = add(s.b, marker_name(sm.springs[k].b));
    element.spring = s.stiffness_n_per_m != 0.0 || !s.deflection_curve.x.empty();
    element.damper = s.damping_n_s_per_m != 0.0 || !s.velocity_curve.x.empty();
    d.elements.push_back(std::move(element));
  }
  for (size_t k = 0; k < model.bushings.size(); ++k) {
    const Bushing& b = model.bushings[k];
    spec::SceneDrawing::Element element;
    element.name = b.name;
    element.a = add(Point{b.a.body, b.a.position_m}, marker_name(sm.bushings[k].a));
    element.b = add(Point{b.b.body, b.b.position_m}, marker_name(sm.bushings[k].b));
    element.bushing = true;
    d.elements.push_back(std::move(element));
  }
  // Loads: where and which way, not how large (a time factor's sign
  // included).
  auto add_load = [&](spec::SceneDrawing::Load load, const Vector3d& vector, int body, bool body_axes) {
    const double norm = vector.norm();
    const Vector3d u = norm > 0.0 ? Vector3d(vector / norm) : Vector3d::Zero();
    load.direction_x = u.x();
    load.direction_y = u.y();
    load.direction_z = u.z();
    d.loads.push_back(std::move(load));
    layout.load_bodies.push_back(body_axes && body != kGround ? body : -1);
    layout.load_body_directions.push_back(u);
  };
  for (size_t k = 0; k < model.point_forces.size(); ++k) {
    const PointForce& f = model.point_forces[k];
    spec::SceneDrawing::Load load;
    load.name = f.name.empty() ? absl::StrFormat("force %d", k + 1) : f.name;
    load.point = add(f.at, marker_name(sm.point_forces[k].at));
    add_load(std::move(load), f.force_n, f.at.body, f.body_axes);
  }
  for (size_t k = 0; k < model.torques.size(); ++k) {
    const BodyTorque& t = model.torques[k];
    if (t.body < 0 || t.body >= static_cast<int>(model.bodies.size())) continue;
    spec::SceneDrawing::Load load;
    load.name = t.name.empty() ? "torque on " + model.bodies[static_cast<size_t>(t.body)].name : t.name;
    load.kind = spec::SceneDrawing::LoadKind::kTorque;
    // The centre of mass, not part of the body's outline.
    load.point = PointIndex(Point{t.body, Vector3d::Zero()}, load.name, &layout);
    add_load(std::move(load), t.torque_n_m, t.body, t.body_axes);
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    if (d.bodies[b].points.size() < 2) {
      add(Point{static_cast<int>(b), Vector3d::Zero()}, model.bodies[b].name + " centre of mass");
    }
  }
  return layout;
}

void AppendSpatialDrawingInstant(const SpatialSystem& system, double t_s, const Eigen::VectorXd& q,
                                 SpatialDrawingLayout* layout) {
  spec::SceneDrawing& d = layout->drawing;
  d.times_s.push_back(t_s);
  std::vector<spec::DrawingPosition>& positions = d.points_m.emplace_back();
  positions.reserve(layout->points.size());
  for (const Point& p : layout->points) {
    const Vector3d r = system.PointPosition(p, q);
    positions.push_back(spec::DrawingPosition{r.x(), r.y(), r.z()});
  }
  for (size_t j = 0; j < d.joints.size(); ++j) {
    const SpatialDrawingLayout::Axis& axis = layout->axes[j];
    if (!axis.direction.isZero()) {
      d.joints[j].axis_directions.push_back(WorldDirection(system, axis.body, axis.direction, q));
    }
    const SpatialDrawingLayout::Axis& second = layout->second_axes[j];
    if (!second.direction.isZero()) {
      d.joints[j].second_axis_directions.push_back(WorldDirection(system, second.body, second.direction, q));
    }
  }
  for (size_t k = 0; k < d.loads.size(); ++k) {
    if (layout->load_bodies[k] < 0) continue;
    d.loads[k].directions.push_back(WorldDirection(system, layout->load_bodies[k], layout->load_body_directions[k], q));
  }
}

spec::SceneDrawing DrawSpatialScene(const spec::Scene& scene, const std::vector<double>& p,
                                    budget::AnalysisBudget* budget) {
  spec::SceneDrawing failed;
  failed.scene_name = scene.name;
  failed.spatial = true;
  if (!std::holds_alternative<spec::SpatialModel>(scene.model) || p.size() != scene.parameters.size()) {
    failed.failure = absl::StrFormat("expected a spatial scene and %d parameter values", scene.parameters.size());
    return failed;
  }
  absl::StatusOr<Model> model = CompileSpatialModel(scene, p);
  if (!model.ok()) {
    failed.failure = std::string(model.status().message());
    return failed;
  }
  SpatialDrawingLayout layout = LayoutSpatialDrawing(scene, p, *model);
  const SpatialSystem system(*model);
  const SpatialAssembly assembled = AssembleSpatial(system, 0.0);
  if (!assembled.failure.ok()) {
    // The bodies' declared poses are drawn: they show what would not close.
    AppendSpatialDrawingInstant(system, 0.0, system.InitialGuess(), &layout);
    layout.drawing.failure = "does not assemble (the declared poses are drawn): " + assembled.failure.reason;
    return std::move(layout.drawing);
  }
  const std::vector<double> grid = scene.time_grid.Instants();
  std::vector<double> times;
  if (grid.empty() || grid.front() > 0.0) times.push_back(0.0);
  times.insert(times.end(), grid.begin(), grid.end());
  size_t next = 0;
  const multibody::MotionCallback record = [&](const multibody::MotionSample& s) {
    if (budget != nullptr) {
      if (spec::AnalysisFailure f = budget->Check(s.t_s); !f.ok()) return f;
    }
    if (next < grid.size() && s.t_s == grid[next]) {
      ++next;
      AppendSpatialDrawingInstant(system, s.t_s, s.q, &layout);
    }
    return spec::AnalysisFailure::Ok();
  };
  spec::AnalysisFailure outcome;
  if (std::get<spec::SpatialModel>(scene.model).analysis == spec::MultibodyModel::Analysis::kStaticEquilibrium) {
    multibody::StaticCounters counters;
    outcome = RunSpatialStaticEquilibrium(system, assembled, times, budget, record, &counters);
  } else if (assembled.degrees_of_freedom == 0) {
    SpatialKinematicOptions options;
    options.budget = budget;
    SpatialKinematicCounters counters;
    outcome = RunSpatialKinematics(system, assembled.q, times, options, record, &counters);
  } else {
    const multibody::ForwardDynamicsOptions options = multibody::ForwardDynamicsOptions::Of(scene.integrator, budget);
    multibody::ForwardDynamicsCounters counters;
    RedundantIntegrationCounters redundant;
    outcome = assembled.redundant_rows > 0
                  ? IntegrateWithRedundantRows(system, assembled.independent_combination, 0.0, assembled.q,
                                               assembled.v, times, options, record, &counters, &redundant)
                  : multibody::IntegrateForward(system, 0.0, assembled.q, assembled.v, times, options, record,
                                                &counters);
  }
  if (!outcome.ok()) layout.drawing.failure = outcome.reason;
  return std::move(layout.drawing);
}

}  // namespace mbopt::spatial
