#include "tests/fuzz/fuzz_checks.h"

#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <string>

#include "absl/status/status.h"
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

}  // namespace mbopt::fuzz
