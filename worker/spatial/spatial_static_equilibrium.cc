#include "worker/spatial/spatial_static_equilibrium.h"

#include "absl/strings/str_format.h"
#include "worker/spatial/redundant_constraints.h"

namespace mbopt::spatial {

multibody::StaticOptions SpatialStaticOptions(budget::AnalysisBudget* budget) {
  multibody::StaticOptions options;
  options.coordinates_per_body = SpatialSystem::kCoordinatesPerBody;
  options.translations_per_body = 3;
  options.budget = budget;
  return options;
}

namespace {

// The combination solves (see the header): each instant's equilibrium with
// the rows combined as they stand at the previous one's, every row of the
// full system checked at the result.
spec::AnalysisFailure StaticWithRedundantRows(const SpatialSystem& system, const SpatialAssembly& assembled,
                                              const std::vector<double>& times_s, budget::AnalysisBudget* budget,
                                              const multibody::MotionCallback& at_instant,
                                              multibody::StaticCounters* counters,
                                              Eigen::MatrixXd* combination_in_use) {
  const int bodies = static_cast<int>(system.model().bodies.size());
  const int rank = static_cast<int>(assembled.independent_combination.rows());
  const multibody::StaticOptions options = SpatialStaticOptions(budget);
  Eigen::VectorXd q = assembled.q;
  for (double t : times_s) {
    const IndependentConstraints now = IndependentCombination(system, t, q);
    if (!now.ok || now.rank != rank) {
      return spec::AnalysisFailure::Of(
          spec::FailureKind::kAssembly,
          absl::StrFormat("the joints' equations have rank %d at t = %.6g s, %d at the start: the mechanism "
                          "reached a pose where its mobility changes",
                          now.rank, t, rank));
    }
    const CombinedConstraintSystem combined(system, now.combination);
    if (combination_in_use != nullptr) *combination_in_use = now.combination;
    const multibody::MotionCallback check = [&](const multibody::MotionSample& s) {
      Eigen::VectorXd phi;
      if (system.Constraints(s.t_s, s.q, &phi) != 0) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kNonFiniteValue,
            absl::StrFormat("the constraint equations are not finite at t = %.6g s", s.t_s));
      }
      phi.head(bodies) /= SpatialSystem::kNormRowScale;
      int row = 0;
      const double largest = phi.size() == 0 ? 0.0 : phi.cwiseAbs().maxCoeff(&row);
      if (!(largest <= kRowBound)) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kAssembly,
            absl::StrFormat("%s is off by %.3g at the equilibrium at t = %.6g s although the redundant joints' "
                            "equations were combined to hold it: the mechanism reached a pose where its "
                            "mobility changes",
                            system.RowOwner(row), phi[row], s.t_s));
      }
      q = s.q;
      return at_instant(s);
    };
    multibody::StaticCounters part;
    const Eigen::VectorXd start = q;  // the check moves q to the result
    const spec::AnalysisFailure f = multibody::RunStaticEquilibrium(combined, start, {t}, options, check, &part);
    counters->position_solves += part.position_solves;
    counters->newton_iterations += part.newton_iterations;
    counters->residual_evaluations += part.residual_evaluations;
    counters->newton_matrices += part.newton_matrices;
    if (!f.ok()) return f;
  }
  return spec::AnalysisFailure::Ok();
}

}  // namespace

spec::AnalysisFailure RunSpatialStaticEquilibrium(const SpatialSystem& system, const SpatialAssembly& assembled,
                                                  const std::vector<double>& times_s, budget::AnalysisBudget* budget,
                                                  const multibody::MotionCallback& at_instant,
                                                  multibody::StaticCounters* counters,
                                                  Eigen::MatrixXd* combination_in_use) {
  if (assembled.redundant_rows > 0) {
    // KINSOL's Newton matrix would be singular with the dependent rows.
    return StaticWithRedundantRows(system, assembled, times_s, budget, at_instant, counters, combination_in_use);
  }
  return multibody::RunStaticEquilibrium(system, assembled.q, times_s, SpatialStaticOptions(budget), at_instant,
                                         counters);
}

}  // namespace mbopt::spatial
