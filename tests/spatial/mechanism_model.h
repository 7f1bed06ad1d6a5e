// The mbopt model of a mechanism of spatial_mechanisms.h: bodies with
// their principal moments in body axes and start velocities, each joint's
// world frame fixed in its two bodies (frames that coincide in the initial
// pose), the driver.
#pragma once

#include <Eigen/Dense>

#include "tests/spatial/spatial_mechanisms.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

inline Eigen::Vector3d ToVector(const oracle::Vec& v) { return {v[0], v[1], v[2]}; }

inline Eigen::Matrix3d ToMatrix(const oracle::Mat& m) {
  Eigen::Matrix3d r;
  r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
  return r;
}

inline Model ModelOf(const oracle::Mechanism& mechanism) {
  Model model;
  for (size_t i = 0; i < mechanism.bodies.size(); ++i) {
    const oracle::MechanismBody& b = mechanism.bodies[i];
    Body body;
    body.name = "body " + std::to_string(i);
    body.mass_kg = b.mass_kg;
    body.inertia_kg_m2 = ToVector(b.principal_moments_kg_m2).asDiagonal();
    body.position_m = ToVector(b.position_m);
    body.orientation = ToMatrix(b.orientation);
    body.velocity_m_per_s = ToVector(b.velocity_m_per_s);
    body.angular_velocity_rad_per_s = ToVector(b.angular_velocity_rad_per_s);
    model.bodies.push_back(body);
  }
  auto frame_on = [&](int body, const Eigen::Vector3d& point, const Eigen::Matrix3d& axes) {
    Frame f;
    f.body = body;
    if (body == kGround) {
      f.position_m = point;
      f.axes = axes;
    } else {
      const Body& b = model.bodies[static_cast<size_t>(body)];
      f.position_m = b.orientation.transpose() * (point - b.position_m);
      f.axes = b.orientation.transpose() * axes;
    }
    return f;
  };
  for (size_t j = 0; j < mechanism.joints.size(); ++j) {
    const oracle::MechanismJoint& joint = mechanism.joints[j];
    Joint::Kind kind = Joint::Kind::kRevolute;
    switch (joint.kind) {
      case oracle::MechanismJointKind::kRevolute: kind = Joint::Kind::kRevolute; break;
      case oracle::MechanismJointKind::kSpherical: kind = Joint::Kind::kSpherical; break;
      case oracle::MechanismJointKind::kUniversal: kind = Joint::Kind::kUniversal; break;
      case oracle::MechanismJointKind::kPointOnLine: kind = Joint::Kind::kPointOnLine; break;
      case oracle::MechanismJointKind::kPrismatic: kind = Joint::Kind::kPrismatic; break;
    }
    const Eigen::Vector3d point = ToVector(joint.point_m);
    const Eigen::Matrix3d axes = ToMatrix(joint.axes);
    model.joints.push_back(
        {"joint " + std::to_string(j), kind, frame_on(joint.a, point, axes), frame_on(joint.b, point, axes)});
  }
  if (mechanism.driven_joint >= 0) {
    Driver d;
    d.joint = mechanism.driven_joint;
    d.profile.kind = multibody::Profile::Kind::kConstantRate;
    d.profile.rate = mechanism.driver_rate_rad_per_s;
    model.drivers.push_back(d);
  }
  const oracle::Vec& g = mechanism.gravity_m_per_s2;
  if (g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0) model.gravity_m_per_s2 = ToVector(g);
  return model;
}

}  // namespace mbopt::spatial
