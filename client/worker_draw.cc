#include "client/worker_draw.h"

#include <chrono>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/strip.h"
#include "client/local_cluster.h"
#include "client/subprocess.h"
#include "mbopt/v1/drawing.pb.h"
#include "spec/io/drawing_convert.h"

namespace mbopt::client {
namespace {

// A drawing follows the scene's own time limit; this only guards a hang.
constexpr std::chrono::minutes kDrawGuard{30};

}  // namespace

absl::StatusOr<std::string> FindWorkerProgram() {
  return FindMboptBinary("mbopt-worker", "MBOPT_WORKER_BIN", "worker/main");
}

absl::StatusOr<spec::SceneDrawing> RunWorkerDraw(const std::string& worker, const std::string& file,
                                                 const std::vector<std::string>& sets, const std::string& work_path,
                                                 const std::string& load_case) {
  std::vector<std::string> argv = {worker, "draw", file, "--out", work_path};
  if (!load_case.empty()) {
    argv.push_back("--case");
    argv.push_back(load_case);
  }
  for (const std::string& s : sets) {
    argv.push_back("--set");
    argv.push_back(s);
  }
  SpawnOptions options;
  options.capture_stdout = true;
  options.capture_stderr = true;
  absl::StatusOr<Subprocess> child = Subprocess::Start(argv, options);
  if (!child.ok()) return child.status();
  absl::StatusOr<Subprocess::Output> output = child->Communicate(kDrawGuard);
  if (!output.ok()) return output.status();
  v1::SceneDrawing message;
  std::ifstream in(work_path, std::ios::binary);
  // Exit 1 writes the drawing up to where the motion stopped; 2 writes none.
  if (output->exit_code > 1 || !in || !message.ParseFromIstream(&in)) {
    return absl::InvalidArgumentError(absl::StrCat(absl::StripSuffix(output->stderr_text, "\n"),
                                                   " (mbopt-worker draw, exit ", output->exit_code, ")"));
  }
  return spec::io::DrawingFromProto(message);
}

}  // namespace mbopt::client
