#include "worker/multibody/floating_frame.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "absl/strings/str_format.h"
#include "worker/multibody/floating_frame_beam.h"
#include "worker/sundials/integrator_failure.h"

namespace mbopt::multibody {

namespace {

using floating_frame::BeamMatrix;
using Vector6d = Eigen::Matrix<double, 6, 1>;
constexpr double kPi = std::numbers::pi;

struct NodeDofs {
  int dof[3] = {-1, -1, -1};  // global x, global y, rotation; -1: fixed
};

struct LinkMesh {
  int link = -1;
  int elements = 0;
  double element_length_m = 0.0;
  BeamMatrix k, m;           // local element matrices
  double axial_stiffness_n = 0.0;  // E A
  double bending_stiffness_n_m2 = 0.0;  // E I
  double beta_s = 0.0;       // stiffness-proportional damping coefficient
  std::vector<NodeDofs> nodes;
  int clamped_node = -1;     // node whose rotation is the driver's
};

// Element dofs in the link frame (u1, w1, theta1, u2, w2, theta2) from the
// unknowns: the translations of a joint node are global (Ux, Uy) and are
// rotated into the link frame; inner nodes are already in the link frame.
BeamMatrix Transform(double angle, bool first_is_joint, bool second_is_joint) {
  const double c = std::cos(angle), s = std::sin(angle);
  BeamMatrix t = BeamMatrix::Identity();
  for (int n = 0; n < 2; ++n) {
    if (!(n == 0 ? first_is_joint : second_is_joint)) continue;
    const int o = 3 * n;
    t(o, o) = c;
    t(o, o + 1) = s;
    t(o + 1, o) = -s;
    t(o + 1, o + 1) = c;
  }
  return t;
}

// Rotates the translations of both nodes of an element vector from the
// global frame into the link frame.
Vector6d ToLinkFrame(double angle, const Vector6d& g) {
  const double c = std::cos(angle), s = std::sin(angle);
  Vector6d l = g;
  for (int o = 0; o < 6; o += 3) {
    l(o) = c * g(o) + s * g(o + 1);
    l(o + 1) = -s * g(o) + c * g(o + 1);
  }
  return l;
}

class ElasticLinkage {
 public:
  ElasticLinkage(const LinkageSystem& sys, const RigidMotionAt& rigid_motion)
      : sys_(sys), rigid_motion_(rigid_motion) {}

