#include "worker/service/batch_log_line.h"

#include <algorithm>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace mbopt::worker {

std::string BatchLogLine(const v1::TaskResults& batch, std::int64_t delivered_in_all) {
  std::vector<std::string> jobs;
  int ok = 0;
  double analysis_s = 0.0;
  for (const v1::TaskResult& r : batch.results()) {
    if (std::find(jobs.begin(), jobs.end(), r.job_id()) == jobs.end()) jobs.push_back(r.job_id());
    if (r.ok()) ++ok;
    analysis_s += r.counters().wall_seconds();
  }
  const int n = batch.results_size();
  std::string outcome = absl::StrCat(ok, " ok");
  if (ok < n) absl::StrAppend(&outcome, ", ", n - ok, " failed");
  return absl::StrCat(absl::StrJoin(jobs, ", "), ": ", n, n == 1 ? " result" : " results", " delivered (", outcome,
                      "), ", absl::StrFormat("%.2f", analysis_s), " s of analysis; ", delivered_in_all, " in all");
}

}  // namespace mbopt::worker
