// The analytic derivatives of the multibody equations (mechanism_derivatives.cc)
// and the GGL Newton matrix built from them (ggl_residual.h), against
// central difference quotients of what they differentiate, on scenes that
// together hold every joint kind, driver kind and force element: a closed
// chain (ten bodies, two loops), the press (prismatic guide, point force),
// the isolator with tabulated spring and damper curves, the co-rotational
// elastic four-bar (beams with structural damping), and a hand-built model
// with the elements those lack (point on line, a driven prismatic joint,
// rotational springs, an off-centre force, a spring between two bodies).
//
// Step and tolerance: central differences with step 1e-6 (scaled by the
// coordinate's size) have truncation error ~1e-12 of the entry and round-off
// ~1e-16 |F| / 1e-6 = 1e-10 of the function's size; entries are compared
// with 1e-6 of their column's largest magnitude (at least 1e-3 of the
// matrix's).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/ggl_residual.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kStep = 1e-6;
constexpr double kTolerance = 1e-6;

// Every entry of `analytic` against `numeric`, relative to its column.
::testing::AssertionResult ColumnsAgree(const MatrixXd& analytic, const MatrixXd& numeric, const std::string& what) {
  if (analytic.rows() != numeric.rows() || analytic.cols() != numeric.cols()) {
    return ::testing::AssertionFailure() << what << ": sizes differ";
  }
  // A column whose entries are all small (a coordinate that barely enters)
  // is compared at the matrix's scale: its difference quotients are mostly
  // round-off of the function's value.
  const double overall = numeric.size() == 0 ? 0.0 : numeric.cwiseAbs().maxCoeff();
  for (Eigen::Index j = 0; j < numeric.cols(); ++j) {
    const double scale = std::max(numeric.col(j).cwiseAbs().maxCoeff(), analytic.col(j).cwiseAbs().maxCoeff());
    for (Eigen::Index i = 0; i < numeric.rows(); ++i) {
      if (std::abs(analytic(i, j) - numeric(i, j)) > kTolerance * std::max({scale, 1e-3 * overall, 1e-3})) {
        return ::testing::AssertionFailure() << what << " (" << i << ", " << j << "): analytic " << analytic(i, j)
                                             << ", difference quotient " << numeric(i, j) << ", column scale "
                                             << scale;
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// d f(x) / dx by central differences, f: R^k -> R^r.
template <class F>
MatrixXd DifferenceQuotients(const VectorXd& x, int rows, F f) {
  MatrixXd out(rows, x.size());
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double h = kStep * std::max(1.0, std::abs(x[j]));
    VectorXd plus = x, minus = x;
    plus[j] += h;
    minus[j] -= h;
    out.col(j) = (f(plus) - f(minus)) / (2.0 * h);
  }
  return out;
}

// A state away from any special position: the assembled pose, every
// coordinate moved a little and every body moving (the derivatives hold at
// any state, consistent or not). Deterministic.
void GenericState(const Mechanism& m, VectorXd* q, VectorXd* v, VectorXd* w) {
  const Assembly assembled = Assemble(m, 0.0);
  *q = assembled.failure.ok() ? assembled.q : m.InitialGuess();
  v->resize(q->size());
  for (Eigen::Index i = 0; i < q->size(); ++i) {
    (*q)[i] += 1e-3 * std::sin(1.0 + 1.7 * static_cast<double>(i));
    (*v)[i] = 0.3 * std::cos(0.5 + 2.3 * static_cast<double>(i));
  }
  w->resize(m.num_constraints());
  for (Eigen::Index i = 0; i < w->size(); ++i) (*w)[i] = 10.0 * std::sin(0.2 + 1.3 * static_cast<double>(i));
}

void ExpectDerivativesMatchDifferences(const Mechanism& m, double t) {
  VectorXd q, v, w;
  GenericState(m, &q, &v, &w);
  const int n = m.num_coordinates(), rows = m.num_constraints();
  const ContinuedPastBounds continued(m);

  MatrixXd q_q, q_v;
  ASSERT_EQ(m.ForceJacobians(t, q, v, &q_q, &q_v), 0);
  const auto forces_at = [&](const VectorXd& qq, const VectorXd& vv) {
    VectorXd f;
    EXPECT_EQ(m.AppliedForces(t, qq, vv, &f), 0);
    return f;
  };
  EXPECT_TRUE(ColumnsAgree(q_q, DifferenceQuotients(q, n, [&](const VectorXd& x) { return forces_at(x, v); }),
                           "dQ/dq"));
  EXPECT_TRUE(ColumnsAgree(q_v, DifferenceQuotients(v, n, [&](const VectorXd& x) { return forces_at(q, x); }),
                           "dQ/dv"));
  if (rows == 0) return;

  MatrixXd curvature, velocity_q;
  ASSERT_EQ(m.ConstraintCurvature(t, q, w, &curvature), 0);
  EXPECT_TRUE(ColumnsAgree(curvature, DifferenceQuotients(q, n, [&](const VectorXd& x) {
                             MatrixXd phi_q;
                             EXPECT_EQ(m.ConstraintJacobian(t, x, &phi_q), 0);
                             return VectorXd(phi_q.transpose() * w);
                           }),
                           "d(Phi_q^T w)/dq"));
  ASSERT_EQ(m.VelocityConstraintJacobian(t, q, v, &velocity_q), 0);
  EXPECT_TRUE(ColumnsAgree(velocity_q, DifferenceQuotients(q, rows, [&](const VectorXd& x) {
                             MatrixXd phi_q;
                             VectorXd phi_t;
                             EXPECT_EQ(m.ConstraintJacobian(t, x, &phi_q), 0);
                             EXPECT_EQ(m.ConstraintTimeDerivative(t, x, &phi_t), 0);
                             return VectorXd(phi_q * v + phi_t);
                           }),
                           "d(Phi_q v + Phi_t)/dq"));
}

// The Newton matrix dF/dy + cj dF/dy' against differences of the residual
// in y and in y' (cj = 1e3, a step of about 1 ms).
void ExpectNewtonMatrixMatchesDifferences(const Mechanism& m, double t) {
  VectorXd q, v, w;
  GenericState(m, &q, &v, &w);
  const int n = m.num_coordinates(), rows = m.num_constraints(), size = 2 * n + 2 * rows;
  VectorXd y(size), y_dot(size);
  y << q, v, w, 1e-3 * w.reverse();
  for (Eigen::Index i = 0; i < size; ++i) y_dot[i] = std::cos(0.7 * static_cast<double>(i));
  constexpr double kCj = 1e3;
  GglWorkspace work;
  MatrixXd newton;
  ASSERT_EQ(GglNewtonMatrix(m, t, kCj, y, y_dot, &work, &newton), 0);
  const auto residual = [&](const VectorXd& yy, const VectorXd& yy_dot) {
    VectorXd r(size);
    EXPECT_EQ(GglResidual(m, t, yy, yy_dot, &work, r), 0);
    return r;
  };
  const MatrixXd numeric = DifferenceQuotients(y, size, [&](const VectorXd& x) { return residual(x, y_dot); }) +
                           kCj * DifferenceQuotients(y_dot, size, [&](const VectorXd& x) { return residual(y, x); });
  EXPECT_TRUE(ColumnsAgree(newton, numeric, "Newton matrix"));
  // The sparse solver's pattern holds every entry that is not zero.
  const ConstrainedSystem::Pattern pattern = GglNewtonPattern(m);
  ASSERT_EQ(pattern.rows(), size);
  ASSERT_EQ(pattern.cols(), size);
  for (int j = 0; j < size; ++j) {
    for (int i = 0; i < size; ++i) {
      EXPECT_TRUE(pattern(i, j) || newton(i, j) == 0.0) << "(" << i << ", " << j << ") outside the pattern";
    }
  }
  EXPECT_LT(pattern.count(), size * size) << "a pattern with every entry would not be sparse";
}

// Paths from the source tree (the tests run there).
spec::Scene LoadScene(const std::string& relative) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(relative);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : spec::Scene{};
}

// At the scene's default parameter values.
Model Compiled(const std::string& relative) {
  const spec::Scene scene = LoadScene(relative);
  std::vector<double> defaults;
  for (const spec::Parameter& p : scene.parameters) defaults.push_back(p.value_si);
  absl::StatusOr<Model> model = CompileModel(scene, defaults);
  EXPECT_TRUE(model.ok()) << model.status();
  return model.ok() ? *model : Model{};
}

// Elements no example scene combines: a slider on a point-on-line joint
// pulled by a damped spring from a swinging arm, a prismatic joint driven
// along its axis, rotational springs with damping, a force off a body's
// centre.
Model EveryElement() {
  using testing::At;
  using testing::Bar;
  Model m;
  m.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  m.bodies.push_back(Bar("arm", 2.0, 1.0, {0.5, 0.0}, 0.0));
  Body slider;
  slider.name = "slider";
  slider.mass_kg = 1.0;
  slider.inertia_kg_m2 = 0.02;
  slider.position_m = {1.5, -0.5};
  m.bodies.push_back(slider);
  Body carriage = slider;
  carriage.name = "carriage";
  carriage.position_m = {-1.0, 0.5};
  carriage.angle_rad = 0.3;
  m.bodies.push_back(carriage);
  m.bodies.push_back(Bar("flap", 0.5, 0.4, {-1.0, 0.7}, 0.3 + 1.2));
  m.joints.push_back(testing::Revolute("hinge", At(kGround, 0.0), At(0, -0.5)));
  Joint line;
  line.name = "line";
  line.kind = JointKind::kPointOnLine;
  line.a = At(kGround, 1.5, -0.5);
  line.b = At(1, 0.05, 0.02);
  line.axis_angle_rad = 0.2;
  m.joints.push_back(line);
  Joint slide;
  slide.name = "slide";
  slide.kind = JointKind::kPrismatic;
  slide.a = At(0, 0.1, 0.05);
  slide.b = At(2, 0.0, 0.0);
  slide.axis_angle_rad = -0.4;
  // Body a is the arm, so the carriage's axis turns with it.
  m.joints.push_back(slide);
  m.joints.push_back(testing::Revolute("flap_pin", At(2, 0.1, 0.1), At(3, -0.2)));
  Driver drive;
  drive.joint = 2;
  drive.profile.kind = Profile::Kind::kHarmonic;
  drive.profile.amplitude = 0.1;
  drive.profile.angular_frequency_rad_per_s = 3.0;
  m.drivers.push_back(drive);
  SpringDamper s;
  s.name = "link";
  s.a = At(0, 0.4, 0.1);
  s.b = At(1, -0.05, 0.03);
  s.free_length_m = 0.3;
  s.stiffness_n_per_m = 500.0;
  s.damping_n_s_per_m = 7.0;
  s.actuator_force_n = 3.0;
  m.springs.push_back(s);
  RotationalSpringDamper r;
  r.name = "hinge spring";
  r.joint = 0;
  r.stiffness_n_m_per_rad = 40.0;
  r.damping_n_m_s_per_rad = 0.5;
  r.free_angle_rad = 0.1;
  m.rotational_springs.push_back(r);
  r.name = "flap spring";
  r.joint = 3;
  m.rotational_springs.push_back(r);
  m.point_forces.push_back(PointForce{At(0, 0.3, -0.05), Eigen::Vector2d(4.0, -2.0), std::nullopt});
  BodyTorque torque;
  torque.body = 1;
  torque.torque_n_m = 0.7;
  m.torques.push_back(torque);
  return m;
}

TEST(MultibodyDerivatives, EveryElementMatchesDifferenceQuotients) {
  const Model model = EveryElement();
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const Mechanism m(model);
  ExpectDerivativesMatchDifferences(m, 0.3);
  ExpectNewtonMatrixMatchesDifferences(m, 0.3);
}

TEST(MultibodyDerivatives, ClosedChainMatchesDifferenceQuotients) {
  const Model model = testing::TenBodyChain();
  const Mechanism m(model);
  ExpectDerivativesMatchDifferences(m, 0.0);
  ExpectNewtonMatrixMatchesDifferences(m, 0.0);
}

TEST(MultibodyDerivatives, SliderCrankMatchesDifferenceQuotients) {
  const Model model = testing::SundialsSliderCrank(1.0, 0.3);
  const Mechanism m(model);
  ExpectDerivativesMatchDifferences(m, 0.0);
  ExpectNewtonMatrixMatchesDifferences(m, 0.0);
}

TEST(MultibodyDerivatives, PressMatchesDifferenceQuotients) {
  const Model model = Compiled("examples/press/press.scene.textproto");
  const Mechanism m(model);
  ExpectDerivativesMatchDifferences(m, 0.01);
  ExpectNewtonMatrixMatchesDifferences(m, 0.01);
}

TEST(MultibodyDerivatives, TabulatedIsolatorMatchesDifferenceQuotients) {
  // The isolator driven through its tabulated base motion, its suspension
  // given force curves in place of the linear laws (scenes write them as
  // literal tables; tables_test.cc loads those), stiffening and with a
  // bilinear damper.
  Model model = Compiled("tests/multibody/isolator_tabulated.scene.textproto");
  ASSERT_EQ(model.springs.size(), 1u);
  model.springs[0].deflection_curve = LinearTable{{-0.3, -0.02, 0.0, 0.02, 0.3}, {-3000.0, -60.0, 0.0, 50.0, 4000.0}};
  model.springs[0].velocity_curve = LinearTable{{-10.0, -0.05, 0.05, 10.0}, {-300.0, -1.5, 1.0, 100.0}};
  const Mechanism m(model);
  ExpectDerivativesMatchDifferences(m, 0.02);
  ExpectNewtonMatrixMatchesDifferences(m, 0.02);
}

TEST(MultibodyDerivatives, CorotationalFourBarMatchesDifferenceQuotients) {
  const Model model = Compiled("examples/fourbar/fourbar_corotational.scene.textproto");
  ASSERT_FALSE(model.beams.empty());
  ASSERT_GT(model.beams[0].damping_s, 0.0);
  const Mechanism m(model);
  ExpectDerivativesMatchDifferences(m, 0.0);
  ExpectNewtonMatrixMatchesDifferences(m, 0.0);
}

// The integrator uses the analytic Newton matrix: forming it costs no
// residual evaluations, where difference quotients cost one per unknown.
TEST(MultibodyDerivatives, IntegratorFormsNewtonMatrixWithoutResiduals) {
  const Model model = testing::TenBodyChain();
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f =
      IntegrateForward(m, 0.0, assembled.q, assembled.v, {0.0, 0.5}, ForwardDynamicsOptions{},
                       [](const MotionSample&) { return spec::AnalysisFailure::Ok(); }, &counters);
  ASSERT_TRUE(f.ok()) << f.reason;
  EXPECT_GT(counters.jacobian_evaluations, 0);
  EXPECT_EQ(counters.jacobian_residual_evaluations, 0);
}

// Dense LU and KLU solve the same Newton systems: the same motion to well
// within the integration tolerance (rtol 1e-8; the two round differently).
TEST(MultibodyDerivatives, SparseAndDenseSolversGiveTheSameMotion) {
  const Model model = testing::TenBodyChain();
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<VectorXd> ends;
  for (const auto solver : {ForwardDynamicsOptions::LinearSolver::kDense, ForwardDynamicsOptions::LinearSolver::kSparse}) {
    ForwardDynamicsOptions options;
    options.relative_tolerance = 1e-8;
    options.absolute_tolerance = 1e-10;
    options.linear_solver = solver;
    ForwardDynamicsCounters counters;
    VectorXd end;
    const spec::AnalysisFailure f = IntegrateForward(
        m, 0.0, assembled.q, assembled.v, {0.0, 1.0}, options,
        [&](const MotionSample& sample) {
          end = sample.q;
          return spec::AnalysisFailure::Ok();
        },
        &counters);
    ASSERT_TRUE(f.ok()) << f.reason;
    EXPECT_EQ(counters.sparse_linear_solver, solver == ForwardDynamicsOptions::LinearSolver::kSparse);
    ends.push_back(end);
  }
  EXPECT_LT((ends[0] - ends[1]).cwiseAbs().maxCoeff(), 1e-7);
}

}  // namespace
}  // namespace mbopt::multibody
