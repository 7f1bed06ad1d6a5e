// Assembly of a spatial mechanism at a time t: positions by Newton on the
// constraint equations with minimum-norm steps from the bodies' initial
// poses (the drivers at t; the Euler parameters' unit norms are rows like
// the joints'), then velocities as the least-squares correction of the
// bodies' initial velocities onto Phi_q v = -Phi_t. The planar assembly
// (worker/multibody/assembly.h) works on a planar Mechanism's joint
// coordinates and initial joint values; this one needs only the
// ConstrainedSystem equations and the initial guesses of a SpatialSystem.
//
// The degrees of freedom are n minus the rank of Phi_q at the assembled
// configuration (column-pivoted QR, IndependentCombination in
// redundant_constraints.h), so redundant rows are counted, not refused,
// and the independent combinations to integrate with are given. Failures are data: a loop that cannot close is a kAssembly
// failure naming the row with the largest residual and the time.
#pragma once

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {

struct SpatialAssemblyOptions {
  // Residual accepted as closed (m, or dimensionless for the dot products
  // of unit vectors): far below any integration tolerance.
  double position_tolerance = 1e-12;
  int max_iterations = 50;
  // Relative threshold of the QR's diagonal below which a row is counted
  // as redundant.
  double rank_tolerance = 1e-9;
  // Full Newton steps taken after the tolerance is met: sensitivities
  // difference the assemblies of models at p +- h, so each must close to
  // round-off, not merely to the tolerance.
  int polish_iterations = 0;
};

struct SpatialAssembly {
  spec::AnalysisFailure failure;
  Eigen::VectorXd q, v;
  int degrees_of_freedom = 0;  // with the drivers
  int redundant_rows = 0;      // rows beyond the rank of Phi_q
  // r x m, r the rank of Phi_q at q: the normalization rows and
  // orthonormal combinations of the others, what forward dynamics
  // integrates with when redundant_rows > 0 (CombinedConstraintSystem).
  Eigen::MatrixXd independent_combination;
  int newton_iterations = 0;
};

SpatialAssembly AssembleSpatial(const SpatialSystem& system, double t_s, const SpatialAssemblyOptions& options = {});

}  // namespace mbopt::spatial
