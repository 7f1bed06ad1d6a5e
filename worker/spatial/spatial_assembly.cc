#include "worker/spatial/spatial_assembly.h"

#include "absl/strings/str_format.h"
#include "worker/spatial/redundant_constraints.h"

namespace mbopt::spatial {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// The constraint residuals in their own units: the normalization rows
// without their scale (SpatialSystem::kNormRowScale).
VectorXd Unscaled(const SpatialSystem& system, VectorXd phi) {
  phi.head(static_cast<int>(system.model().bodies.size())) /= SpatialSystem::kNormRowScale;
  return phi;
}

int LargestRow(const VectorXd& phi) {
  int row = 0;
  phi.cwiseAbs().maxCoeff(&row);
  return row;
}

}  // namespace

SpatialAssembly AssembleSpatial(const SpatialSystem& system, double t, const SpatialAssemblyOptions& options) {
  SpatialAssembly out;
  const int m = system.num_constraints();
  out.q = system.InitialGuess();
  VectorXd phi;
  MatrixXd phi_q;
  auto not_finite = [&] {
    return spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue,
                                     absl::StrFormat("the constraint equations are not finite at t = %.6g s", t));
  };
  if (m > 0) {
    if (system.Constraints(t, out.q, &phi) != 0) {
      out.failure = not_finite();
      return out;
    }
    double residual = multibody::MaxAbs(Unscaled(system, phi));
    bool stalled = false;
    while (residual > options.position_tolerance) {
      if (stalled || out.newton_iterations == options.max_iterations) {
        const VectorXd unscaled = Unscaled(system, phi);
        const int row = LargestRow(unscaled);
        out.failure = spec::AnalysisFailure::Of(
            spec::FailureKind::kAssembly,
            absl::StrFormat("the mechanism does not assemble at t = %.6g s: %s is off by %.3g after %d Newton "
                            "iterations",
                            t, system.RowOwner(row), unscaled[row], out.newton_iterations));
        return out;
      }
      if (system.ConstraintJacobian(t, out.q, &phi_q) != 0) {
        out.failure = not_finite();
        return out;
      }
      // Minimum-norm step: the joints' rows do not fix the free coordinates,
      // and redundant rows make Phi_q rank-deficient.
      const Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(phi_q);
      const VectorXd step = cod.solve(-phi);
      // Halve the step until the residual falls: far from the solution the
      // full Newton step of these quadratic equations can overshoot.
      double scale = 1.0;
      VectorXd trial, trial_phi;
      double trial_residual = 0.0;
      for (int halving = 0; halving < 30; ++halving, scale *= 0.5) {
        trial = out.q + scale * step;
        if (system.Constraints(t, trial, &trial_phi) != 0) continue;
        trial_residual = multibody::MaxAbs(Unscaled(system, trial_phi));
        if (trial_residual < residual) break;
      }
      ++out.newton_iterations;
      if (!(trial_residual < residual)) {
        stalled = true;  // no descent along Newton's direction: the loop cannot close from here
        continue;
      }
      out.q = trial;
      phi = trial_phi;
      residual = trial_residual;
    }
    for (int i = 0; i < options.polish_iterations; ++i) {
      if (system.ConstraintJacobian(t, out.q, &phi_q) != 0) {
        out.failure = not_finite();
        return out;
      }
      const VectorXd polished = out.q + Eigen::CompleteOrthogonalDecomposition<MatrixXd>(phi_q).solve(-phi);
      if (system.Constraints(t, polished, &phi) != 0) {
        out.failure = not_finite();
        return out;
      }
      out.q = polished;
      ++out.newton_iterations;
    }
  }
  // Velocities: the smallest change of the bodies' initial velocities that
  // satisfies Phi_q v + Phi_t = 0.
  out.v = system.InitialVelocityGuess();
  const int n = system.num_coordinates();
  if (m == 0) {
    out.degrees_of_freedom = n;
    return out;
  }
  VectorXd phi_t;
  if (system.ConstraintJacobian(t, out.q, &phi_q) != 0 || system.ConstraintTimeDerivative(t, out.q, &phi_t) != 0) {
    out.failure = not_finite();
    return out;
  }
  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(phi_q);
  cod.setThreshold(options.rank_tolerance);
  out.v -= cod.solve(phi_q * out.v + phi_t);
  const IndependentConstraints independent = IndependentCombination(system, t, out.q);
  if (!independent.ok) {
    out.failure = not_finite();
    return out;
  }
  out.independent_combination = independent.combination;
  const int rank = independent.rank;
  out.degrees_of_freedom = n - rank;
  out.redundant_rows = m - rank;
  return out;
}

}  // namespace mbopt::spatial
