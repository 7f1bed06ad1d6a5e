// Replays through the fuzzing targets' checks, in the ordinary build: every
// example study (as the seeds are made), every input kept under
// tests/fuzz/regressions/<target>/ (each a finding of a fuzzer, now fixed),
// and deterministic mutations of the examples. A check that fails aborts
// the test binary, which fails the test.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/fuzz/fuzz_checks.h"
#include "tests/fuzz/mutate.h"
#include "tests/fuzz/result_intake_check.h"

namespace mbopt::fuzz {
namespace {

std::vector<std::string> ExampleStudies() {
  std::vector<std::string> paths;
  for (const auto& dir : std::filesystem::directory_iterator("examples")) {
    if (!dir.is_directory()) continue;
    for (const auto& file : std::filesystem::directory_iterator(dir.path())) {
      const std::string name = file.path().filename().string();
      if (name.size() > 16 && name.substr(name.size() - 16) == ".study.textproto") paths.push_back(file.path());
    }
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

std::string InlinedText(const std::string& path, v1::Study* study) {
  absl::StatusOr<v1::Study> read = spec::io::ReadStudyProto(path);
  EXPECT_TRUE(read.ok()) << read.status();
  if (!read.ok()) return "";
  *study = *read;
  std::string text;
  google::protobuf::TextFormat::PrintToString(*read, &text);
  return text;
}

std::string ReadAll(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

TEST(FuzzSeeds, EveryExampleStudyPassesEveryCheck) {
  const std::vector<std::string> studies = ExampleStudies();
  ASSERT_GE(studies.size(), 8u) << "the examples directory was not found from " << std::filesystem::current_path();
  for (const std::string& path : studies) {
    v1::Study study;
    const std::string text = InlinedText(path, &study);
    ASSERT_FALSE(text.empty()) << path;
    CheckStudyText(text);
    CheckStudyBinary(study.SerializeAsString());
    std::string scene;
    google::protobuf::TextFormat::PrintToString(study.scene(), &scene);
    CheckSceneText(scene);
    // The seed is accepted by the text path itself, not only "handled".
    EXPECT_TRUE(spec::io::ParseStudyText(text, "seed.study.textproto").ok()) << path;
  }
}

// The packed_values seeds pass, and so does every single-byte change of
// them and every truncation (refused or unpacked, never a crash).
TEST(FuzzSeeds, PackedValuesSeedsAndTheirMutantsAreHandled) {
  const std::vector<std::string> seeds = PackedValuesSeeds();
  ASSERT_EQ(seeds.size(), 4u);
  for (const std::string& seed : seeds) {
    CheckPackedValues(seed);
    for (size_t at = 0; at < seed.size(); at += 7) {
      std::string mutant = seed;
      mutant[at] = static_cast<char>(mutant[at] ^ 0xA5);
      CheckPackedValues(mutant);
      CheckPackedValues(std::string_view(seed).substr(0, at));
    }
  }
}

// The result_intake seeds pass, and so do their single-byte changes and
// truncations (a third of them, spread over each seed).
TEST(FuzzSeeds, ResultIntakeSeedsAndTheirMutantsAreHandled) {
  const std::vector<std::string> seeds = ResultIntakeSeeds();
  ASSERT_EQ(seeds.size(), 3u);
  int checked = 0;
  for (const std::string& seed : seeds) {
    CheckResultIntake(seed);
    for (size_t at = 1; at < seed.size(); at += 23) {
      std::string mutant = seed;
      mutant[at] = static_cast<char>(mutant[at] ^ 0x5A);
      CheckResultIntake(mutant);
      CheckResultIntake(std::string_view(seed).substr(0, at));
      checked += 2;
    }
  }
  EXPECT_GT(checked, 20);
}

TEST(FuzzRegressions, EveryKeptFindingIsHandled) {
  const std::filesystem::path root = "tests/fuzz/regressions";
  ASSERT_TRUE(std::filesystem::is_directory(root));
  int replayed = 0;
  for (const auto& [target, check] : std::vector<std::pair<std::string, void (*)(std::string_view)>>{
           {"study_text", &CheckStudyText},
           {"scene_text", &CheckSceneText},
           {"study_binary", &CheckStudyBinary},
           {"packed_values", &CheckPackedValues},
           {"result_intake", &CheckResultIntake}}) {
    if (!std::filesystem::is_directory(root / target)) continue;
    for (const auto& file : std::filesystem::directory_iterator(root / target)) {
      SCOPED_TRACE(file.path().string());
      check(ReadAll(file.path()));
      ++replayed;
    }
  }
  EXPECT_GT(replayed, 0);
}

// The property: whatever a user does to an example file, the file path and
// the server's path agree on it (CheckStudyText aborts when they do not),
// and nothing crashes. 60 mutants of each example.
TEST(FuzzMutations, MutatedExamplesAreAcceptedOrRefusedAlikeOnEveryPath) {
  int refused = 0, accepted = 0;
  std::uint32_t seed = 1;
  for (const std::string& path : ExampleStudies()) {
    v1::Study study;
    const std::string text = InlinedText(path, &study);
    ASSERT_FALSE(text.empty()) << path;
    for (const std::string& mutant : MutateStudyText(text, 60, seed++)) {
      CheckStudyText(mutant);
      (spec::io::ParseStudyText(mutant, "m.study.textproto").ok() ? accepted : refused) += 1;
    }
  }
  // Both outcomes occur: the mutations reach the validation, not only the parser.
  EXPECT_GT(refused, 0);
  EXPECT_GT(accepted, 0);
}

}  // namespace
}  // namespace mbopt::fuzz