  // Numbers the degrees of freedom and builds the element matrices.
  std::string Build() {
    std::vector<int> joint_dof(sys_.joints.size(), -1);
    for (size_t j = 0; j < sys_.joints.size(); ++j) {
      if (!sys_.joints[j].ground) {
        joint_dof[j] = n_;
        n_ += 2;
      }
    }
    for (size_t i = 0; i < sys_.links.size(); ++i) {
      const LinkageLink& l = sys_.links[i];
      if (l.both_ground) continue;
      if (l.flexible_elements <= 0) {
        return absl::StrFormat(
            "elastodynamic analysis needs every moving link flexible; %s is rigid",
            sys_.LinkLabel(static_cast<int>(i)));
      }
      LinkMesh mesh;
      mesh.link = static_cast<int>(i);
      mesh.elements = l.flexible_elements;
      mesh.element_length_m = l.length_m / l.flexible_elements;
      floating_frame::BeamSection sec;
      sec.length_m = mesh.element_length_m;
      sec.axial_stiffness_n = l.youngs_modulus_pa * l.area_m2;
      sec.bending_stiffness_n_m2 = l.youngs_modulus_pa * l.second_moment_m4();
      sec.mass_per_length_kg_per_m = l.mass_per_length_kg_per_m();
      sec.rotary_inertia_kg_m = l.rotary_inertia ? l.density_kg_per_m3 * l.second_moment_m4() : 0.0;
      mesh.k = floating_frame::BeamStiffness(sec);
      mesh.axial_stiffness_n = sec.axial_stiffness_n;
      mesh.bending_stiffness_n_m2 = sec.bending_stiffness_n_m2;
      mesh.m = floating_frame::BeamConsistentMass(sec);
      mesh.nodes.resize(static_cast<size_t>(mesh.elements + 1));
      const bool driven = static_cast<int>(i) == sys_.driver.link;
      for (int nd = 0; nd <= mesh.elements; ++nd) {
        NodeDofs& d = mesh.nodes[static_cast<size_t>(nd)];
        const bool end = nd == 0 || nd == mesh.elements;
        if (end) {
          const int joint = nd == 0 ? l.joint_a : l.joint_b;
          const int jd = joint_dof[static_cast<size_t>(joint)];
          if (jd >= 0) {
            d.dof[0] = jd;
            d.dof[1] = jd + 1;
          }
          if (driven && joint == sys_.driver.pivot_joint) {
            mesh.clamped_node = nd;
          } else {
            d.dof[2] = n_++;
          }
        } else {
          for (int c = 0; c < 3; ++c) d.dof[c] = n_++;
        }
      }
      meshes_.push_back(std::move(mesh));
    }
    for (const LinkMesh& mesh : meshes_) {
      const double omega = LowestFrequency(mesh);
      lowest_frequency_ = lowest_frequency_ == 0.0 ? omega : std::min(lowest_frequency_, omega);
    }
    // One beta for the whole linkage, set at the lowest link bending
    // frequency: every higher mode is damped more (zeta = beta omega / 2).
    if (sys_.has_structural_damping && lowest_frequency_ > 0.0) {
      beta_ = 2.0 * sys_.structural_damping_ratio / lowest_frequency_;
      for (LinkMesh& mesh : meshes_) mesh.beta_s = beta_;
    }
    m_inner_.setZero(n_, n_);
    k_inner_.setZero(n_, n_);
    c_inner_.setZero(n_, n_);
    for (const LinkMesh& mesh : meshes_) {
      for (int e = 1; e + 1 < mesh.elements; ++e) {
        int dofs[6];
        ElementDofs(mesh, e, dofs);
        AddElement(mesh, dofs, mesh.m, mesh.k, &m_inner_, &k_inner_, &c_inner_);
      }
    }
    f_.resize(n_);
    newton_rhs_.resize(n_);
    return {};
  }

  int num_dofs() const { return n_; }
  double lowest_frequency() const { return lowest_frequency_; }
  const LinkageState& rigid_state() const { return state_; }
  // Why the integration could not go on, if the model knows: a failed
  // rigid motion, a singular mass matrix, or an elastic response that blew
  // up (a link in compression beyond its buckling load).
  spec::AnalysisFailure failure() const { return failure_.ok() ? divergence_ : failure_; }

  // Rigid motion and the assembled M, K, C, load at t (cached per t).
  bool Prepare(double t) {
    if (prepared_ && t == prepared_t_) return true;
    if (spec::AnalysisFailure o = rigid_motion_(t, &state_); !o.ok()) {
      failure_ = o;
      prepared_ = false;
      return false;
    }
    m_ = m_inner_;
    k_ = k_inner_;
    c_ = c_inner_;
    f_.setZero();
    const Eigen::Vector2d g = sys_.has_gravity ? sys_.gravity_m_per_s2 : Eigen::Vector2d::Zero();
    for (const LinkMesh& mesh : meshes_) {
      const LinkFrameMotion frame = FrameMotionOf(mesh);
      const double angle = frame.angle_rad;
      for (int e = 0; e < mesh.elements; ++e) {
        const bool at_joint = e == 0 || e + 1 == mesh.elements;
        const BeamMatrix t6 = Transform(angle, e == 0, e + 1 == mesh.elements);
        const Vector6d load =
            t6.transpose() *
            (mesh.m * ToLinkFrame(angle, GravityVector(g) - RigidAcceleration(mesh, e, frame)));
        int dofs[6];
        ElementDofs(mesh, e, dofs);
        for (int r = 0; r < 6; ++r) {
          if (dofs[r] >= 0) f_(dofs[r]) += load(r);
        }
        // Inner elements live wholly in the link frame: their matrices are
        // constant and already in m_inner_, k_inner_, c_inner_.
        if (at_joint) AddElement(mesh, dofs, t6.transpose() * mesh.m * t6, t6.transpose() * mesh.k * t6, &m_, &k_, &c_);
      }
    }
    lu_.compute(m_);
    if (lu_.info() != Eigen::Success) {
      failure_ = spec::AnalysisFailure::Of(
          spec::FailureKind::kInvalidModel, absl::StrFormat("mass matrix not positive definite at t = %.6g s", t));
      prepared_ = false;
      return false;
    }
    prepared_ = true;
    prepared_t_ = t;
    return true;
  }

