// `mbopt draw FILE [-o OUT.html] [--set NAME=VALUE ...]`: the drawing of a
// scene (or of a study's scene at its initial design) as a self-contained
// HTML page, animated over the time grid, to check a model before
// optimizing it. The worker program computes the drawing; this draws it.
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/report/mechanism_drawing.h"
#include "client/temp_dir.h"
#include "client/worker_draw.h"

namespace mbopt::client {
namespace {

constexpr char kDrawUsage[] = "usage: mbopt draw FILE [-o|--output OUT.html] [--set NAME=VALUE ...]";

// FILE's name without its folder and its .scene/.study suffix, + ".html".
std::string DefaultOutput(const std::string& file) {
  std::string name = file.substr(file.find_last_of('/') == std::string::npos ? 0 : file.find_last_of('/') + 1);
  for (const char* suffix : {".textproto", ".txtpb", ".json"}) {
    if (absl::EndsWith(name, suffix)) name.resize(name.size() - std::char_traits<char>::length(suffix));
  }
  return name + ".html";
}

}  // namespace

int DrawCommand(const Args& args) {
  std::string file, output;
  std::vector<std::string> sets;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "-o" || a == "--output" || a == "--set") {
      if (i + 1 >= args.size()) return Fail(a + " needs a value\n" + kDrawUsage, kExitBadInput);
      (a == "--set" ? sets.emplace_back() : output) = args[++i];
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
  if (output.empty()) output = DefaultOutput(file);
  absl::StatusOr<std::string> worker = FindWorkerProgram();
  if (!worker.ok()) return Fail(std::string(worker.status().message()), kExitBadInput);
  TempDir dir;
  absl::StatusOr<spec::SceneDrawing> drawing = RunWorkerDraw(*worker, file, sets, dir.path() + "/drawing.pb");
  if (!drawing.ok()) return Fail(std::string(drawing.status().message()), kExitBadInput);
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
