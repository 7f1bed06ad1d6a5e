#include "worker/multibody/linkage_system.h"

#include <cmath>
#include <numbers>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"

namespace mbopt::multibody {

double LinkageLink::second_moment_m4() const {
  return area_m2 * area_m2 / (4.0 * std::numbers::pi);
}

double LinkageLink::StressFromMoment(double moment_n_m) const {
  return 4.0 * std::sqrt(std::numbers::pi) * moment_n_m / std::pow(area_m2, 1.5);
}

bool LinkageSystem::AnyFlexible() const {
  for (const LinkageLink& link : links) {
    if (link.flexible_elements > 0 && !link.both_ground) return true;
  }
  return false;
}

std::string LinkageSystem::JointLabel(int joint) const {
  return absl::StrFormat("joint '%s'", joints[static_cast<size_t>(joint)].name);
}

std::string LinkageSystem::LinkLabel(int link) const {
  const LinkageLink& l = links[static_cast<size_t>(link)];
  return absl::StrFormat("link '%s' (joints %s-%s)", l.name,
                         joints[static_cast<size_t>(l.joint_a)].name,
                         joints[static_cast<size_t>(l.joint_b)].name);
}

namespace {

Eigen::Vector2d Resolve(const spec::Vec2& v, const std::vector<double>& p) {
  return {v.x.Resolve(p), v.y.Resolve(p)};
}

bool ValidIndex(int i, size_t n) { return i >= 0 && static_cast<size_t>(i) < n; }

}  // namespace

absl::StatusOr<LinkageSystem> ResolveLinkage(const spec::LinkageModel& linkage,
                                             const spec::Effects& effects,
                                             const std::vector<double>& p) {
  LinkageSystem sys;
  for (const spec::Joint& j : linkage.joints) {
    LinkageJoint joint{j.name, Resolve(j.position_m, p), j.ground};
    if (!joint.position_m.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("joint '%s': position is not finite", j.name));
    }
    sys.joints.push_back(joint);
  }
  const size_t nj = sys.joints.size();
  for (const spec::Link& l : linkage.links) {
    LinkageLink link;
    link.name = l.name;
    if (!ValidIndex(l.joint_a, nj) || !ValidIndex(l.joint_b, nj) || l.joint_a == l.joint_b) {
      return absl::InvalidArgumentError(
          absl::StrFormat("link '%s': needs two different joints (got %d, %d)", l.name,
                          l.joint_a, l.joint_b));
    }
    link.joint_a = l.joint_a;
    link.joint_b = l.joint_b;
    const Eigen::Vector2d ra = sys.joints[static_cast<size_t>(l.joint_a)].position_m;
    const Eigen::Vector2d rb = sys.joints[static_cast<size_t>(l.joint_b)].position_m;
    link.length_m = l.length_m ? l.length_m->Resolve(p) : (rb - ra).norm();
    if (!(link.length_m > 0.0) || !std::isfinite(link.length_m)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "link '%s': length must be positive (got %g m)", l.name, link.length_m));
    }
    if (l.section) {
      link.has_section = true;
      link.area_m2 = l.section->area_m2.Resolve(p);
      link.youngs_modulus_pa = l.section->youngs_modulus_pa.Resolve(p);
      link.density_kg_per_m3 = l.section->density_kg_per_m3.Resolve(p);
      if (!(link.area_m2 > 0.0) || !(link.density_kg_per_m3 >= 0.0) ||
          !(link.youngs_modulus_pa >= 0.0)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "link '%s': section needs area > 0, density >= 0, E >= 0 (got %g m^2, %g kg/m^3, "
            "%g Pa)",
            l.name, link.area_m2, link.density_kg_per_m3, link.youngs_modulus_pa));
      }
    }
    if (l.flexible_elements < 0) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "link '%s': flexible.elements must be >= 0 (got %d)", l.name, l.flexible_elements));
    }
    link.flexible_elements = l.flexible_elements;
    link.rotary_inertia = l.rotary_inertia;
    link.both_ground = sys.joints[static_cast<size_t>(l.joint_a)].ground &&
                       sys.joints[static_cast<size_t>(l.joint_b)].ground;
    if (link.flexible_elements > 0 && !link.both_ground &&
        (!link.has_section || !(link.youngs_modulus_pa > 0.0))) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "link '%s': a flexible link needs a section with E > 0", l.name));
    }
    // Points are given in the scene's joint frame; carried with the link.
    const Eigen::Vector2d d = rb - ra;
    if (!l.points.empty() && !(d.norm() > 0.0)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "link '%s': points need distinct joint positions to define the link frame", l.name));
    }
    const Eigen::Vector2d e = d.normalized();
    const Eigen::Vector2d n(-e.y(), e.x());
    for (const spec::LinkPoint& pt : l.points) {
      const Eigen::Vector2d r = Resolve(pt.position_m, p) - ra;
      link.points.push_back({pt.name, Eigen::Vector2d(r.dot(e), r.dot(n))});
    }
    sys.links.push_back(std::move(link));
  }

  const spec::Driver& d = linkage.driver;
  if (!ValidIndex(d.link, sys.links.size())) {
    return absl::InvalidArgumentError(absl::StrFormat("driver: unknown link index %d", d.link));
  }
  const LinkageLink& driven = sys.links[static_cast<size_t>(d.link)];
  if (d.pivot_joint != driven.joint_a && d.pivot_joint != driven.joint_b) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "driver: pivot joint must be a joint of link '%s'", driven.name));
  }
  if (!sys.joints[static_cast<size_t>(d.pivot_joint)].ground) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "driver: pivot %s must be a ground joint", sys.JointLabel(d.pivot_joint)));
  }
  sys.driver.link = d.link;
  sys.driver.pivot_joint = d.pivot_joint;
  sys.driver.driven_joint = d.pivot_joint == driven.joint_a ? driven.joint_b : driven.joint_a;
  if (sys.joints[static_cast<size_t>(sys.driver.driven_joint)].ground) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "driver: link '%s' has both joints on the ground", driven.name));
  }
  const Eigen::Vector2d arm = sys.joints[static_cast<size_t>(sys.driver.driven_joint)].position_m -
                              sys.joints[static_cast<size_t>(sys.driver.pivot_joint)].position_m;
  if (d.start_angle_rad) {
    sys.driver.start_angle_rad = d.start_angle_rad->Resolve(p);
  } else {
    if (!(arm.norm() > 0.0)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "driver: link '%s' has coincident joints and no start angle", driven.name));
    }
    sys.driver.start_angle_rad = std::atan2(arm.y(), arm.x());
  }
  sys.driver.angular_velocity_rad_per_s = d.angular_velocity_rad_per_s.Resolve(p);
  if (!std::isfinite(sys.driver.start_angle_rad) ||
      !std::isfinite(sys.driver.angular_velocity_rad_per_s)) {
    return absl::InvalidArgumentError("driver: start angle and angular velocity must be finite");
  }

  if (effects.gravity_m_per_s2) {
    sys.has_gravity = true;
    sys.gravity_m_per_s2 = Resolve(*effects.gravity_m_per_s2, p);
  }
  if (effects.structural_damping_ratio) {
    sys.has_structural_damping = true;
    sys.structural_damping_ratio = *effects.structural_damping_ratio;
    if (!(sys.structural_damping_ratio >= 0.0)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "effects.structural_damping: ratio must be >= 0 (got %g)",
          sys.structural_damping_ratio));
    }
  }
  return sys;
}

