// One analysis as the server knows it: what a worker (or an in-process
// evaluator) reported, validated once at intake (Job::Intake), then logged to
// the job database and handed to the optimizer. A replay after a crash hands
// the optimizer the logged records again, so this is exactly what the
// optimizer saw. The one result type on the server's side: the wire message
// and the database row translate to and from it; the SLP core's own
// AnalysisResult is made from it in one place (Job).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spec/analysis_outcome.h"

namespace mbopt::jobs {

struct AnalysisRecord {
  std::int64_t request_id = 0;
  std::vector<double> x_scaled;    // the design point it was computed at
  spec::AnalysisFailure failure;   // ok, or the kind and the reason
  // When ok: one value per objective term and per constraint row (g_h, SI).
  std::vector<double> objective_terms;
  std::vector<double> constraint_values;
  // The same values as a worker packed them (common/packed_doubles), logged
  // verbatim so the server need not pack them again; both empty when the
  // values came unpacked (the store packs them then). A worker's report
  // carries only these; Job::Intake unpacks them into the vectors above.
  std::string objective_terms_packed;
  std::string constraint_values_packed;
  // Simulator sensitivities, when the request wanted them and they were
  // usable: d(value)/d(x_scaled), row-major (one row per objective term,
  // resp. constraint row; one column per design variable). Both empty: none,
  // and gradients_unavailable may say why.
  std::vector<double> objective_gradients;
  std::vector<double> constraint_gradients;
  std::string gradients_unavailable;
  std::string worker;              // worker id; "" for the server or an in-process run
  // The name of the token whose worker delivered it (per-worker tokens say
  // which machine); "" on a server without tokens and for the server's own.
  std::string holder;
  std::int32_t attempts = 1;       // attempts it took (leases given out)
  // From the task's queueing on the server to its result's arrival there
  // (real time, s); 0 where nothing was measured (in-process runs).
  double latency_seconds = 0;
  spec::AnalysisCounters counters; // wall_seconds: the analysis' own running time

  bool ok() const { return failure.ok(); }
};

}  // namespace mbopt::jobs
