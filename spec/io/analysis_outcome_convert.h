// spec/analysis_outcome.h <-> mbopt.v1 wire messages: the failure kind and
// the counters of one analysis, translated in one place for the worker
// (which sends them) and the server (which receives them).
#pragma once

#include "mbopt/v1/service.pb.h"
#include "spec/analysis_outcome.h"

namespace mbopt::spec::io {

v1::AnalysisFailureKind FailureKindToProto(FailureKind kind);
// A failed result without a kind (a worker that predates failure kinds) is
// kUnclassified; kNone never comes from a failed result.
FailureKind FailureKindFromProto(v1::AnalysisFailureKind kind);

void CountersToProto(const AnalysisCounters& counters, v1::AnalysisCountersProto* proto);
AnalysisCounters CountersFromProto(const v1::AnalysisCountersProto& proto);

}  // namespace mbopt::spec::io
