#include "worker/multibody/linkage_front_end.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>
#include <utility>

#include "absl/strings/str_format.h"
#include "worker/multibody/flexible_link.h"

namespace mbopt::multibody {
namespace {

constexpr int kDefaultStressElements = 6;

// The end `end` (0: joint a) of a bar of length `length_m`, in its body's axes.
Eigen::Vector2d EndMarker(double length_m, int end) {
  return Eigen::Vector2d(end == 0 ? -0.5 * length_m : 0.5 * length_m, 0.0);
}

// Revolute joints at the pins (named after them) and the driver on the
// driven bar's pivot; `end_point(link, end)` is the model point at a moving
// link's end (0: joint a).
void AddPinsAndDriver(const LinkageSystem& sys, const std::function<Point(int, int)>& end_point,
                      CompiledLinkage* out) {
  const LinkageDriver& driver = sys.driver;
  out->joint_point.assign(sys.joints.size(), Point{});
  int driven_joint = -1;
  for (size_t j = 0; j < sys.joints.size(); ++j) {
    const LinkageJoint& pin = sys.joints[j];
    Point ground{kGround, pin.position_m, pin.name};
    out->joint_point[j] = ground;
    std::vector<std::pair<int, int>> ends;  // (link, end) of the moving bars pinned here
    for (size_t i = 0; i < sys.links.size(); ++i) {
      const LinkageLink& l = sys.links[i];
      if (l.both_ground) continue;
      if (l.joint_a == static_cast<int>(j)) ends.emplace_back(static_cast<int>(i), 0);
      if (l.joint_b == static_cast<int>(j)) ends.emplace_back(static_cast<int>(i), 1);
    }
    auto marker = [&](const std::pair<int, int>& end) {
      Point p = end_point(end.first, end.second);
      p.name = pin.name;
      return p;
    };
    if (!pin.ground && !ends.empty()) out->joint_point[j] = marker(ends.front());
    for (size_t k = pin.ground ? 0 : 1; k < ends.size(); ++k) {
      Joint joint;
      joint.name = pin.name;
      joint.kind = JointKind::kRevolute;
      CompiledLinkage::PinEnds pe;
      if (pin.ground) {
        joint.a = ground;
      } else {
        joint.a = marker(ends.front());
        pe.link_a = ends.front().first;
        pe.end_a = ends.front().second;
      }
      joint.b = marker(ends[k]);
      pe.link_b = ends[k].first;
      pe.end_b = ends[k].second;
      if (pin.ground && static_cast<int>(j) == driver.pivot_joint && ends[k].first == driver.link) {
        driven_joint = static_cast<int>(out->model.joints.size());
      }
      out->model.joints.push_back(std::move(joint));
      out->pin_ends.push_back(pe);
    }
  }
  if (driven_joint >= 0) {
    Driver d;
    d.joint = driven_joint;
    d.profile.kind = Profile::Kind::kConstantRate;
    const bool pivot_is_a = driver.pivot_joint == sys.links[static_cast<size_t>(driver.link)].joint_a;
    d.profile.start = driver.start_angle_rad + (pivot_is_a ? 0.0 : std::numbers::pi);
    d.profile.rate = driver.angular_velocity_rad_per_s;
    out->model.drivers.push_back(d);
  }
}

// A moving link's start pose: its angle (joint a to joint b) and where its
// joint a is. The driven link starts at the driver's angle from its pivot;
// the others along their given pins (which may be only a guess: assembly
// closes the loops).
void StartPose(const LinkageSystem& sys, int link, double* angle_rad, Eigen::Vector2d* end_a_m) {
  const LinkageLink& l = sys.links[static_cast<size_t>(link)];
  const Eigen::Vector2d ra = sys.joints[static_cast<size_t>(l.joint_a)].position_m;
  const Eigen::Vector2d rb = sys.joints[static_cast<size_t>(l.joint_b)].position_m;
  *angle_rad = (rb - ra).norm() > 0.0 ? std::atan2(rb.y() - ra.y(), rb.x() - ra.x()) : 0.0;
  *end_a_m = ra;
  if (link == sys.driver.link) {
    const bool pivot_at_b = sys.driver.pivot_joint == l.joint_b;
    *angle_rad = sys.driver.start_angle_rad + (pivot_at_b ? std::numbers::pi : 0.0);
    if (pivot_at_b) *end_a_m = rb - l.length_m * Eigen::Vector2d(std::cos(*angle_rad), std::sin(*angle_rad));
  }
}

}  // namespace

CompiledLinkage CompileLinkage(const LinkageSystem& sys) {
  CompiledLinkage out;
  Model& m = out.model;
  out.link_body.assign(sys.links.size(), -1);
  for (size_t i = 0; i < sys.links.size(); ++i) {
    const LinkageLink& l = sys.links[i];
    if (l.both_ground) continue;
    double angle = 0.0;
    Eigen::Vector2d end_a;
    StartPose(sys, static_cast<int>(i), &angle, &end_a);
    const Eigen::Vector2d centre = end_a + 0.5 * l.length_m * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    const double mu = l.has_section ? l.mass_per_length_kg_per_m() : 0.0;
    const double rho_i = l.has_section && l.rotary_inertia ? l.density_kg_per_m3 * l.second_moment_m4() : 0.0;
    const double mass = mu * l.length_m;
    out.link_body[i] = static_cast<int>(m.bodies.size());
    m.bodies.push_back(Body{l.name, mass, mass * l.length_m * l.length_m / 12.0 + rho_i * l.length_m,
                            centre, angle});
  }
  AddPinsAndDriver(sys, [&](int link, int end) {
    const LinkageLink& l = sys.links[static_cast<size_t>(link)];
    return Point{out.link_body[static_cast<size_t>(link)], EndMarker(l.length_m, end), l.name};
  }, &out);
  if (sys.has_gravity) m.gravity_m_per_s2 = sys.gravity_m_per_s2;
  return out;
}

CompiledLinkage CompileCorotationalLinkage(const LinkageSystem& sys) {
  CompiledLinkage out;
  const size_t n = sys.links.size();
  out.link_body.assign(n, -1);
  out.link_first_node.assign(n, -1);
  out.link_first_element.assign(n, -1);
  double damping_s = 0.0;
  if (sys.has_structural_damping) {
    double lowest_rad_per_s = INFINITY;
    for (size_t i = 0; i < n; ++i) {
      const LinkageLink& l = sys.links[i];
      if (l.both_ground) continue;
      // First roots (beta L)^2 of the clamped-pinned and pinned-pinned beams.
      const double root = static_cast<int>(i) == sys.driver.link ? 15.4182057 : std::numbers::pi * std::numbers::pi;
      const double ei = l.youngs_modulus_pa * l.second_moment_m4();
      lowest_rad_per_s = std::min(
          lowest_rad_per_s, root * std::sqrt(ei / (l.mass_per_length_kg_per_m() * std::pow(l.length_m, 4))));
    }
    if (std::isfinite(lowest_rad_per_s) && lowest_rad_per_s > 0.0) {
      damping_s = 2.0 * sys.structural_damping_ratio / lowest_rad_per_s;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const LinkageLink& l = sys.links[i];
    if (l.both_ground) continue;
    FlexibleLinkSpec link;
    link.name = l.name;
    StartPose(sys, static_cast<int>(i), &link.angle_rad, &link.start_m);
    link.length_m = l.length_m;
    link.axial_stiffness_n = l.youngs_modulus_pa * l.area_m2;
    link.bending_stiffness_n_m2 = l.youngs_modulus_pa * l.second_moment_m4();
    link.mass_per_length_kg_per_m = l.mass_per_length_kg_per_m();
    if (l.rotary_inertia) link.rotary_inertia_per_length_kg_m = l.density_kg_per_m3 * l.second_moment_m4();
    link.damping_s = damping_s;
    link.elements = l.flexible_elements;
    const FlexibleLinkNodes nodes = AddFlexibleLink(link, &out.model);
    out.link_first_node[i] = nodes.first_node;
    out.link_first_element[i] = nodes.first_element;
  }
  AddPinsAndDriver(sys, [&](int link, int end) {
    const int elements = sys.links[static_cast<size_t>(link)].flexible_elements;
    return Point{out.link_first_node[static_cast<size_t>(link)] + (end == 0 ? 0 : elements), Eigen::Vector2d::Zero(),
                 sys.links[static_cast<size_t>(link)].name};
  }, &out);
  if (sys.has_gravity) out.model.gravity_m_per_s2 = sys.gravity_m_per_s2;
  return out;
}

int LinkageDegreesOfFreedom(const LinkageSystem& sys, std::string* message) {
  int unknowns = 0;
  for (const LinkageJoint& j : sys.joints) unknowns += j.ground ? 0 : 2;
  int equations = 2;  // the driven bar's end
  for (size_t i = 0; i < sys.links.size(); ++i) {
    if (!sys.links[i].both_ground && static_cast<int>(i) != sys.driver.link) ++equations;
  }
  const int dof = unknowns - equations;
  if (dof != 0) {
    *message = absl::StrFormat(
        "the driven linkage has %d degree(s) of freedom (%d joint coordinates, %d constraints); a driven "
        "mechanism needs exactly 0",
        dof, unknowns, equations);
  }
  return dof;
}

void ToLinkageState(const Mechanism& mech, const CompiledLinkage& c, const MotionSample& s, LinkageState* state) {
  const size_t nj = c.joint_point.size();
  state->time_s = s.t_s;
  state->position_m.resize(nj);
  state->velocity_m_per_s.resize(nj);
  state->acceleration_m_per_s2.resize(nj);
  for (size_t j = 0; j < nj; ++j) {
    const Point& p = c.joint_point[j];
    if (p.body == kGround) {
      state->position_m[j] = p.local_m;
      state->velocity_m_per_s[j].setZero();
      state->acceleration_m_per_s2[j].setZero();
      continue;
    }
    state->position_m[j] = mech.PointPosition(p, s.q);
    state->velocity_m_per_s[j] = mech.PointVelocity(p, s.q, s.v);
    state->acceleration_m_per_s2[j] = mech.PointAcceleration(p, s.q, s.v, s.a);
  }
}

int StressNodes(const LinkageLink& link) {
  return (link.flexible_elements > 0 ? link.flexible_elements : kDefaultStressElements) + 1;
}

void RigidBarMoments(const LinkageSystem& sys, const Mechanism& mech, const CompiledLinkage& c, const MotionSample& s,
                     const LinkageState& state, RigidBarLoads* loads) {
  // -lambda of a driver row is the torque it applies to the driven bar.
  loads->drive_torque_n_m = c.model.drivers.empty() ? 0.0 : -s.lambda[mech.row_of_driver(0)];
  // A revolute joint's rows (x, y) of lambda are the force its body a exerts
  // on its body b: a bar's pin force at its joint a sums them with that sign.
  std::vector<Eigen::Vector2d> force_a(sys.links.size(), Eigen::Vector2d::Zero());
  for (size_t j = 0; j < c.pin_ends.size(); ++j) {
    const CompiledLinkage::PinEnds& pe = c.pin_ends[j];
    const Eigen::Vector2d lambda = s.lambda.segment<2>(mech.first_row_of_joint(static_cast<int>(j)));
    if (pe.link_a >= 0 && pe.end_a == 0) force_a[static_cast<size_t>(pe.link_a)] -= lambda;
    if (pe.link_b >= 0 && pe.end_b == 0) force_a[static_cast<size_t>(pe.link_b)] += lambda;
  }
  const Eigen::Vector2d g = sys.has_gravity ? sys.gravity_m_per_s2 : Eigen::Vector2d::Zero();
  loads->node_moment_n_m.assign(sys.links.size(), {});
  for (size_t i = 0; i < sys.links.size(); ++i) {
    const LinkageLink& l = sys.links[i];
    std::vector<double>& out = loads->node_moment_n_m[i];
    const int nodes = StressNodes(l);
    out.assign(static_cast<size_t>(nodes), 0.0);
    if (c.link_body[i] < 0) continue;
    const double len = l.length_m;
    const Eigen::Vector2d e = state.LinkVector(l).normalized();
    const Eigen::Vector2d n(-e.y(), e.x());
    const double mu = l.has_section ? l.mass_per_length_kg_per_m() : 0.0;
    const double rho_i = l.has_section && l.rotary_inertia ? l.density_kg_per_m3 * l.second_moment_m4() : 0.0;
    const double dist_moment = -rho_i * state.LinkAngularAcceleration(l);
    const Eigen::Vector2d aa = state.acceleration_m_per_s2[static_cast<size_t>(l.joint_a)];
    const Eigen::Vector2d ab = state.acceleration_m_per_s2[static_cast<size_t>(l.joint_b)];
    const double f0 = mu * n.dot(g - aa), f1 = mu * n.dot(g - ab);
    const double torque_at_a =
        static_cast<int>(i) == sys.driver.link && sys.driver.pivot_joint == l.joint_a ? loads->drive_torque_n_m : 0.0;
    const double fa_perp = n.dot(force_a[i]);
    for (int k = 0; k < nodes; ++k) {
      const double sk = len * k / (nodes - 1);
      out[static_cast<size_t>(k)] = sk * fa_perp + f0 * sk * sk / 2.0 + (f1 - f0) * sk * sk * sk / (6.0 * len) -
                                    dist_moment * sk - torque_at_a;
    }
  }
}

}  // namespace mbopt::multibody
