#include "worker/spatial/spatial_static_equilibrium.h"

#include "absl/strings/str_format.h"

namespace mbopt::spatial {

multibody::StaticOptions SpatialStaticOptions(budget::AnalysisBudget* budget) {
  multibody::StaticOptions options;
  options.coordinates_per_body = SpatialSystem::kCoordinatesPerBody;
  options.translations_per_body = 3;
  options.budget = budget;
  return options;
}

spec::AnalysisFailure RunSpatialStaticEquilibrium(const SpatialSystem& system, const SpatialAssembly& assembled,
                                                  const std::vector<double>& times_s, budget::AnalysisBudget* budget,
                                                  const multibody::MotionCallback& at_instant,
                                                  multibody::StaticCounters* counters) {
  if (assembled.redundant_rows > 0) {
    // KINSOL's Newton matrix is singular with dependent rows.
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kInvalidModel,
        absl::StrFormat("the mechanism has %d redundant constraint equation(s): a static-equilibrium analysis "
                        "needs independent joints (e.g. a spherical joint made a point-on-line one)",
                        assembled.redundant_rows));
  }
  return multibody::RunStaticEquilibrium(system, assembled.q, times_s, SpatialStaticOptions(budget), at_instant,
                                         counters);
}

}  // namespace mbopt::spatial
