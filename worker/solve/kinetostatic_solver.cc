#include "worker/solve/kinetostatic_solver.h"

#include <cmath>

#include "absl/strings/str_format.h"

namespace mbopt::solve {

namespace {
constexpr int kDefaultStressElements = 6;  // the report's 6 elements per link
constexpr double kSingularRcond = 1e-12;
double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}
}  // namespace

int KinetostaticSolver::NumNodes(const model::LinkageLink& link) {
  return (link.flexible_elements > 0 ? link.flexible_elements : kDefaultStressElements) + 1;
}

KinetostaticSolver::KinetostaticSolver(const model::LinkageSystem& system) : sys_(system) {
  moving_index_.assign(sys_.links.size(), -1);
  for (size_t i = 0; i < sys_.links.size(); ++i) {
    if (!sys_.links[i].both_ground) moving_index_[i] = num_moving_++;
  }
}

KinematicOutcome KinetostaticSolver::Solve(const LinkageState& s, KinetostaticLoads* loads) {
  // Unknowns: force on moving link m at its end k (2 each: 4 m + 2 k), then
  // the drive torque. Rows: 3 per moving link, 2 per non-ground joint.
  const int n_unknowns = 4 * num_moving_ + 1;
  int n_free_joints = 0;
  for (const model::LinkageJoint& j : sys_.joints) n_free_joints += j.ground ? 0 : 1;
  const int n_rows = 3 * num_moving_ + 2 * n_free_joints;
  if (n_rows != n_unknowns) {
    return KinematicOutcome::Of(spec::FailureKind::kInvalidModel, absl::StrFormat(
        "pin forces are not statically determinate (%d equations, %d unknowns)", n_rows,
        n_unknowns));
  }
  a_.setZero(n_rows, n_unknowns);
  b_.setZero(n_rows);
  const int torque = n_unknowns - 1;
  const Eigen::Vector2d g = sys_.has_gravity ? sys_.gravity_m_per_s2 : Eigen::Vector2d::Zero();

  std::vector<int> joint_row(sys_.joints.size(), -1);
  int row = 3 * num_moving_;
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    if (!sys_.joints[j].ground) {
      joint_row[j] = row;
      row += 2;
    }
  }

  for (size_t i = 0; i < sys_.links.size(); ++i) {
    const int m = moving_index_[i];
    if (m < 0) continue;
    const model::LinkageLink& l = sys_.links[i];
    const double len = l.length_m;
    const Eigen::Vector2d d = s.LinkVector(l);
    const Eigen::Vector2d e = d.normalized();
    const Eigen::Vector2d aa = s.acceleration_m_per_s2[static_cast<size_t>(l.joint_a)];
    const Eigen::Vector2d ab = s.acceleration_m_per_s2[static_cast<size_t>(l.joint_b)];
    const double mu = l.has_section ? l.mass_per_length_kg_per_m() : 0.0;
    const double rho_i = (l.has_section && l.rotary_inertia)
                             ? l.density_kg_per_m3 * l.second_moment_m4()
                             : 0.0;
    const double alpha = s.LinkAngularAcceleration(l);
    const Eigen::Vector2d resultant = mu * len * (g - 0.5 * (aa + ab));
    const Eigen::Vector2d first_moment = mu * len * len * (0.5 * g - aa / 6.0 - ab / 3.0);
    const double moment_about_a = Cross(e, first_moment) - rho_i * alpha * len;
    const int r0 = 3 * m;
    const int fa = 4 * m, fb = 4 * m + 2;
    a_(r0, fa) = a_(r0, fb) = 1.0;
    a_(r0 + 1, fa + 1) = a_(r0 + 1, fb + 1) = 1.0;
    b_(r0) = -resultant.x();
    b_(r0 + 1) = -resultant.y();
    a_(r0 + 2, fb) = -d.y();
    a_(r0 + 2, fb + 1) = d.x();
    if (static_cast<int>(i) == sys_.driver.link) a_(r0 + 2, torque) = 1.0;
    b_(r0 + 2) = -moment_about_a;
    for (int k = 0; k < 2; ++k) {
      const int jr = joint_row[static_cast<size_t>(k == 0 ? l.joint_a : l.joint_b)];
      if (jr < 0) continue;
      a_(jr, 4 * m + 2 * k) = 1.0;
      a_(jr + 1, 4 * m + 2 * k + 1) = 1.0;
    }
  }
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(a_);
  if (!(lu.rcond() > kSingularRcond)) {
    return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
        "pin forces are indeterminate at t = %.6g s (singular equilibrium equations)", s.time_s));
  }
  const Eigen::VectorXd x = lu.solve(b_);
  loads->drive_torque_n_m = x(torque);
  loads->node_moment_n_m.assign(sys_.links.size(), {});
  loads->force_a_n.assign(sys_.links.size(), Eigen::Vector2d::Zero());
  loads->force_b_n.assign(sys_.links.size(), Eigen::Vector2d::Zero());
  for (size_t i = 0; i < sys_.links.size(); ++i) {
    const model::LinkageLink& l = sys_.links[i];
    const int m = moving_index_[i];
    const int nodes = NumNodes(l);
    std::vector<double>& out = loads->node_moment_n_m[i];
    out.assign(static_cast<size_t>(nodes), 0.0);
    if (m < 0) continue;
    const Eigen::Vector2d fa = x.segment<2>(4 * m);
    loads->force_a_n[i] = fa;
    loads->force_b_n[i] = x.segment<2>(4 * m + 2);
    const double len = l.length_m;
    const Eigen::Vector2d e = s.LinkVector(l).normalized();
    const Eigen::Vector2d n(-e.y(), e.x());
    const double mu = l.has_section ? l.mass_per_length_kg_per_m() : 0.0;
    const double rho_i = (l.has_section && l.rotary_inertia)
                             ? l.density_kg_per_m3 * l.second_moment_m4()
                             : 0.0;
    const double dist_moment = -rho_i * s.LinkAngularAcceleration(l);
    const Eigen::Vector2d aa = s.acceleration_m_per_s2[static_cast<size_t>(l.joint_a)];
    const Eigen::Vector2d ab = s.acceleration_m_per_s2[static_cast<size_t>(l.joint_b)];
    const double f0 = mu * n.dot(g - aa), f1 = mu * n.dot(g - ab);
    const double torque_at_a = (static_cast<int>(i) == sys_.driver.link &&
                                sys_.driver.pivot_joint == l.joint_a)
                                   ? x(torque)
                                   : 0.0;
    const double fa_perp = n.dot(fa);
    for (int k = 0; k < nodes; ++k) {
      const double sk = len * k / (nodes - 1);
      out[static_cast<size_t>(k)] = sk * fa_perp + f0 * sk * sk / 2.0 +
                                    (f1 - f0) * sk * sk * sk / (6.0 * len) -
                                    dist_moment * sk - torque_at_a;
    }
  }
  return {};
}

}  // namespace mbopt::solve
