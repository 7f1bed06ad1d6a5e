// KinetostaticSolver: pin forces, drive torque and bending moments of a
// driven linkage of rigid bars carrying their own inertia loads, at one
// instant of a kinematic solution. No time integration: the motion is
// prescribed, the loads follow from it.
//
// Each bar is a slender rod (mass per length rho A) whose acceleration field
// is linear along it, a(s) = a_a + (s / l) (a_b - a_a); its D'Alembert load
// rho A (g - a(s)) per unit length (g only if the scene declares gravity) and,
// if the link declares rotary inertia, the distributed moment -rho I alpha,
// are balanced by the pin forces at its two joints and, on the driven bar,
// the drive torque. Joints are massless pins (forces sum to zero at a
// non-ground joint). The bending moment at a section s is the moment, about
// that section, of the loads on the part s' > s (counter-clockwise positive,
// equal to EI w'' with w along the link's left normal).
//
// Borrows the LinkageSystem; owns its work buffers.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "worker/model/linkage_model.h"
#include "worker/solve/kinematic_solver.h"

namespace mbopt::solve {

struct KinetostaticLoads {
  double drive_torque_n_m = 0.0;  // on the driven bar, counter-clockwise positive
  // [link][node] bending moment at equally spaced nodes (ends included), N m.
  std::vector<std::vector<double>> node_moment_n_m;
  // [link] force on the bar at joint a and at joint b, N (global frame).
  std::vector<Eigen::Vector2d> force_a_n, force_b_n;
};

class KinetostaticSolver {
 public:
  explicit KinetostaticSolver(const model::LinkageSystem& system);

  // Stress nodes of a link: its beam elements + 1, or 7 for a rigid link.
  static int NumNodes(const model::LinkageLink& link);

  // False (with a reason) if the pin-force equations are singular.
  KinematicOutcome Solve(const LinkageState& state, KinetostaticLoads* loads);

 private:
  const model::LinkageSystem& sys_;
  std::vector<int> moving_index_;  // per link: index among moving links, -1 if grounded
  int num_moving_ = 0;
  Eigen::MatrixXd a_;
  Eigen::VectorXd b_;
};

}  // namespace mbopt::solve
