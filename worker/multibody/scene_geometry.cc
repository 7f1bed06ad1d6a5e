#include "worker/multibody/scene_geometry.h"

#include <algorithm>
#include <string>
#include <utility>
#include <variant>

#include "absl/strings/str_format.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/flexible_link.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/scene_analysis.h"
#include "worker/multibody/static_equilibrium.h"

namespace mbopt::multibody {
namespace {

// The node bodies of the flexible links follow the rigid bodies, link after
// link (CompileModel).
int FirstNodeOfLink(const spec::MultibodyModel& m, int link) {
  int first = static_cast<int>(m.bodies.size());
  for (int j = 0; j < link; ++j) first += m.flexible_links[static_cast<size_t>(j)].elements + 1;
  return first;
}

Eigen::Vector2d Resolve(const spec::Vec2& v, const std::vector<double>& p) {
  return Eigen::Vector2d(v.x.Resolve(p), v.y.Resolve(p));
}

bool SamePoint(const Point& a, const Point& b) {
  return a.body == b.body && a.input == b.input && a.local_m == b.local_m;
}

// The drawing point that follows `p`: an existing one at the same place of
// the same body, else a new one.
int PointIndex(const Point& p, MultibodyDrawingLayout* layout) {
  for (size_t k = 0; k < layout->points.size(); ++k) {
    if (SamePoint(layout->points[k], p)) return static_cast<int>(k);
  }
  layout->points.push_back(p);
  return layout->drawing.AddPoint(p.name);
}

}  // namespace

MultibodyDrawingLayout LayoutMultibodyDrawing(const spec::Scene& scene, const std::vector<double>& p,
                                              const Model& model) {
  const auto& sm = std::get<spec::MultibodyModel>(scene.model);
  MultibodyDrawingLayout layout;
  spec::SceneDrawing& d = layout.drawing;
  d.scene_name = scene.name;
  // The points of joints, springs and forces are the declared markers (same
  // body, same place): each is drawn once.
  for (size_t b = 0; b < sm.bodies.size(); ++b) {
    spec::SceneDrawing::Body body;
    body.name = sm.bodies[b].name;
    d.bodies.push_back(std::move(body));
  }
  auto add_to_body = [&](const Point& point) {
    const int index = PointIndex(point, &layout);
    if (point.body >= 0 && point.body < static_cast<int>(sm.bodies.size())) {
      std::vector<int>& points = d.bodies[static_cast<size_t>(point.body)].points;
      if (std::find(points.begin(), points.end(), index) == points.end()) points.push_back(index);
    }
    return index;
  };
  auto ground = [&](const Point& point) {
    const int index = PointIndex(point, &layout);
    if (point.body == kGround && point.input < 0 &&
        std::find(d.ground_points.begin(), d.ground_points.end(), index) == d.ground_points.end()) {
      d.ground_points.push_back(index);
    }
    return index;
  };
  auto point_of = [&](const Point& point) { return point.body == kGround ? ground(point) : add_to_body(point); };
  // Every declared marker is drawn, used or not: a marker left where it was
  // not meant to be is what a drawing should show.
  for (const spec::LinkPoint& marker : sm.ground_markers) {
    ground(Point{kGround, Resolve(marker.position_m, p), marker.name});
  }
  for (size_t b = 0; b < sm.bodies.size(); ++b) {
    for (const spec::LinkPoint& marker : sm.bodies[b].markers) {
      add_to_body(Point{static_cast<int>(b), Resolve(marker.position_m, p), sm.bodies[b].name + "." + marker.name});
    }
  }

  for (const Joint& j : model.joints) {
    point_of(j.a);
    const int at = point_of(j.b);
    spec::SceneDrawing::Joint joint;
    joint.name = j.name;
    joint.point = at;
    int axis_joint = -1;
    switch (j.kind) {
      case JointKind::kRevolute: joint.kind = spec::SceneDrawing::JointKind::kPin; break;
      case JointKind::kFixed: joint.kind = spec::SceneDrawing::JointKind::kFixed; break;
      case JointKind::kPrismatic:
        joint.kind = spec::SceneDrawing::JointKind::kSlider;
        axis_joint = static_cast<int>(&j - model.joints.data());
        break;
      case JointKind::kPointOnLine:
        joint.kind = spec::SceneDrawing::JointKind::kPinInSlot;
        axis_joint = static_cast<int>(&j - model.joints.data());
        break;
    }
    d.joints.push_back(std::move(joint));
    layout.axis_joints.push_back(axis_joint);
  }
  for (const RotationalSpringDamper& r : model.rotational_springs) {
    if (r.joint < 0 || r.joint >= static_cast<int>(d.joints.size())) continue;
    spec::SceneDrawing::Joint& joint = d.joints[static_cast<size_t>(r.joint)];
    joint.rotational_spring = joint.rotational_spring || r.stiffness_n_m_per_rad != 0.0;
    joint.rotational_damper = joint.rotational_damper || r.damping_n_m_s_per_rad != 0.0;
  }
  for (const SpringDamper& s : model.springs) {
    spec::SceneDrawing::Element element;
    element.name = s.name;
    element.a = point_of(s.a);
    element.b = point_of(s.b);
    element.spring = s.stiffness_n_per_m != 0.0 || !s.deflection_curve.empty();
    element.damper = s.damping_n_s_per_m != 0.0 || !s.velocity_curve.empty();
    d.elements.push_back(std::move(element));
  }
  for (size_t k = 0; k < model.point_forces.size(); ++k) {
    const PointForce& f = model.point_forces[k];
    spec::SceneDrawing::Load load;
    load.name = f.at.name.empty() ? absl::StrFormat("force %d", k + 1) : "force at " + f.at.name;
    load.point = point_of(f.at);
    const double norm = f.force_n.norm();
    if (norm > 0.0) {
      load.direction_x = f.force_n.x() / norm;
      load.direction_y = f.force_n.y() / norm;
    }
    d.loads.push_back(std::move(load));
  }
  for (const BodyTorque& t : model.torques) {
    if (t.body < 0 || t.body >= static_cast<int>(sm.bodies.size()) || t.torque_n_m == 0.0) continue;
    spec::SceneDrawing::Load load;
    load.name = "torque on " + sm.bodies[static_cast<size_t>(t.body)].name;
    load.kind = spec::SceneDrawing::LoadKind::kTorque;
    // The centre of mass, not part of the body's outline.
    load.point = PointIndex(Point{t.body, Eigen::Vector2d::Zero(), load.name}, &layout);
    load.direction_x = t.torque_n_m > 0.0 ? 1.0 : -1.0;
    load.direction_y = 0.0;
    d.loads.push_back(std::move(load));
  }
  for (size_t b = 0; b < sm.bodies.size(); ++b) {
    if (d.bodies[b].points.size() < 2) {
      add_to_body(Point{static_cast<int>(b), Eigen::Vector2d::Zero(), sm.bodies[b].name + " centre of mass"});
    }
  }
  for (size_t i = 0; i < model.inputs.size(); ++i) {
    const InputPoint& in = model.inputs[i];
    spec::SceneDrawing::Input input;
    input.name = in.name;
    input.point = PointIndex(Point{kGround, Eigen::Vector2d::Zero(), in.name, static_cast<int>(i)}, &layout);
    input.direction_x = in.direction.x();
    input.direction_y = in.direction.y();
    d.inputs.push_back(std::move(input));
  }
  for (size_t l = 0; l < sm.flexible_links.size(); ++l) {
    spec::SceneDrawing::Line line;
    line.name = sm.flexible_links[l].name;
    const int first = FirstNodeOfLink(sm, static_cast<int>(l));
    for (int k = 0; k <= sm.flexible_links[l].elements; ++k) {
      line.points.push_back(
          PointIndex(Point{first + k, Eigen::Vector2d::Zero(), absl::StrFormat("%s node %d", line.name, k)}, &layout));
    }
    d.lines.push_back(std::move(line));
  }
  return layout;
}

void AppendDrawingInstant(const Mechanism& mechanism, double t_s, const Eigen::VectorXd& q,
                          MultibodyDrawingLayout* layout) {
  spec::SceneDrawing& d = layout->drawing;
  d.times_s.push_back(t_s);
  std::vector<spec::DrawingPosition>& positions = d.points_m.emplace_back();
  positions.reserve(layout->points.size());
  for (const Point& p : layout->points) {
    const Eigen::Vector2d r = mechanism.PointPosition(p, q, t_s);
    positions.push_back(spec::DrawingPosition{r.x(), r.y()});
  }
  for (size_t j = 0; j < d.joints.size(); ++j) {
    const int model_joint = layout->axis_joints[j];
    if (model_joint < 0) continue;
    const Joint& joint = mechanism.model().joints[static_cast<size_t>(model_joint)];
    // The axis is fixed in body a.
    const double body_angle = joint.a.body == kGround ? 0.0 : q[3 * joint.a.body + 2];
    d.joints[j].axis_angle_rad.push_back(body_angle + joint.axis_angle_rad);
  }
}

spec::SceneDrawing DrawMultibodyScene(const spec::Scene& scene, const std::vector<double>& p,
                                      budget::AnalysisBudget* budget) {
  spec::SceneDrawing failed;
  failed.scene_name = scene.name;
  const auto* sm = std::get_if<spec::MultibodyModel>(&scene.model);
  if (sm == nullptr || p.size() != scene.parameters.size()) {
    failed.failure = absl::StrFormat("expected a multibody scene and %d parameter values", scene.parameters.size());
    return failed;
  }
  absl::StatusOr<Model> model = CompileModel(scene, p);
  if (!model.ok()) {
    failed.failure = std::string(model.status().message());
    return failed;
  }
  MultibodyDrawingLayout layout = LayoutMultibodyDrawing(scene, p, *model);
  const Mechanism mechanism(*model);
  AssemblyOptions assembly_options;
  assembly_options.budget = budget;
  // As the analysis: flexible links start with rigid-body velocities.
  Eigen::MatrixXd velocity_basis;
  if (!sm->flexible_links.empty()) {
    const int rigid = static_cast<int>(sm->bodies.size());
    velocity_basis = Eigen::MatrixXd::Zero(mechanism.num_coordinates(),
                                           3 * rigid + 3 * static_cast<int>(sm->flexible_links.size()));
    velocity_basis.topLeftCorner(3 * rigid, 3 * rigid).setIdentity();
    const Eigen::VectorXd q0 = mechanism.InitialGuess();
    for (size_t i = 0; i < sm->flexible_links.size(); ++i) {
      SetRigidLinkVelocityColumns(q0, FirstNodeOfLink(*sm, static_cast<int>(i)), sm->flexible_links[i].elements,
                                  3 * rigid + 3 * static_cast<int>(i), &velocity_basis);
    }
    assembly_options.velocity_basis = &velocity_basis;
  }
  const Assembly assembled = Assemble(mechanism, 0.0, assembly_options);
  if (!assembled.failure.ok()) {
    // The initial guess is drawn: it shows what would not assemble.
    AppendDrawingInstant(mechanism, 0.0, mechanism.InitialGuess(), &layout);
    layout.drawing.failure = "does not assemble (the initial guess is drawn): " + assembled.failure.reason;
    return std::move(layout.drawing);
  }
  const std::vector<double> grid = scene.time_grid.Instants();
  std::vector<double> times;
  if (grid.empty() || grid.front() > 0.0) times.push_back(0.0);
  times.insert(times.end(), grid.begin(), grid.end());
  size_t next = 0;
  const MotionCallback record = [&](const MotionSample& s) {
    if (budget != nullptr) {
      if (spec::AnalysisFailure f = budget->Check(s.t_s); !f.ok()) return f;
    }
    if (next < grid.size() && s.t_s == grid[next]) {
      ++next;
      AppendDrawingInstant(mechanism, s.t_s, s.q, &layout);
    }
    return spec::AnalysisFailure::Ok();
  };
  spec::AnalysisFailure outcome;
  if (sm->analysis == spec::MultibodyModel::Analysis::kStaticEquilibrium) {
    StaticOptions options;
    options.budget = budget;
    StaticCounters counters;
    outcome = RunStaticEquilibrium(mechanism, assembled.q, times, options, record, &counters);
  } else if (assembled.degrees_of_freedom == 0) {
    KinematicOptions options;
    options.budget = budget;
    KinematicCounters counters;
    outcome = RunKinematics(mechanism, assembled.q, times, options, record, &counters);
  } else {
    ForwardDynamicsCounters counters;
    outcome = IntegrateForward(mechanism, 0.0, assembled.q, assembled.v, times,
                               ForwardDynamicsOptions::Of(scene.integrator, budget), record, &counters);
  }
  if (!outcome.ok()) layout.drawing.failure = outcome.reason;
  return std::move(layout.drawing);
}

}  // namespace mbopt::multibody
