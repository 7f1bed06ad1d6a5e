// Planar Euler-Bernoulli beam element: statics, natural frequencies against
// the closed-form Euler-Bernoulli values, buckling and beam-column bending
// (geometric stiffness), and energy of free vibration.
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "worker/multibody/floating_frame_beam.h"
#include "worker/sundials/cvodes_integrator.h"

namespace mbopt {
namespace {

// A straight beam along x of `n` equal elements, dofs (u, w, theta) per node.
struct Beam {
  Eigen::MatrixXd k, m, kg;  // kg: geometric stiffness of a unit tension
};

constexpr double kLength = 0.9144, kArea = 4e-4, kE = 6.895e10, kRho = 2757;
const double kI = kArea * kArea / (4 * std::numbers::pi);

Beam Assemble(int n, double rotary_inertia = 0.0) {
  multibody::floating_frame::BeamSection s;
  s.length_m = kLength / n;
  s.axial_stiffness_n = kE * kArea;
  s.bending_stiffness_n_m2 = kE * kI;
  s.mass_per_length_kg_per_m = kRho * kArea;
  s.rotary_inertia_kg_m = rotary_inertia;
  const multibody::floating_frame::BeamMatrix ke = multibody::floating_frame::BeamStiffness(s), me = multibody::floating_frame::BeamConsistentMass(s);
  const multibody::floating_frame::BeamMatrix kge = multibody::floating_frame::BeamGeometricStiffness(s.length_m, 1.0);
  const int nd = 3 * (n + 1);
  Beam b{Eigen::MatrixXd::Zero(nd, nd), Eigen::MatrixXd::Zero(nd, nd), Eigen::MatrixXd::Zero(nd, nd)};
  for (int e = 0; e < n; ++e) {
    b.k.block<6, 6>(3 * e, 3 * e) += ke;
    b.m.block<6, 6>(3 * e, 3 * e) += me;
    b.kg.block<6, 6>(3 * e, 3 * e) += kge;
  }
  return b;
}

// Keeps the dofs not in `fixed`.
Eigen::MatrixXd Reduce(const Eigen::MatrixXd& a, const std::vector<int>& keep) {
  Eigen::MatrixXd r(keep.size(), keep.size());
  for (size_t i = 0; i < keep.size(); ++i)
    for (size_t j = 0; j < keep.size(); ++j) r(i, j) = a(keep[i], keep[j]);
  return r;
}

std::vector<int> Keep(int n, const std::vector<int>& fixed) {
  std::vector<int> keep;
  for (int i = 0; i < 3 * (n + 1); ++i) {
    if (std::find(fixed.begin(), fixed.end(), i) == fixed.end()) keep.push_back(i);
  }
  return keep;
}

double LowestBendingFrequency(int n, const std::vector<int>& fixed) {
  const Beam b = Assemble(n);
  const std::vector<int> keep = Keep(n, fixed);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Reduce(b.k, keep),
                                                                Reduce(b.m, keep));
  return std::sqrt(eig.eigenvalues()(0));
}

TEST(BeamElement, CantileverTipDeflectionIsPLCubedOver3EI) {
  for (int n : {1, 3, 6}) {
    const Beam b = Assemble(n);
    const std::vector<int> keep = Keep(n, {0, 1, 2});  // clamped at x = 0
    Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(keep.size()));
    const double p = 10.0;
    f(static_cast<Eigen::Index>(keep.size()) - 2) = p;  // transverse tip load
    const Eigen::VectorXd u = Reduce(b.k, keep).ldlt().solve(f);
    const double exact = p * kLength * kLength * kLength / (3 * kE * kI);
    // Hermite cubics are exact for end-loaded beams: only round-off.
    EXPECT_NEAR(u(u.size() - 2), exact, 1e-9 * exact) << n << " elements";
    EXPECT_NEAR(u(u.size() - 1), p * kLength * kLength / (2 * kE * kI), 1e-9 * exact / kLength);
  }
}

