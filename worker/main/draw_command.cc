#include "worker/main/draw_command.h"

#include <fstream>
#include <ostream>
#include <utility>

#include "absl/status/statusor.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/monotonic_clock.h"
#include "spec/io/drawing_convert.h"
#include "spec/io/study_io.h"
#include "worker/budget/analysis_budget.h"
#include "worker/engine/scene_drawing.h"
#include "worker/main/eval_command.h"

namespace mbopt::worker {
namespace {

const char kUsage[] =
    "usage: mbopt-worker draw FILE --out DRAWING [--case NAME] [--set NAME=VALUE ...]\n"
    "  Computes the drawing of a scene: FILE is a .scene.textproto (drawn at its\n"
    "  parameters' values) or a .study.textproto (its scene at the initial design).\n"
    "  Multibody, linkage and spatial scenes are drawn at every instant of their time\n"
    "  grid, lumped scenes as a schematic. Writes DRAWING (binary mbopt.v1.SceneDrawing,\n"
    "  proto/mbopt/v1/drawing.proto): what `mbopt draw` and `mbopt report` draw.\n"
    "  --out FILE        the drawing file (required)\n"
    "  --set NAME=VALUE  a design variable (scaled) or a scene parameter (its unit);\n"
    "                    repeatable\n"
    "  --case NAME       a study's load case: the scene with the parameters the case\n"
    "                    sets (without it, a study with load cases is drawn with\n"
    "                    its scene's own values)\n"
    "  exit status: 0 drawn, 1 drawn up to where the motion stopped (the file says\n"
    "  why), 2 bad input\n";

bool IsSceneFile(const std::string& path) {
  return absl::EndsWith(path, ".scene.textproto") || absl::EndsWith(path, ".scene.json") ||
         absl::EndsWith(path, ".scene.txtpb");
}

// The index of `name` among the study's load cases; -1 for no name. A name
// the study does not have (or a scene file, which has no cases) is refused
// with the names there are.
absl::StatusOr<int> FindLoadCase(const spec::Study& study, const std::string& path, const std::string& name) {
  if (name.empty()) return -1;
  std::vector<std::string> names;
  for (size_t c = 0; c < study.cases.size(); ++c) {
    if (study.cases[c].name == name) return static_cast<int>(c);
    names.push_back("\"" + study.cases[c].name + "\"");
  }
  if (names.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": --case \"", name, "\": this file has no load cases (only a study's `cases` have names)"));
  }
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": --case \"", name, "\" is not a load case of the study; its cases: ",
                   absl::StrJoin(names, ", ")));
}

}  // namespace

const char* DrawUsage() { return kUsage; }

int RunDraw(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string path, out_path, case_name;
  std::vector<std::string> sets;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      out << kUsage;
      return kExitOk;
    }
    if (a == "--out" || a == "--set" || a == "--case") {
      if (i + 1 >= args.size()) {
        err << "mbopt-worker draw: " << a << " needs a value\n" << kUsage;
        return kExitBadInput;
      }
      (a == "--out" ? out_path : a == "--case" ? case_name : sets.emplace_back()) = args[++i];
    } else if (a.rfind("--case=", 0) == 0) {
      case_name = a.substr(7);
    } else if (a.rfind("--set=", 0) == 0) {
      sets.push_back(a.substr(6));
    } else if (a.rfind("--out=", 0) == 0) {
      out_path = a.substr(6);
    } else if (!a.empty() && a[0] == '-') {
      err << "mbopt-worker draw: unknown option \"" << a << "\"\n" << kUsage;
      return kExitBadInput;
    } else if (path.empty()) {
      path = a;
    } else {
      err << "mbopt-worker draw: more than one file given\n" << kUsage;
      return kExitBadInput;
    }
  }
  if (path.empty() || out_path.empty()) {
    err << "mbopt-worker draw: " << (path.empty() ? "no scene or study file given" : "no --out file given") << "\n"
        << kUsage;
    return kExitBadInput;
  }
  spec::Study study;
  if (IsSceneFile(path)) {
    absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path);
    if (!scene.ok()) {
      err << scene.status().message() << "\n";
      return kExitBadInput;
    }
    study.scene = *std::move(scene);
  } else {
    absl::StatusOr<spec::Study> loaded = spec::io::LoadStudyFile(path);
    if (!loaded.ok()) {
      err << loaded.status().message() << "\n";
      return kExitBadInput;
    }
    study = *std::move(loaded);
  }
  absl::StatusOr<int> load_case = FindLoadCase(study, path, case_name);
  if (!load_case.ok()) {
    err << "mbopt-worker draw: " << load_case.status().message() << "\n";
    return kExitBadInput;
  }
  std::vector<double> x;
  for (const spec::DesignVariable& v : study.variables) x.push_back(v.initial);
  std::vector<std::pair<int, double>> overrides;
  for (const std::string& s : sets) {
    if (absl::Status st = ApplyDesignSet(study, s, &x, &overrides); !st.ok()) {
      err << "mbopt-worker draw: " << st.message() << "\n";
      return kExitBadInput;
    }
  }
  std::vector<double> parameters = study.ParameterValuesAt(x);
  // The case's values as its analyses have them; a parameter set on the
  // command line is the user's explicit choice and wins.
  if (*load_case >= 0) parameters = study.CaseParameterValues(*load_case, std::move(parameters));
  for (const auto& [p, value] : overrides) parameters[static_cast<size_t>(p)] = value;
  // On this process' clock: the scene's time limit applies as to an analysis.
  budget::AnalysisBudget budget =
      budget::AnalysisBudget(&MonotonicSeconds, nullptr)
          .ForAnalysis(study.scene.integrator.max_wall_seconds, study.scene.integrator.max_steps);
  absl::StatusOr<spec::SceneDrawing> drawing = engine::DrawScene(study.scene, parameters, &budget);
  if (!drawing.ok()) {
    err << "mbopt-worker draw: " << drawing.status().message() << "\n";
    return kExitBadInput;
  }
  std::ofstream file(out_path, std::ios::binary | std::ios::trunc);
  if (!file || !spec::io::DrawingToProto(*drawing).SerializeToOstream(&file) || !(file.close(), file)) {
    err << "mbopt-worker draw: cannot write " << out_path << "\n";
    return kExitBadInput;
  }
  if (!drawing->failure.empty()) {
    err << "mbopt-worker draw: " << study.scene.name << (case_name.empty() ? "" : " (load case " + case_name + ")")
        << ": " << drawing->failure << "\n";
    return kExitAnalysisFailed;
  }
  out << "drew " << study.scene.name << (case_name.empty() ? "" : " (load case " + case_name + ")") << " at "
      << drawing->times_s.size() << " instant" << (drawing->times_s.size() == 1 ? "" : "s") << " to " << out_path
      << "\n";
  return kExitOk;
}

}  // namespace mbopt::worker