  // y = (u, v): u' = v, v' = M^-1 (f - K u - C v).
  int Rhs(double t, const double* y, double* ydot) {
    if (!Prepare(t)) return -1;
    Eigen::Map<const Eigen::VectorXd> u(y, n_), v(y + n_, n_);
    Eigen::Map<Eigen::VectorXd> du(ydot, n_), dv(ydot + n_, n_);
    du = v;
    AddGeometricForces(u, &geometric_force_);
    dv = lu_.solve(f_ - k_ * u - c_ * v - geometric_force_);
    if (dv.allFinite()) {
      divergence_ = spec::AnalysisFailure::Ok();
      if (buckled_link_ < 0 && largest_compression_ratio_ > 1.0) {
        buckled_link_ = most_compressed_link_;
        buckled_t_ = t;
      }
      return 0;
    }
    divergence_ = DivergenceReason(t);
    return 1;
  }

  // Solves (I - gamma J) x = b in place for y = (u, v), J = [0 I; -M^-1 K
  // -M^-1 C]: eliminating x_u = b_u + gamma x_v leaves the symmetric
  // positive definite (M + gamma C + gamma^2 K) x_v = M b_v - gamma K b_u,
  // n x n instead of 2n x 2n and exact at the step's own t but for the
  // geometric stiffness, which it leaves out (see AddGeometricForces).
  int NewtonSolve(double t, double gamma, double* bx, bool* refactored) {
    if (!Prepare(t)) return -1;
    if (!(factored_ && t == factored_t_ && gamma == factored_gamma_)) {
      newton_matrix_ = m_;
      newton_matrix_.noalias() += gamma * c_;
      newton_matrix_.noalias() += (gamma * gamma) * k_;
      newton_.compute(newton_matrix_);
      *refactored = true;
      if (newton_.info() != Eigen::Success) {
        factored_ = false;
        return 1;
      }
      factored_ = true;
      factored_t_ = t;
      factored_gamma_ = gamma;
    }
    Eigen::Map<Eigen::VectorXd> bu(bx, n_), bv(bx + n_, n_);
    newton_rhs_.noalias() = m_ * bv;
    newton_rhs_.noalias() -= gamma * (k_ * bu);
    bv = newton_.solve(newton_rhs_);
    bu += gamma * bv;
    return bv.allFinite() ? 0 : 1;
  }

  // The elastic displacement of every node of every moving link at the
  // prepared instant (after Rhs or Moments at its t), world axes: a joint
  // node's unknowns are world translations already, an inner node's are
  // along and across its link.
  void NodeDisplacements(const Eigen::VectorXd& y, std::vector<std::vector<Eigen::Vector2d>>* out) const {
    out->assign(sys_.links.size(), {});
    for (const LinkMesh& mesh : meshes_) {
      const double angle = state_.LinkAngle(sys_.links[static_cast<size_t>(mesh.link)]);
      const double c = std::cos(angle), s = std::sin(angle);
      std::vector<Eigen::Vector2d>& nodes = (*out)[static_cast<size_t>(mesh.link)];
      for (int nd = 0; nd <= mesh.elements; ++nd) {
        const NodeDofs& d = mesh.nodes[static_cast<size_t>(nd)];
        const double first = d.dof[0] < 0 ? 0.0 : y(d.dof[0]), second = d.dof[1] < 0 ? 0.0 : y(d.dof[1]);
        const bool end = nd == 0 || nd == mesh.elements;
        nodes.push_back(end ? Eigen::Vector2d(first, second)
                            : Eigen::Vector2d(c * first - s * second, s * first + c * second));
      }
    }
  }