TEST(BeamElement, AxialStretchIsPLOverEA) {
  const Beam b = Assemble(4);
  const std::vector<int> keep = Keep(4, {0, 1, 2});
  Eigen::VectorXd f = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(keep.size()));
  f(static_cast<Eigen::Index>(keep.size()) - 3) = 1000.0;
  const Eigen::VectorXd u = Reduce(b.k, keep).ldlt().solve(f);
  const double exact = 1000.0 * kLength / (kE * kArea);
  EXPECT_NEAR(u(u.size() - 3), exact, 1e-9 * exact);
}

// Euler-Bernoulli: omega_1 = (beta L)^2 / L^2 sqrt(EI / rho A) with
// beta L = pi (pinned-pinned) and 1.875104 (cantilever). Consistent-mass
// Hermite elements converge from above, with error ~ h^4.
TEST(BeamElement, PinnedPinnedFrequencyConvergesToEulerBernoulli) {
  const double exact = std::pow(std::numbers::pi / kLength, 2) * std::sqrt(kE * kI / (kRho * kArea));
  double previous_error = 1.0;
  for (int n : {1, 2, 4, 8}) {
    const double w = LowestBendingFrequency(n, {0, 1, 3 * n, 3 * n + 1});  // both ends pinned
    const double error = (w - exact) / exact;
    EXPECT_GT(error, -1e-12) << n;  // an upper bound (Rayleigh-Ritz)
    EXPECT_LT(error, previous_error) << n;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-4);  // 8 elements
}

TEST(BeamElement, CantileverFrequencyConvergesToEulerBernoulli) {
  const double exact = std::pow(1.8751040687 / kLength, 2) * std::sqrt(kE * kI / (kRho * kArea));
  double previous_error = 1.0;
  for (int n : {1, 2, 4, 8}) {
    const double w = LowestBendingFrequency(n, {0, 1, 2});
    const double error = (w - exact) / exact;
    EXPECT_GT(error, -1e-12) << n;
    EXPECT_LT(error, previous_error) << n;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-5);
}

// Geometric stiffness, first check: K v = P Kg v gives the buckling loads.
// Euler: P_cr = pi^2 EI / L^2 (pinned-pinned); Hermite elements with the
// consistent geometric stiffness converge to it from above.
TEST(BeamElement, BucklingLoadConvergesToEuler) {
  const double euler = std::pow(std::numbers::pi / kLength, 2) * kE * kI;
  double previous_error = 1.0;
  for (int n : {1, 2, 4, 8}) {
    const Beam b = Assemble(n);
    // Bending dofs only (Kg is zero on the axial ones), both ends pinned.
    std::vector<int> fixed = {1, 3 * n + 1};
    for (int node = 0; node <= n; ++node) fixed.push_back(3 * node);
    const std::vector<int> keep = Keep(n, fixed);
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Reduce(b.k, keep),
                                                                  Reduce(b.kg, keep));
    ASSERT_EQ(eig.info(), Eigen::Success);
    const double error = (eig.eigenvalues()(0) - euler) / euler;
    EXPECT_GT(error, -1e-12) << n;
    EXPECT_LT(error, previous_error) << n;
    previous_error = error;
  }
  EXPECT_LT(previous_error, 1e-4);  // 8 elements: 3.3e-5
}

