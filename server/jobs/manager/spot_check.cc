#include "server/jobs/manager/spot_check.h"

#include <cstring>

namespace mbopt::jobs::manager {
namespace {

// SplitMix64's finalizer: every input bit moves every output bit.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

bool SameBits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

}  // namespace

bool SpotChecked(std::string_view job_id, std::int64_t request_id, double fraction) {
  if (fraction <= 0) return false;
  if (fraction >= 1) return true;
  // FNV-1a of the id, then mixed with the request id: fixed across
  // platforms and builds, unlike std::hash.
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : job_id) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ULL;
  h = Mix(h ^ Mix(static_cast<std::uint64_t>(request_id)));
  const double uniform = static_cast<double>(h >> 11) * 0x1.0p-53;
  return uniform < fraction;
}

bool SameAnswer(const AnalysisRecord& a, const AnalysisRecord& b) {
  return a.failure.kind == b.failure.kind && SameBits(a.objective_terms, b.objective_terms) &&
         SameBits(a.constraint_values, b.constraint_values) && SameBits(a.objective_gradients, b.objective_gradients) &&
         SameBits(a.constraint_gradients, b.constraint_gradients);
}

}  // namespace mbopt::jobs::manager
