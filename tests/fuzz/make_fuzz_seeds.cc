// Writes the seed corpora of the fuzzing targets from study files:
// OUT/study_text/NAME (the study with its scene inline, text format),
// OUT/study_binary/NAME (the same as a binary message) and
// OUT/scene_text/NAME (the scene alone), and OUT/packed_values/seed-K (the
// packings of PackedValuesSeeds), and OUT/result_intake/seed-K (the batches
// of ResultIntakeSeeds). Usage: make_fuzz_seeds OUT STUDY...
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include <google/protobuf/text_format.h>

#include "spec/io/study_io.h"
#include "tests/fuzz/fuzz_checks.h"
#include "tests/fuzz/result_intake_check.h"

namespace {

bool Write(const std::filesystem::path& path, const std::string& bytes) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  return static_cast<bool>(out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: make_fuzz_seeds OUT STUDY...\n";
    return 2;
  }
  const std::filesystem::path out = argv[1];
  for (int i = 2; i < argc; ++i) {
    absl::StatusOr<mbopt::v1::Study> study = mbopt::spec::io::ReadStudyProto(argv[i]);
    if (!study.ok()) {
      std::cerr << "make_fuzz_seeds: " << study.status().message() << "\n";
      return 1;
    }
    const std::string name = std::filesystem::path(argv[i]).filename().string();
    std::string study_text, scene_text;
    google::protobuf::TextFormat::PrintToString(*study, &study_text);
    google::protobuf::TextFormat::PrintToString(study->scene(), &scene_text);
    if (!Write(out / "study_text" / name, study_text) || !Write(out / "scene_text" / name, scene_text) ||
        !Write(out / "study_binary" / name, study->SerializeAsString())) {
      std::cerr << "make_fuzz_seeds: cannot write under " << out << "\n";
      return 1;
    }
  }
  for (const auto& [target, seeds] : {std::pair{"packed_values", mbopt::fuzz::PackedValuesSeeds()},
                                     std::pair{"result_intake", mbopt::fuzz::ResultIntakeSeeds()}}) {
    for (size_t k = 0; k < seeds.size(); ++k) {
      if (!Write(out / target / ("seed-" + std::to_string(k)), seeds[k])) {
        std::cerr << "make_fuzz_seeds: cannot write under " << out << "\n";
        return 1;
      }
    }
  }
  return 0;
}
