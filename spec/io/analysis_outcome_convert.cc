#include "spec/io/analysis_outcome_convert.h"

namespace mbopt::spec::io {

v1::AnalysisFailureKind FailureKindToProto(FailureKind kind) {
  switch (kind) {
    case FailureKind::kInvalidModel:
      return v1::ANALYSIS_FAILURE_INVALID_MODEL;
    case FailureKind::kAssembly:
      return v1::ANALYSIS_FAILURE_ASSEMBLY;
    case FailureKind::kIntegrator:
      return v1::ANALYSIS_FAILURE_INTEGRATOR;
    case FailureKind::kTimeLimit:
      return v1::ANALYSIS_FAILURE_TIME_LIMIT;
    case FailureKind::kNonFiniteValue:
      return v1::ANALYSIS_FAILURE_NON_FINITE_VALUE;
    case FailureKind::kModelValidity:
      return v1::ANALYSIS_FAILURE_MODEL_VALIDITY;
    case FailureKind::kService:
      return v1::ANALYSIS_FAILURE_SERVICE;
    case FailureKind::kInjected:
      return v1::ANALYSIS_FAILURE_INJECTED;
    case FailureKind::kCancelled:
      return v1::ANALYSIS_FAILURE_CANCELLED;
    case FailureKind::kNone:
    case FailureKind::kUnclassified:
      return v1::ANALYSIS_FAILURE_KIND_UNSPECIFIED;
  }
  return v1::ANALYSIS_FAILURE_KIND_UNSPECIFIED;
}

FailureKind FailureKindFromProto(v1::AnalysisFailureKind kind) {
  switch (kind) {
    case v1::ANALYSIS_FAILURE_INVALID_MODEL:
      return FailureKind::kInvalidModel;
    case v1::ANALYSIS_FAILURE_ASSEMBLY:
      return FailureKind::kAssembly;
    case v1::ANALYSIS_FAILURE_INTEGRATOR:
      return FailureKind::kIntegrator;
    case v1::ANALYSIS_FAILURE_TIME_LIMIT:
      return FailureKind::kTimeLimit;
    case v1::ANALYSIS_FAILURE_NON_FINITE_VALUE:
      return FailureKind::kNonFiniteValue;
    case v1::ANALYSIS_FAILURE_MODEL_VALIDITY:
      return FailureKind::kModelValidity;
    case v1::ANALYSIS_FAILURE_SERVICE:
      return FailureKind::kService;
    case v1::ANALYSIS_FAILURE_INJECTED:
      return FailureKind::kInjected;
    case v1::ANALYSIS_FAILURE_CANCELLED:
      return FailureKind::kCancelled;
    default:
      return FailureKind::kUnclassified;
  }
}

void CountersToProto(const AnalysisCounters& counters, v1::AnalysisCountersProto* proto) {
  proto->set_time_steps(counters.time_steps);
  proto->set_rhs_evaluations(counters.rhs_evaluations);
  proto->set_jacobian_evaluations(counters.jacobian_evaluations);
  proto->set_newton_iterations(counters.newton_iterations);
  proto->set_position_solves(counters.position_solves);
  proto->set_wall_seconds(counters.wall_seconds);
}

AnalysisCounters CountersFromProto(const v1::AnalysisCountersProto& proto) {
  AnalysisCounters counters;
  counters.time_steps = proto.time_steps();
  counters.rhs_evaluations = proto.rhs_evaluations();
  counters.jacobian_evaluations = proto.jacobian_evaluations();
  counters.newton_iterations = proto.newton_iterations();
  counters.position_solves = proto.position_solves();
  counters.wall_seconds = proto.wall_seconds();
  return counters;
}

}  // namespace mbopt::spec::io