// Second check: the P-delta effect on a pinned-pinned beam under a uniform
// load q and an axial force P. Beam-column theory (Timoshenko & Gere,
// Theory of Elastic Stability, 1.11) gives the mid-span deflection as the
// linear one, 5 q L^4 / 384 EI, times 12 (2 sec v - 2 - v^2) / (5 v^4) in
// compression and 12 (2 sech v - 2 + v^2) / (5 v^4) in tension, with
// v = (L / 2) sqrt(|P| / EI).
TEST(BeamElement, AxialForceScalesBendingAsBeamColumnTheory) {
  const int n = 6;  // the four-bar's mesh
  const double euler = std::pow(std::numbers::pi / kLength, 2) * kE * kI;
  const double q = 100.0;  // N/m
  const double h = kLength / n;
  const Beam b = Assemble(n);
  const std::vector<int> keep = Keep(n, {0, 1, 3 * n + 1});  // pinned; axial held at one end
  Eigen::VectorXd f_full = Eigen::VectorXd::Zero(3 * (n + 1));
  for (int e = 0; e < n; ++e) {  // consistent nodal loads of q
    f_full(3 * e + 1) += q * h / 2;
    f_full(3 * e + 2) += q * h * h / 12;
    f_full(3 * e + 4) += q * h / 2;
    f_full(3 * e + 5) -= q * h * h / 12;
  }
  Eigen::VectorXd f(static_cast<Eigen::Index>(keep.size()));
  for (size_t i = 0; i < keep.size(); ++i) f(static_cast<Eigen::Index>(i)) = f_full(keep[i]);
  const double linear = 5 * q * std::pow(kLength, 4) / (384 * kE * kI);
  // Six elements resolve the amplified shape to ~1e-4 at 60 % of the
  // buckling load (the cubic no longer interpolates the exact deflection).
  constexpr double kMeshTolerance = 2e-4;
  for (double ratio : {-0.6, -0.3, -0.05, 0.05, 0.3, 1.0, 3.0}) {  // P / P_cr, tension > 0
    const double p = ratio * euler;
    const double v = 0.5 * kLength * std::sqrt(std::abs(p) / (kE * kI));
    const double factor = p < 0 ? 12 * (2 / std::cos(v) - 2 - v * v) / (5 * std::pow(v, 4))
                                : 12 * (2 / std::cosh(v) - 2 + v * v) / (5 * std::pow(v, 4));
    const Eigen::VectorXd u = Reduce(b.k + p * b.kg, keep).lu().solve(f);
    // keep drops dofs 0 and 1, so the middle node's w is at 3 (n / 2) + 1 - 2.
    const double mid = u(3 * (n / 2) - 1);
    EXPECT_NEAR(mid / linear, factor, kMeshTolerance * factor) << "P / P_cr = " << ratio;
  }
}

// Undamped free vibration of a pinned-pinned beam from a bent shape:
// kinetic + strain energy stays constant (integrated with CVODES Adams at a
// tight tolerance, whose drift bounds the check).
TEST(BeamElement, UndampedFreeVibrationConservesEnergy) {
  const int n = 4;
  const Beam b = Assemble(n, kRho * kI);
  const std::vector<int> keep = Keep(n, {0, 1, 3 * n, 3 * n + 1});
  const Eigen::MatrixXd k = Reduce(b.k, keep), m = Reduce(b.m, keep);
  const int nd = static_cast<int>(keep.size());
  const Eigen::LDLT<Eigen::MatrixXd> mfac(m);
  Eigen::VectorXd y0 = Eigen::VectorXd::Zero(2 * nd);
  // Initial deflection: the static shape under a mid-span load.
  Eigen::VectorXd f = Eigen::VectorXd::Zero(nd);
  f(3 * (n / 2) + 1 - 2) = 50.0;  // w of the middle node (first two dofs removed)
  y0.head(nd) = k.ldlt().solve(f);
  auto energy = [&](const Eigen::VectorXd& y) {
    return 0.5 * y.head(nd).dot(k * y.head(nd)) + 0.5 * y.tail(nd).dot(m * y.tail(nd));
  };
  sundials::CvodesOptions options;
  options.method = sundials::CvodesOptions::Method::kAdams;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-14;
  auto integrator = sundials::CvodesIntegrator::Create(
      2 * nd,
      [&](double, const double* y, double* ydot) {
        Eigen::Map<const Eigen::VectorXd> u(y, nd), v(y + nd, nd);
        Eigen::Map<Eigen::VectorXd>(ydot, nd) = v;
        Eigen::Map<Eigen::VectorXd>(ydot + nd, nd) = -mfac.solve(k * u);
        return 0;
      },
      nullptr, options, 0.0, y0);
  ASSERT_TRUE(integrator.ok()) << integrator.status();
  const double e0 = energy(y0);
  ASSERT_GT(e0, 0.0);
  Eigen::VectorXd y = y0;
  for (int i = 1; i <= 10; ++i) {
    ASSERT_TRUE((*integrator)->IntegrateTo(0.005 * i, &y).ok());  // a quarter of the lowest period each
    EXPECT_NEAR(energy(y), e0, 1e-5 * e0) << "t = " << 0.005 * i;
  }
}

}  // namespace
}  // namespace mbopt