  // Node moments of every link and the drive torque at t from y.
  bool Moments(double t, const Eigen::VectorXd& y, std::vector<std::vector<double>>* moments,
               double* drive_torque) {
    Eigen::VectorXd ydot(2 * n_);
    if (Rhs(t, y.data(), ydot.data()) != 0) return false;
    const Eigen::Vector2d g = sys_.has_gravity ? sys_.gravity_m_per_s2 : Eigen::Vector2d::Zero();
    moments->assign(sys_.links.size(), {});
    *drive_torque = 0.0;
    for (const LinkMesh& mesh : meshes_) {
      const LinkFrameMotion frame = FrameMotionOf(mesh);
      const double angle = frame.angle_rad;
      std::vector<double>& out = (*moments)[static_cast<size_t>(mesh.link)];
      out.assign(static_cast<size_t>(mesh.elements + 1), 0.0);
      std::vector<int> hits(out.size(), 0);
      for (int e = 0; e < mesh.elements; ++e) {
        int dofs[6];
        ElementDofs(mesh, e, dofs);
        Vector6d d, dd, acc;
        for (int r = 0; r < 6; ++r) {
          d(r) = dofs[r] < 0 ? 0.0 : y(dofs[r]);
          dd(r) = dofs[r] < 0 ? 0.0 : y(n_ + dofs[r]);
          acc(r) = dofs[r] < 0 ? 0.0 : ydot(n_ + dofs[r]);
        }
        const BeamMatrix t6 = Transform(angle, e == 0, e + 1 == mesh.elements);
        const Vector6d rigid =
            ToLinkFrame(angle, RigidAcceleration(mesh, e, frame) - GravityVector(g));
        const Vector6d local = t6 * d;
        const Vector6d end = mesh.k * local + GeometricStiffness(mesh, local) * local +
                             mesh.beta_s * (mesh.k * (t6 * dd)) + mesh.m * (t6 * acc + rigid);
        // The moment a node passes on: minus the left end moment of the
        // element to its right, the right end moment of the element to its left.
        out[static_cast<size_t>(e)] += -end(2);
        hits[static_cast<size_t>(e)] += 1;
        out[static_cast<size_t>(e + 1)] += end(5);
        hits[static_cast<size_t>(e + 1)] += 1;
        if (mesh.clamped_node == e && e == 0) *drive_torque = end(2);
        if (mesh.clamped_node == e + 1 && e + 1 == mesh.elements) *drive_torque = end(5);
      }
      for (size_t nd = 0; nd < out.size(); ++nd) out[nd] /= hits[nd];
    }
    return true;
  }

 private:
  // The element's geometric stiffness at its current axial force, the force
  // of its own axial strain (tension > 0).
  static BeamMatrix GeometricStiffness(const LinkMesh& mesh, const Vector6d& local) {
    const double axial_force_n =
        mesh.axial_stiffness_n * (local(3) - local(0)) / mesh.element_length_m;
    return floating_frame::BeamGeometricStiffness(mesh.element_length_m, axial_force_n);
  }

