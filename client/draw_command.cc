// `mbopt draw FILE [-o OUT.html] [--case NAME] [--set NAME=VALUE ...]
// [--deflection-scale K]`: the
// drawing of a scene (or of a study's scene at its initial design, once per
// load case) as a self-contained HTML page, animated over the time grid, to
// check a model before optimizing it. The worker program computes the
// drawing; this draws it (its flexible links' deflection magnified K times
// if asked: the drawing file itself stays true to scale).
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/report/deflection_scale.h"
#include "client/report/load_case_drawings.h"
#include "client/report/mechanism_drawing.h"
#include "client/temp_dir.h"
#include "client/worker_draw.h"
#include "spec/io/study_io.h"

namespace mbopt::client {
namespace {

constexpr char kDrawUsage[] =
    "usage: mbopt draw FILE [-o|--output OUT.html] [--case NAME] [--set NAME=VALUE ...] [--deflection-scale K]";

// FILE's name without its folder and its .scene/.study suffix, + ".html".
std::string DefaultOutput(const std::string& file) {
  std::string name = file.substr(file.find_last_of('/') == std::string::npos ? 0 : file.find_last_of('/') + 1);
  for (const char* suffix : {".textproto", ".txtpb", ".json"}) {
    if (absl::EndsWith(name, suffix)) name.resize(name.size() - std::char_traits<char>::length(suffix));
  }
  return name + ".html";
}

bool IsSceneFile(const std::string& path) {
  for (const char* suffix : {".scene.textproto", ".scene.txtpb", ".scene.json"}) {
    if (absl::EndsWith(path, suffix)) return true;
  }
  return false;
}

// One page with a figure per load case; exit as for one drawing, a motion
// that stops in any case making it kExitJobFailed.
int DrawLoadCases(const std::string& worker, const std::string& file, const std::vector<std::string>& sets,
                  const std::vector<std::string>& cases, const std::string& study_name, const std::string& output,
                  double deflection_scale, const TempDir& dir) {
  std::vector<report::CaseDrawing> drawn;
  for (size_t k = 0; k < cases.size(); ++k) {
    absl::StatusOr<spec::SceneDrawing> drawing =
        RunWorkerDraw(worker, file, sets, dir.path() + "/case-" + std::to_string(k) + ".pb", cases[k]);
    if (!drawing.ok()) return Fail(std::string(drawing.status().message()), kExitBadInput);
    drawn.push_back(report::CaseDrawing{cases[k], report::MagnifyDeflection(*std::move(drawing), deflection_scale)});
  }
  std::ofstream out(output, std::ios::binary | std::ios::trunc);
  out << report::LoadCaseDrawingsPageHtml(drawn, study_name.empty() ? drawn.front().drawing.scene_name : study_name,
                                          file);
  out.close();
  if (!out) return Fail("cannot write the drawing to " + output, kExitBadInput);
  bool stopped = false;
  for (const report::CaseDrawing& c : drawn) {
    if (c.drawing.failure.empty()) continue;
    stopped = true;
    std::fprintf(stderr, "mbopt draw: %s (load case %s): %s\n", c.drawing.scene_name.c_str(), c.load_case.c_str(),
                 c.drawing.failure.c_str());
  }
  std::printf("wrote %s (%zu load case%s:", output.c_str(), drawn.size(), drawn.size() == 1 ? "" : "s");
  for (const report::CaseDrawing& c : drawn) {
    std::printf(" %s %zu instant%s%s", c.load_case.c_str(), c.drawing.times_s.size(),
                c.drawing.times_s.size() == 1 ? "" : "s", &c == &drawn.back() ? "" : ",");
  }
  std::printf(")\n");
  return stopped ? kExitJobFailed : kExitOk;
}

}  // namespace

int DrawCommand(const Args& args) {
  std::string file, output, only_case, scale_text;
  std::vector<std::string> sets;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--deflection-scale") {
      if (i + 1 >= args.size()) return Fail(a + " needs a value\n" + kDrawUsage, kExitBadInput);
      scale_text = args[++i];
    } else if (a.rfind("--deflection-scale=", 0) == 0) {
      scale_text = a.substr(19);
    } else if (a == "-o" || a == "--output" || a == "--set" || a == "--case") {
      if (i + 1 >= args.size()) return Fail(a + " needs a value\n" + kDrawUsage, kExitBadInput);
      (a == "--set" ? sets.emplace_back() : a == "--case" ? only_case : output) = args[++i];
    } else if (a.rfind("--case=", 0) == 0) {
      only_case = a.substr(7);
    } else if (a.rfind("--output=", 0) == 0) {
      output = a.substr(9);
    } else if (a.rfind("--set=", 0) == 0) {
      sets.push_back(a.substr(6));
    } else if (!a.empty() && a[0] == '-') {
      return Fail("unknown option \"" + a + "\"\n" + kDrawUsage, kExitBadInput);
    } else if (file.empty()) {
      file = a;
    } else {
      return Fail("more than one file given\n" + std::string(kDrawUsage), kExitBadInput);
    }
  }
  if (file.empty()) return Fail(std::string("no scene or study file given\n") + kDrawUsage, kExitBadInput);
  double deflection_scale = 1.0;
  if (!scale_text.empty() && !report::ParseDeflectionScale(scale_text, &deflection_scale)) {
    return Fail("--deflection-scale needs a positive number, not \"" + scale_text + "\"\n" + kDrawUsage,
                kExitBadInput);
  }
  if (output.empty()) output = DefaultOutput(file);
  absl::StatusOr<std::string> worker = FindWorkerProgram();
  if (!worker.ok()) return Fail(std::string(worker.status().message()), kExitBadInput);
  TempDir dir;
  // A study with load cases is drawn once per case (or the one --case
  // names); the worker checks the name and says which cases there are.
  std::vector<std::string> cases;
  std::string study_name;
  if (!IsSceneFile(file)) {
    // A file that does not load is left to the worker, which says why.
    if (absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(file); study.ok()) {
      for (const spec::LoadCase& c : study->cases) cases.push_back(c.name);
      study_name = study->name;
    }
  }
  if (!only_case.empty()) cases = {only_case};
  if (!cases.empty()) return DrawLoadCases(*worker, file, sets, cases, study_name, output, deflection_scale, dir);
  absl::StatusOr<spec::SceneDrawing> drawing = RunWorkerDraw(*worker, file, sets, dir.path() + "/drawing.pb");
  if (!drawing.ok()) return Fail(std::string(drawing.status().message()), kExitBadInput);
  *drawing = report::MagnifyDeflection(*std::move(drawing), deflection_scale);
  std::ofstream out(output, std::ios::binary | std::ios::trunc);
  out << report::SceneDrawingPageHtml(*drawing, file);
  out.close();
  if (!out) return Fail("cannot write the drawing to " + output, kExitBadInput);
  if (!drawing->failure.empty()) {
    std::fprintf(stderr, "mbopt draw: %s: %s\n", drawing->scene_name.c_str(), drawing->failure.c_str());
  }
  std::printf("wrote %s (%zu instant%s)\n", output.c_str(), drawing->times_s.size(),
              drawing->times_s.size() == 1 ? "" : "s");
  return drawing->failure.empty() ? kExitOk : kExitJobFailed;
}

}  // namespace mbopt::client
