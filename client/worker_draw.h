// Runs `mbopt-worker draw` (the worker program computes a scene's drawing;
// the client only draws it) and reads the drawing it writes back: what
// `mbopt draw` and the report's "Mechanism" section share.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/scene_drawing.h"

namespace mbopt::client {

// The worker program as `mbopt report` finds it ($MBOPT_WORKER_BIN, beside
// this program, or in the build tree).
absl::StatusOr<std::string> FindWorkerProgram();

// The drawing of `file` (a scene or a study) with the `--set NAME=VALUE`
// assignments, of the study's load case `load_case` when not empty (the
// scene with the parameters the case sets); the file goes through
// `work_path`. A motion that stops
// early is no error (SceneDrawing::failure says where and why); a scene
// without a drawing or a bad file is, with the worker's message.
absl::StatusOr<spec::SceneDrawing> RunWorkerDraw(const std::string& worker, const std::string& file,
                                                 const std::vector<std::string>& sets, const std::string& work_path,
                                                 const std::string& load_case = "");

}  // namespace mbopt::client