  // Names the first link whose compression passed its Euler load (ends
  // pinned): past that load the linear elastic response grows without bound.
  spec::AnalysisFailure DivergenceReason(double t) const {
    if (buckled_link_ < 0) {
      return spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue,
                                       absl::StrFormat("elastic response diverged at t = %.6g s", t));
    }
    return spec::AnalysisFailure::Of(spec::FailureKind::kModelValidity, absl::StrFormat(
        "elastic response diverged at t = %.6g s after %s passed its Euler buckling load (ends "
        "pinned) in compression at t = %.6g s: the link is too slender for the mechanism's inertia "
        "loads",
        t, sys_.LinkLabel(buckled_link_), buckled_t_));
  }

  // Internal forces of the axial force acting on the bending deflection (the
  // P-delta effect), assembled in the unknowns. Second order in u, but of
  // relative size N / P_euler, which is first order in the loads: a coupler in
  // compression at a few per cent of its buckling load bends a few per cent
  // more than a linear model says. Not in the Newton matrix: the few-per-cent
  // difference only costs CVODES an extra Newton iteration now and then.
  void AddGeometricForces(const Eigen::Ref<const Eigen::VectorXd>& u, Eigen::VectorXd* force) {
    force->setZero(n_);
    most_compressed_link_ = -1;
    largest_compression_ratio_ = 0.0;
    for (const LinkMesh& mesh : meshes_) {
      const double angle = state_.LinkAngle(sys_.links[static_cast<size_t>(mesh.link)]);
      const double length_m = mesh.element_length_m * mesh.elements;
      const double euler_n = kPi * kPi * mesh.bending_stiffness_n_m2 / (length_m * length_m);
      for (int e = 0; e < mesh.elements; ++e) {
        int dofs[6];
        ElementDofs(mesh, e, dofs);
        Vector6d d;
        for (int r = 0; r < 6; ++r) d(r) = dofs[r] < 0 ? 0.0 : u(dofs[r]);
        const BeamMatrix t6 = Transform(angle, e == 0, e + 1 == mesh.elements);
        const Vector6d local = t6 * d;
        const double compression_n =
            -mesh.axial_stiffness_n * (local(3) - local(0)) / mesh.element_length_m;
        if (std::isfinite(compression_n) && compression_n / euler_n > largest_compression_ratio_) {
          largest_compression_ratio_ = compression_n / euler_n;
          most_compressed_link_ = mesh.link;
        }
        const Vector6d f = t6.transpose() * (GeometricStiffness(mesh, local) * local);
        for (int r = 0; r < 6; ++r) {
          if (dofs[r] >= 0) (*force)(dofs[r]) += f(r);
        }
      }
    }
  }

  static Vector6d GravityVector(const Eigen::Vector2d& g) {
    Vector6d v;
    v << g.x(), g.y(), 0.0, g.x(), g.y(), 0.0;
    return v;
  }

  // A link's rigid motion at the prepared instant: what the loads and the
  // moments both read per link.
  struct LinkFrameMotion {
    double angle_rad = 0.0;
    Eigen::Vector2d end_a_acceleration_m_per_s2;
    Eigen::Vector2d end_b_acceleration_m_per_s2;
    double angular_acceleration_rad_per_s2 = 0.0;
  };

  LinkFrameMotion FrameMotionOf(const LinkMesh& mesh) const {
    const LinkageLink& l = sys_.links[static_cast<size_t>(mesh.link)];
    return {state_.LinkAngle(l), state_.acceleration_m_per_s2[static_cast<size_t>(l.joint_a)],
            state_.acceleration_m_per_s2[static_cast<size_t>(l.joint_b)], state_.LinkAngularAcceleration(l)};
  }

  // Rigid acceleration of element e's two nodes (linear along the link).
  static Vector6d RigidAcceleration(const LinkMesh& mesh, int e, const LinkFrameMotion& frame) {
    const Eigen::Vector2d& aa = frame.end_a_acceleration_m_per_s2;
    const Eigen::Vector2d& ab = frame.end_b_acceleration_m_per_s2;
    const double alpha = frame.angular_acceleration_rad_per_s2;
    const double x1 = static_cast<double>(e) / mesh.elements;
    const double x2 = static_cast<double>(e + 1) / mesh.elements;
    const Eigen::Vector2d a1 = aa + x1 * (ab - aa), a2 = aa + x2 * (ab - aa);
    Vector6d v;
    v << a1.x(), a1.y(), alpha, a2.x(), a2.y(), alpha;
    return v;
  }

