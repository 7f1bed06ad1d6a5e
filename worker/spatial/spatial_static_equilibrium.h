// Static equilibrium of a spatial system at each instant: the planar
// kernel's KINSOL solve and stability check (worker/multibody/
// static_equilibrium.h) on a SpatialSystem, which is a ConstrainedSystem,
// with its coordinates grouped as the spatial bodies' (r, Euler
// parameters): 7 per body, 3 of them translations.
//
// The Euler parameters' unit-norm rows are constraints like the joints':
// Newton holds |p| = 1, their multipliers absorb the generalized forces
// along p, and the null space of Phi_q that the stability check reduces the
// tangent stiffness to leaves out the norm's gauge direction. The
// stiffness is taken of Q - Phi_q^T lambda, norm rows' curvature included,
// so forces whose component along p is not the gradient of a potential off
// the unit sphere still give the stiffness of the rotation itself.
//
// Every free direction needs some stiffness (a joint, a spring, a bushing,
// gravity on a pendulum): a body that may spin freely has a singular
// Newton matrix and no isolated equilibrium; it fails as kAssembly naming
// the time. Redundant joints (redundant_constraints.h) would make the
// Newton matrix singular too: each instant is solved with the joint rows
// replaced by independent combinations of them, taken at the previous
// instant's equilibrium (the assembled start's for the first), and every
// row of the full system is checked at the result (kRowBound); a change of
// rank or a row left unheld ends the analysis (kAssembly) naming the time.
// Their multipliers belong to the combinations.
#pragma once

#include <vector>

#include "spec/analysis_outcome.h"
#include "worker/budget/analysis_budget.h"
#include "worker/multibody/motion.h"
#include "worker/multibody/static_equilibrium.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {

// The planar defaults with the spatial bodies' grouping of coordinates.
multibody::StaticOptions SpatialStaticOptions(budget::AnalysisBudget* budget);

// From `assembled` (AssembleSpatial at times_s.front()); reports (q, lambda)
// with zero velocities and accelerations at each of `times_s` (ascending).
// With redundant joints and `combination_in_use`, that holds the
// combination of the rows each instant was solved with (its multipliers'
// rows) while `at_instant` sees it; its sensitivities are those of the
// CombinedConstraintSystem with that combination.
spec::AnalysisFailure RunSpatialStaticEquilibrium(const SpatialSystem& system, const SpatialAssembly& assembled,
                                                  const std::vector<double>& times_s, budget::AnalysisBudget* budget,
                                                  const multibody::MotionCallback& at_instant,
                                                  multibody::StaticCounters* counters,
                                                  Eigen::MatrixXd* combination_in_use = nullptr);

}  // namespace mbopt::spatial
