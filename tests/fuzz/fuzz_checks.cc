#include "tests/fuzz/fuzz_checks.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <cstdlib>
#include <iostream>
#include <string>

#include "absl/status/status.h"
#include "common/packed_doubles/packed_doubles.h"
#include "mbopt/v1/study.pb.h"
#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "spec/limits.h"

namespace mbopt::fuzz {
namespace {

constexpr char kStudyName[] = "fuzz.study.textproto";
constexpr char kSceneName[] = "fuzz.scene.textproto";

[[noreturn]] void Fail(const std::string& what, const absl::Status& status) {
  std::cerr << "fuzz check failed: " << what << ": " << status << std::endl;
  std::abort();
}

// A refusal must be InvalidArgument and name the source it came from.
void ExpectRefusal(const absl::Status& status, const std::string& source, const std::string& what) {
  if (status.code() != absl::StatusCode::kInvalidArgument) Fail(what + ": not InvalidArgument", status);
  if (std::string(status.message()).find(source) == std::string::npos) Fail(what + ": does not name " + source, status);
}

// A legitimate study near the limits (a million instants) takes seconds and
// gigabytes to lay out, the more so under the sanitizers: that is allowed
// work, not a finding, so it is only estimated here. Over the limit the
// layout must refuse before it allocates, which is cheap and checked.
constexpr std::int64_t kLargestLayoutBuilt = std::int64_t{64} << 20;

void CheckLayout(const spec::Study& study, const std::string& source) {
  const spec::StudyFootprint footprint = spec::EstimateStudyFootprint(study);
  if (footprint.memory_bytes > kLargestLayoutBuilt && footprint.memory_bytes <= spec::kMaxStudyMemoryBytes) return;
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  if (!layout.ok()) {
    ExpectRefusal(layout.status(), source, "layout");
  } else if (footprint.memory_bytes > spec::kMaxStudyMemoryBytes) {
    Fail("a study over the memory limit was laid out", absl::OkStatus());
  }
}

}  // namespace

void CheckStudyText(std::string_view data) {
  const std::string text(data);
  absl::StatusOr<v1::Study> message = spec::io::ParseStudyText(text, kStudyName);
  if (!message.ok()) {
    ExpectRefusal(message.status(), kStudyName, "study text");
    return;
  }
  // What the client sends is what the server decodes: it must accept it too.
  v1::Study sent;
  if (!sent.ParseFromString(message->SerializeAsString())) Fail("the inlined study does not round-trip", {});
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(sent, kStudyName);
  if (!study.ok()) Fail("the file path accepted a study the server's path refuses", study.status());
  CheckLayout(*study, kStudyName);
}

void CheckSceneText(std::string_view data) {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(std::string(data), kSceneName);
  if (!scene.ok()) ExpectRefusal(scene.status(), kSceneName, "scene text");
}

void CheckStudyBinary(std::string_view data) {
  v1::Study message;
  if (!message.ParseFromString(std::string(data))) return;  // gRPC refuses it before the server sees it
  const std::string source = "submitted study";
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(message, source);
  if (!study.ok()) {
    ExpectRefusal(study.status(), source, "study message");
    return;
  }
  CheckLayout(*study, source);
}

void CheckPackedValues(std::string_view data) {
  // The bound the server passes is the study's own count of rows.
  constexpr std::size_t kBound = std::size_t{1} << 20;
  absl::StatusOr<std::vector<double>> values = packed::UnpackDoubles(data, kBound);
  if (!values.ok()) {
    if (values.status().code() != absl::StatusCode::kInvalidArgument) Fail("packed values: not InvalidArgument", values.status());
    return;
  }
  if (values->size() > kBound) Fail("packed values: more values than the bound", absl::OkStatus());
  absl::StatusOr<std::vector<double>> again = packed::UnpackDoubles(packed::PackDoubles(*values), kBound);
  if (!again.ok()) Fail("packed values: a repacking does not unpack", again.status());
  if (again->size() != values->size() ||
      (!values->empty() && std::memcmp(again->data(), values->data(), values->size() * sizeof(double)) != 0)) {
    Fail("packed values: a repacking unpacks to other values", absl::OkStatus());
  }
}

std::vector<std::string> PackedValuesSeeds() {
  std::vector<std::vector<double>> sets(4);
  for (int i = 0; i < 3001; ++i) {
    const double f = 0.02 * std::sin(0.01 * i) * std::exp(-1e-3 * i);
    sets[0].push_back(f);
    sets[0].push_back(-f);
  }
  std::uint64_t state = 88172645463325252ull;  // xorshift: the same seeds everywhere
  for (int i = 0; i < 2000; ++i) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    sets[1].push_back(std::bit_cast<double>(state));
  }
  sets[2] = {0.0, -0.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN(),
             std::numeric_limits<double>::denorm_min(), -1.0, 1.0};
  std::vector<std::string> seeds;
  for (const auto& set : sets) seeds.push_back(packed::PackDoubles(set));
  return seeds;
}

}  // namespace mbopt::fuzz
