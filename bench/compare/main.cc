// mbopt_compare: runs each reference study with our SLP method and with
// NLopt's SLSQP and MMA on the same analyses, and writes the comparison as
// Markdown (docs/comparison.md). See docs/comparison.md for the protocol.
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "bench/compare/comparison_table.h"
#include "bench/compare/doc_text.h"
#include "bench/compare/nlopt_peer.h"
#include "bench/compare/slp_method.h"
#include "server/jobs/problem_from_study.h"
#include "spec/io/study_io.h"

namespace mbopt::compare {
namespace {

const char kUsage[] =
    "usage: mbopt_compare [--study FILE ...] [--out FILE] [--cap N]\n"
    "  Runs each study with the mbopt SLP method, NLopt SLSQP and NLopt MMA on the\n"
    "  same analyses and writes a Markdown comparison (default: stdout).\n"
    "  --study FILE  a .study.textproto (repeatable); default: the reference studies\n"
    "  --out FILE    write the Markdown here\n"
    "  --cap N       analyses allowed to each NLopt run (default 2000)\n"
    "  --scene-grid  run every study on its scene's own time grid, ignoring the\n"
    "                study's analysis.time_grid_points (the four-bars: the report's\n"
    "                101 instants instead of the 1001 their study files use)\n";

const std::vector<std::string> kDefaultStudies = {
    "examples/vehicle/vehicle.study.textproto",
    "examples/landing_gear/landing_gear.study.textproto",
    "examples/landing_gear/landing_gear_intermediate.study.textproto",
    "examples/fourbar/fourbar_rigid.study.textproto",
    "examples/fourbar/fourbar_elastic.study.textproto",
};

// Published values (METHOD.md section 4, docs of the benchmarks) for the reader.
const std::map<std::string, std::string> kReferenceNotes = {
    {"vehicle",
     "Published: 6.40 m/s^2 (1994 report), 6.46 (Haug & Arora); with exact sensitivities this model "
     "gives about 6.37."},
    {"landing_gear",
     "Published: 0.88 after 25 cycles (1994 report); F = 0 is reachable on a family of designs."},
    {"landing_gear_intermediate",
     "The landing gear with the report's intermediate responses: the largest weighted residual of the three "
     "targets, min-max over them (an L-infinity distance, 0 exactly where the report's Euclidean F is 0, and "
     "F <= sqrt(3) times it)."},
    {"fourbar_rigid", "Rigid-link model: optimum near 2.34 kg (benchmark notes)."},
    {"fourbar_elastic", "Published: 2.36 kg (1994 report, elastic links), 2.69 kg (Sohoni & Haug)."},
};

// With `scene_grid`, without the study's time-grid override: NLopt's MMA
// treats every constraint row as its own constraint, and its dual
// subproblem over the 32 000 rows of a 1001-point four-bar grid takes
// minutes per iteration; the comparison is about the optimizers, so all
// methods share the report's grid instead.
absl::StatusOr<spec::Study> LoadStudy(const std::string& path, bool scene_grid) {
  if (!scene_grid) return spec::io::LoadStudyFile(path);
  absl::StatusOr<v1::Study> message = spec::io::ReadStudyProto(path);
  if (!message.ok()) return message.status();
  if (message->has_analysis()) message->mutable_analysis()->clear_time_grid_points();
  return spec::io::StudyFromProto(*message, path);
}

int Main(int argc, char** argv) {
  std::vector<std::string> studies;
  std::string out_path;
  PeerOptions peer;
  bool scene_grid = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--study" && i + 1 < argc) {
      studies.push_back(argv[++i]);
    } else if (a == "--out" && i + 1 < argc) {
      out_path = argv[++i];
    } else if (a == "--scene-grid") {
      scene_grid = true;
    } else if (a == "--cap" && i + 1 < argc) {
      peer.max_analyses = std::atoll(argv[++i]);
    } else {
      std::cerr << kUsage;
      return 2;
    }
  }
  if (studies.empty()) studies = kDefaultStudies;
  std::vector<std::string> command(argv, argv + argc);
  command[0] = "mbopt_compare";

  const TargetRule rule;
  std::string body;
  std::string summary =
      "| study | method | analyses to target | final F | final max violation | total analyses | wall [s] |\n"
      "|---|---|---:|---:|---:|---:|---:|\n";
  for (const std::string& path : studies) {
    absl::StatusOr<spec::Study> study = LoadStudy(path, scene_grid);
    if (!study.ok()) {
      std::cerr << study.status() << "\n";
      return 2;
    }
    absl::StatusOr<slp::SlpOptions> fd = jobs::SlpOptionsFromStudy(*study);
    if (!fd.ok()) {
      std::cerr << fd.status() << "\n";
      return 2;
    }
    std::vector<MethodRun> runs;
    std::cerr << study->name << ": mbopt SLP ...\n";
    absl::StatusOr<MethodRun> slp_run = RunSlpMethod(*study);
    if (!slp_run.ok()) {
      std::cerr << slp_run.status() << "\n";
      return 1;
    }
    runs.push_back(*slp_run);
    for (const PeerAlgorithm algorithm : {PeerAlgorithm::kSlsqp, PeerAlgorithm::kMma}) {
      std::cerr << study->name << ": " << PeerAlgorithmName(algorithm) << " ...\n";
      absl::StatusOr<MethodRun> r = RunNloptPeer(*study, algorithm, *fd, peer);
      if (!r.ok()) {
        std::cerr << r.status() << "\n";
        return 1;
      }
      runs.push_back(*r);
    }
    const auto note = kReferenceNotes.find(study->name);
    const StudyComparison c = Compare(study->name, note == kReferenceNotes.end() ? "" : note->second,
                                      std::move(runs), rule);
    absl::StrAppend(&body, ComparisonMarkdown(c, rule), "\n", Verdict(c, rule), "\n\n");
    for (const MethodRun& r : c.runs) {
      const auto reach = AnalysesToTarget(r, c, rule);
      absl::StrAppend(&summary, "| ", c.study, " | ", r.method, " | ",
                      reach.has_value() ? absl::StrCat(*reach) : "not reached", " | ",
                      absl::StrFormat("%.5g | %.2g | %d | %.1f |\n", r.final_objective,
                                      r.final_max_violation, r.analyses, r.wall_seconds));
    }
    std::cerr << ComparisonMarkdown(c, rule) << "\n";
  }

  std::string doc = absl::StrCat(
      "# mbopt SLP side by side with NLopt SLSQP and MMA\n\n"
      "Generated by\n\n```\n", absl::StrJoin(command, " "),
      "\n```\n\n"
      "run from the repository root on the build of deploy/build.sh (RelWithDebInfo, in build/). Nothing in this file is edited by hand.\n\n");
  absl::StrAppend(&doc, kProtocol, "\n## Summary\n\n", summary, "\n## Per study\n\n", body,
                  kDiscussion);
  if (out_path.empty()) {
    std::cout << doc;
  } else {
    std::ofstream f(out_path);
    f << doc;
    if (!f) {
      std::cerr << "cannot write " << out_path << "\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace
}  // namespace mbopt::compare

int main(int argc, char** argv) { return mbopt::compare::Main(argc, argv); }