  static void AddElement(const LinkMesh& mesh, const int dofs[6], const BeamMatrix& mg,
                         const BeamMatrix& kg, Eigen::MatrixXd* m, Eigen::MatrixXd* k,
                         Eigen::MatrixXd* c) {
    for (int r = 0; r < 6; ++r) {
      if (dofs[r] < 0) continue;
      for (int col = 0; col < 6; ++col) {
        if (dofs[col] < 0) continue;
        (*m)(dofs[r], dofs[col]) += mg(r, col);
        (*k)(dofs[r], dofs[col]) += kg(r, col);
        (*c)(dofs[r], dofs[col]) += mesh.beta_s * kg(r, col);
      }
    }
  }

  static void ElementDofs(const LinkMesh& mesh, int e, int dofs[6]) {
    for (int c = 0; c < 3; ++c) {
      dofs[c] = mesh.nodes[static_cast<size_t>(e)].dof[c];
      dofs[3 + c] = mesh.nodes[static_cast<size_t>(e + 1)].dof[c];
    }
  }

  // Lowest natural frequency of one link alone, ends pinned (translations
  // fixed), the driven root clamped. Frame-independent: local matrices.
  double LowestFrequency(const LinkMesh& mesh) const {
    const int nn = 3 * (mesh.elements + 1);
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(nn, nn), m = Eigen::MatrixXd::Zero(nn, nn);
    for (int e = 0; e < mesh.elements; ++e) {
      k.block<6, 6>(3 * e, 3 * e) += mesh.k;
      m.block<6, 6>(3 * e, 3 * e) += mesh.m;
    }
    std::vector<int> keep;
    for (int i = 0; i < nn; ++i) {
      const int node = i / 3, c = i % 3;
      const bool end = node == 0 || node == mesh.elements;
      if (end && c < 2) continue;
      if (node == mesh.clamped_node && c == 2) continue;
      keep.push_back(i);
    }
    const int nk = static_cast<int>(keep.size());
    Eigen::MatrixXd kr(nk, nk), mr(nk, nk);
    for (int a = 0; a < nk; ++a)
      for (int b = 0; b < nk; ++b) {
        kr(a, b) = k(keep[static_cast<size_t>(a)], keep[static_cast<size_t>(b)]);
        mr(a, b) = m(keep[static_cast<size_t>(a)], keep[static_cast<size_t>(b)]);
      }
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(kr, mr, Eigen::EigenvaluesOnly);
    if (eig.info() != Eigen::Success) return 0.0;
    return std::sqrt(std::max(0.0, eig.eigenvalues()(0)));
  }

  const LinkageSystem& sys_;
  const RigidMotionAt& rigid_motion_;
  std::vector<LinkMesh> meshes_;
  int n_ = 0;
  double lowest_frequency_ = 0.0;
  double beta_ = 0.0;  // the one stiffness-proportional damping coefficient, s
  Eigen::MatrixXd m_, k_, c_;
  Eigen::VectorXd f_;
  Eigen::LLT<Eigen::MatrixXd> lu_;  // of M(t), symmetric positive definite
  Eigen::MatrixXd newton_matrix_;    // M + gamma C + gamma^2 K
  Eigen::LLT<Eigen::MatrixXd> newton_;
  Eigen::VectorXd newton_rhs_;
  Eigen::VectorXd geometric_force_;
  bool factored_ = false;
  double factored_t_ = 0.0, factored_gamma_ = 0.0;
  Eigen::MatrixXd m_inner_, k_inner_, c_inner_;
  LinkageState state_;
  bool prepared_ = false;
  double prepared_t_ = 0.0;
  spec::AnalysisFailure failure_;
  spec::AnalysisFailure divergence_;  // set while the right-hand side is not finite
  int most_compressed_link_ = -1;    // of the last right-hand side, -1: none in compression
  double largest_compression_ratio_ = 0.0;  // its compression / Euler load
  int buckled_link_ = -1;  // the first link compressed beyond its Euler load, -1: none
  double buckled_t_ = 0.0;
};

}  // namespace

