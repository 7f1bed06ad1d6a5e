// mbopt: the command-line client of an mbopt server (see docs/cli.md).
#include <signal.h>

#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "client/command_help.h"
#include "client/commands.h"
#include "client/exit_codes.h"
#include "common/secure_channel/client_security.h"
#include "common/version/version.h"

namespace {

constexpr char kUsage[] =
    "usage: mbopt COMMAND [ARGS]\n"
    "\n"
    "commands:\n"
    "  run FILE [--workers N] [--db PATH | --discard-db] [--json] [--quiet]\n"
    "           [--drivers FILE [--keep-runs]]\n"
    "                        start a local server and N workers, optimize, print the result;\n"
    "                        keeps the job database (its path is printed) unless --discard-db\n"
    "  validate FILE         check a study and its scene offline; print its layout\n"
    "  draw FILE [-o OUT.html]\n"
    "                        draw a scene (or a study's scene), animated over its time grid\n"
    "  submit FILE [--watch] submit a study to a server; prints the job id\n"
    "  watch JOB             follow a job's cycles until it ends\n"
    "  status JOB            a job's state, objective and design\n"
    "  list                  all jobs on the server\n"
    "  workers               the server's registered workers: slots, drivers, analyses done\n"
    "  cancel JOB            stop a job\n"
    "  resume JOB [--db PATH [--workers N] [--drivers FILE]]\n"
    "                        continue an interrupted job\n"
    "  results JOB [--csv|--json]\n"
    "                        a job's result and cycle history\n"
    "  report JOB [-o FILE]  write a self-contained HTML page of the job's history\n"
    "                        (default FILE: JOB.html)\n"
    "\n"
    "`mbopt COMMAND --help` describes a command and its options; `mbopt --version` the build.\n"
    "every command but run, validate and draw takes --server HOST:PORT (default $MBOPT_SERVER,\n"
    "else 127.0.0.1:50051); watch, status, list, results, report and resume take\n"
    "--db PATH instead to read a database `mbopt run` kept.\n"
    "a server with TLS and tokens needs --tls-ca FILE and --token-file FILE (or\n"
    "$MBOPT_TLS_CA and $MBOPT_TOKEN_FILE); see docs/cli.md, \"Connecting securely\".\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace mbopt::client;
  // A closed output pipe (e.g. `mbopt run ... | head`) must not kill mbopt
  // before it has stopped its children and removed its temporary files.
  signal(SIGPIPE, SIG_IGN);
  mbopt::secure_channel::QuietGrpcLogUnlessAsked();
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? kExitBadInput : kExitOk;
  }
  if (std::strcmp(argv[1], "--version") == 0 || std::strcmp(argv[1], "version") == 0) {
    std::fputs(mbopt::version::VersionText("mbopt").c_str(), stdout);
    return kExitOk;
  }
  const std::string command = argv[1];
  if (AsksForHelp(argc - 2, argv + 2)) {
    if (const std::optional<std::string> help = CommandHelp(command)) {
      std::fputs(help->c_str(), stdout);
      return kExitOk;
    }
  }
  const Args args(argv + 2, argv + argc);
  if (command == "run") return RunCommandMain(args);
  if (command == "submit") return SubmitCommand(args);
  if (command == "watch") return WatchCommand(args);
  if (command == "status") return StatusCommand(args);
  if (command == "list") return ListCommand(args);
  if (command == "workers") return WorkersCommand(args);
  if (command == "cancel") return CancelCommand(args);
  if (command == "resume") return ResumeCommand(args);
  if (command == "results") return ResultsCommand(args);
  if (command == "report") return ReportCommand(args);
  if (command == "validate") return ValidateCommand(args);
  if (command == "draw") return DrawCommand(args);
  std::fprintf(stderr, "mbopt: unknown command '%s'\n\n%s", command.c_str(), kUsage);
  return kExitBadInput;
}
