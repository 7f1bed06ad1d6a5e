// mbopt-worker: the analysis worker. Subcommands:
//   eval STUDY [--set NAME=VALUE ...] [--json]   one analysis, for debugging
//   serve --server ADDRESS [--slots N] [--name NAME]   work for a server
//   drivers FILE                                 check a drivers file
//   draw FILE --out DRAWING                      the drawing of a scene
//     (`mbopt-worker --server ADDRESS ...` is short for `serve`)
// Each subcommand lives in its own file; this file only dispatches.
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "common/version/version.h"
#include "worker/main/draw_command.h"
#include "worker/main/drivers_command.h"
#include "worker/main/eval_command.h"
#include "worker/service/serve_command.h"

namespace {

struct Subcommand {
  const char* name;
  const char* summary;
  int (*run)(const std::vector<std::string>& args);
};

int Eval(const std::vector<std::string>& args) {
  return mbopt::worker::RunEval(args, std::cout, std::cerr);
}

int Draw(const std::vector<std::string>& args) {
  return mbopt::worker::RunDraw(args, std::cout, std::cerr);
}

int Drivers(const std::vector<std::string>& args) {
  return mbopt::worker::RunDrivers(args, std::cout, std::cerr);
}

const Subcommand kSubcommands[] = {
    {"eval", "run one analysis of a study and print its values", &Eval},
    {"serve", "connect to a server and run its analyses", &mbopt::worker::ServeMain},
    {"drivers", "check a drivers file and list its drivers", &Drivers},
    {"draw", "write the drawing of a scene over its time grid", &Draw},
};

void PrintUsage(std::ostream& os) {
  os << "usage: mbopt-worker <subcommand> [arguments]   (--version: the build)\n\nsubcommands:\n";
  for (const Subcommand& s : kSubcommands) os << "  " << s.name << "  " << s.summary << "\n";
  os << "\n" << mbopt::worker::EvalUsage() << "\n" << mbopt::worker::ServeUsage() << "\n"
     << mbopt::worker::DriversUsage() << "\n" << mbopt::worker::DrawUsage();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    PrintUsage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? mbopt::worker::kExitBadInput : mbopt::worker::kExitOk;
  }
  if (std::strcmp(argv[1], "--version") == 0 || std::strcmp(argv[1], "version") == 0) {
    std::cout << mbopt::version::VersionText("mbopt-worker", {{"FMI", "2.0 (Model Exchange, Co-Simulation)"}});
    return mbopt::worker::kExitOk;
  }
  if (std::strncmp(argv[1], "--server", 8) == 0) {  // shorthand for `serve`
    return mbopt::worker::ServeMain(std::vector<std::string>(argv + 1, argv + argc));
  }
  const std::vector<std::string> args(argv + 2, argv + argc);
  for (const Subcommand& s : kSubcommands) {
    if (std::strcmp(argv[1], s.name) == 0) return s.run(args);
  }
  std::cerr << "mbopt-worker: unknown subcommand \"" << argv[1] << "\"\n\n";
  PrintUsage(std::cerr);
  return mbopt::worker::kExitBadInput;
}