spec::AnalysisFailure RunFloatingFrame(const LinkageSystem& system, const spec::IntegratorSettings& integrator,
                                       const std::vector<double>& times_s, const RigidMotionAt& rigid_motion,
                                       const budget::AnalysisBudget* budget,
                                       FloatingFrameResult* result, bool keep_node_displacements) {
  const double t_end = times_s.empty() ? 0.0 : times_s.back();
  ElasticLinkage elastic(system, rigid_motion);
  if (std::string why = elastic.Build(); !why.empty()) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kInvalidModel, why);
  }
  result->lowest_link_frequency_rad_per_s = elastic.lowest_frequency();
  const int n = elastic.num_dofs();

  sundials::CvodesOptions options;
  options.method = sundials::CvodesOptions::Method::kBdf;
  options.relative_tolerance = integrator.relative_tolerance;
  options.absolute_tolerance = integrator.absolute_tolerance;
  options.max_steps = integrator.max_steps;
  options.budget = budget;
  const Eigen::VectorXd y0 = Eigen::VectorXd::Zero(2 * n);
  auto created = sundials::CvodesIntegrator::CreateWithNewtonSolver(
      2 * n,
      [&elastic](double t, const double* y, double* ydot) { return elastic.Rhs(t, y, ydot); },
      [&elastic](double t, double gamma, double* bx, bool* refactored) {
        return elastic.NewtonSolve(t, gamma, bx, refactored);
      },
      sundials::CvodesIntegrator::NewtonRefresh::kEveryIteration, options, 0.0, y0);
  if (!created.ok()) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator,
        absl::StrFormat("elastodynamic integrator setup failed: %s", created.status().message()));
  }
  sundials::CvodesIntegrator& cvodes = **created;
  if (t_end > 0.0) {
    if (absl::Status s = cvodes.SetStopTime(t_end); !s.ok()) {
      return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, std::string(s.message()));
    }
  }
  Eigen::VectorXd y = y0;
  result->rigid_states.clear();
  result->node_moment_n_m.clear();
  result->drive_torque_n_m.clear();
  result->node_displacement_m.clear();
  for (double t : times_s) {
    if (t > cvodes.current_time()) {
      if (absl::Status s = cvodes.IntegrateTo(t, &y); !s.ok()) {
        result->counters = cvodes.counters();
        const std::string context = absl::StrFormat("elastodynamic integration failed before t = %.6g s: ", t);
        const spec::AnalysisFailure model_failure = elastic.failure();
        if (!model_failure.ok()) return spec::AnalysisFailure::Of(model_failure.kind, context + model_failure.reason);
        return sundials::IntegratorFailure(s, context + std::string(s.message()));
      }
    }
    std::vector<std::vector<double>> moments;
    double torque = 0.0;
    if (!elastic.Moments(t, y, &moments, &torque)) {
      result->counters = cvodes.counters();
      const spec::AnalysisFailure model_failure = elastic.failure();
      return model_failure.ok() ? spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue,
                                                       absl::StrFormat("elastic moments not finite at t = %.6g s", t))
                                : model_failure;
    }
    result->rigid_states.push_back(elastic.rigid_state());
    result->node_moment_n_m.push_back(std::move(moments));
    result->drive_torque_n_m.push_back(torque);
    if (keep_node_displacements) elastic.NodeDisplacements(y, &result->node_displacement_m.emplace_back());
  }
  result->counters = cvodes.counters();
  return {};
}

}  // namespace mbopt::multibody
