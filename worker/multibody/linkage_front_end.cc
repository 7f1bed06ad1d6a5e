#include "worker/multibody/linkage_front_end.h"

#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "absl/strings/str_format.h"

namespace mbopt::multibody {
namespace {

constexpr int kDefaultStressElements = 6;

// The end `end` (0: joint a) of a bar of length `length_m`, in its body's axes.
Eigen::Vector2d EndMarker(double length_m, int end) {
  return Eigen::Vector2d(end == 0 ? -0.5 * length_m : 0.5 * length_m, 0.0);
}

}  // namespace

CompiledLinkage CompileLinkage(const LinkageSystem& sys) {
  CompiledLinkage out;
  Model& m = out.model;
  out.link_body.assign(sys.links.size(), -1);
  const LinkageDriver& driver = sys.driver;
  for (size_t i = 0; i < sys.links.size(); ++i) {
    const LinkageLink& l = sys.links[i];
    if (l.both_ground) continue;
    const Eigen::Vector2d ra = sys.joints[static_cast<size_t>(l.joint_a)].position_m;
    const Eigen::Vector2d rb = sys.joints[static_cast<size_t>(l.joint_b)].position_m;
    // The driven bar starts at the driver's angle; the others along their
    // given pins (which may be only a guess: assembly closes the loops).
    double angle = (rb - ra).norm() > 0.0 ? std::atan2(rb.y() - ra.y(), rb.x() - ra.x()) : 0.0;
    if (static_cast<int>(i) == driver.link) {
      angle = driver.start_angle_rad + (driver.pivot_joint == l.joint_a ? 0.0 : std::numbers::pi);
    }
    const Eigen::Vector2d e(std::cos(angle), std::sin(angle));
    // The driven bar hangs from its pivot; the others start at their joint a.
    const bool pivot_at_b = static_cast<int>(i) == driver.link && driver.pivot_joint == l.joint_b;
    const Eigen::Vector2d centre = pivot_at_b ? Eigen::Vector2d(rb - 0.5 * l.length_m * e)
                                              : Eigen::Vector2d(ra + 0.5 * l.length_m * e);
    const double mu = l.has_section ? l.mass_per_length_kg_per_m() : 0.0;
    const double rho_i = l.has_section && l.rotary_inertia ? l.density_kg_per_m3 * l.second_moment_m4() : 0.0;
    const double mass = mu * l.length_m;
    out.link_body[i] = static_cast<int>(m.bodies.size());
    m.bodies.push_back(Body{l.name, mass, mass * l.length_m * l.length_m / 12.0 + rho_i * l.length_m,
                            centre, angle});
  }
  out.joint_point.assign(sys.joints.size(), Point{});
  int driven_joint = -1;
  for (size_t j = 0; j < sys.joints.size(); ++j) {
    const LinkageJoint& pin = sys.joints[j];
    Point ground{kGround, pin.position_m, pin.name};
    out.joint_point[j] = ground;
    std::vector<std::pair<int, int>> ends;  // (link, end) of the moving bars pinned here
    for (size_t i = 0; i < sys.links.size(); ++i) {
      const LinkageLink& l = sys.links[i];
      if (l.both_ground) continue;
      if (l.joint_a == static_cast<int>(j)) ends.emplace_back(static_cast<int>(i), 0);
      if (l.joint_b == static_cast<int>(j)) ends.emplace_back(static_cast<int>(i), 1);
    }
    auto marker = [&](const std::pair<int, int>& end) {
      const LinkageLink& l = sys.links[static_cast<size_t>(end.first)];
      return Point{out.link_body[static_cast<size_t>(end.first)], EndMarker(l.length_m, end.second), pin.name};
    };
    if (!pin.ground && !ends.empty()) out.joint_point[j] = marker(ends.front());
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
        driven_joint = static_cast<int>(m.joints.size());
      }
      m.joints.push_back(std::move(joint));
      out.pin_ends.push_back(pe);
    }
  }
  if (driven_joint >= 0) {
    Driver d;
    d.joint = driven_joint;
    d.profile.kind = Profile::Kind::kConstantRate;
    const bool pivot_is_a = driver.pivot_joint == sys.links[static_cast<size_t>(driver.link)].joint_a;
    d.profile.start = driver.start_angle_rad + (pivot_is_a ? 0.0 : std::numbers::pi);
    d.profile.rate = driver.angular_velocity_rad_per_s;
    m.drivers.push_back(d);
  }
  if (sys.has_gravity) m.gravity_m_per_s2 = sys.gravity_m_per_s2;
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
