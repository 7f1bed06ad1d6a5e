// `mbopt-worker draw`: the drawing of a scene (a scene file, or a study's
// scene at a design) written as a binary mbopt.v1.SceneDrawing
// (proto/mbopt/v1/drawing.proto) for `mbopt draw` and `mbopt report` to
// draw. Runs no analysis of the study: only the motion the drawing needs.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace mbopt::worker {

// `args` are the arguments after "draw"; exit codes as eval's
// (eval_command.h): 0 drawn (every instant), 1 drawn up to a failure of the
// motion (the file says why), 2 bad input.
int RunDraw(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

const char* DrawUsage();

}  // namespace mbopt::worker