namespace {
double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
}  // namespace

Eigen::Vector2d LinkageState::LinkVector(const LinkageLink& link) const {
  return position_m[static_cast<size_t>(link.joint_b)] - position_m[static_cast<size_t>(link.joint_a)];
}

double LinkageState::LinkAngle(const LinkageLink& link) const {
  const Eigen::Vector2d d = LinkVector(link);
  return std::atan2(d.y(), d.x());
}

double LinkageState::LinkAngularVelocity(const LinkageLink& link) const {
  const Eigen::Vector2d d = LinkVector(link);
  const Eigen::Vector2d v =
      velocity_m_per_s[static_cast<size_t>(link.joint_b)] - velocity_m_per_s[static_cast<size_t>(link.joint_a)];
  return Cross(d, v) / d.squaredNorm();
}

double LinkageState::LinkAngularAcceleration(const LinkageLink& link) const {
  const Eigen::Vector2d d = LinkVector(link);
  const Eigen::Vector2d v =
      velocity_m_per_s[static_cast<size_t>(link.joint_b)] - velocity_m_per_s[static_cast<size_t>(link.joint_a)];
  const Eigen::Vector2d a = acceleration_m_per_s2[static_cast<size_t>(link.joint_b)] -
                            acceleration_m_per_s2[static_cast<size_t>(link.joint_a)];
  const double d2 = d.squaredNorm();
  return Cross(d, a) / d2 - 2.0 * d.dot(v) * Cross(d, v) / (d2 * d2);
}

}  // namespace mbopt::multibody
