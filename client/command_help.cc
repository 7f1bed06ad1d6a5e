#include "client/command_help.h"

#include <cstring>

namespace mbopt::client {

namespace {

struct Help {
  const char* command;
  const char* text;
};

// Options every command that talks to a server takes.
constexpr char kServerOptions[] =
    "  --server HOST:PORT    the server (default $MBOPT_SERVER, else 127.0.0.1:50051)\n"
    "  --tls-ca FILE         the server's CA certificate (or $MBOPT_TLS_CA)\n"
    "  --token-file FILE     a file holding your token (or $MBOPT_TOKEN_FILE; never on the command line)\n"
    "  --tls-cert FILE, --tls-key FILE, --tls-server-name NAME\n"
    "                        a client certificate, and the name the server's certificate must carry\n";
constexpr char kDbOption[] = "  --db PATH             read a database `mbopt run` kept instead of asking a server\n";

constexpr Help kHelp[] = {
    {"run",
     "usage: mbopt run FILE [--workers N] [--db PATH | --discard-db] [--json | --quiet]\n"
     "                [--drivers FILE [--keep-runs]]\n"
     "\n"
     "Optimizes the study in FILE on this machine: starts a server on loopback and N workers,\n"
     "submits the study, prints the cycles as they finish and the result, then stops them.\n"
     "The job database is kept (its path is printed, with the command that writes its report).\n"
     "\n"
     "options:\n"
     "  --workers N           local worker processes (default: the number of cores)\n"
     "  --db PATH             the job database at PATH (default: $XDG_STATE_HOME/mbopt/runs/)\n"
     "  --discard-db          a temporary database, removed when run ends\n"
     "  --json                print only the result, as one JSON object\n"
     "  --quiet               print nothing but errors (the exit code tells the outcome)\n"
     "  --drivers FILE        the analysis drivers the workers offer (external scenes)\n"
     "  --keep-runs           with --drivers: keep every analysis folder\n"},
    {"validate",
     "usage: mbopt validate FILE\n"
     "\n"
     "Checks a study and its scene as a submission would, without a server, and prints the\n"
     "optimization problem's layout: variables, load cases, responses, objective, constraints.\n"
     "Exit 0 when valid, else 2 with each error's file, line, field and what was expected.\n"},
    {"submit",
     "usage: mbopt submit FILE [--watch] [--server HOST:PORT]\n"
     "\n"
     "Validates the study in FILE, sends it (with its scene) to the server and prints the job id.\n"
     "\n"
     "options:\n"
     "  --watch               then follow the job as `mbopt watch` does\n"},
    {"watch",
     "usage: mbopt watch JOB [--server HOST:PORT | --db PATH]\n"
     "\n"
     "Prints one line per LP solve of the job (cycles already done first) until the job ends,\n"
     "then its outcome. Ctrl-C stops watching; the job goes on.\n"},
    {"status",
     "usage: mbopt status JOB [--server HOST:PORT | --db PATH]\n"
     "\n"
     "The job's state, cycles, analyses, objective, largest constraint violation, wall time,\n"
     "message, failed analyses by kind, and the best design analysed.\n"},
    {"list",
     "usage: mbopt list [--server HOST:PORT | --db PATH]\n"
     "\n"
     "One line per job: id, study, state, cycles, analyses, objective, owner.\n"},
    {"workers",
     "usage: mbopt workers [--server HOST:PORT]\n"
     "\n"
     "One line per worker registered now: id, name, slots, analyses done, tasks held, time since\n"
     "last heard from, and what it can run (built-in scenes, declared drivers, FMU platform).\n"},
    {"cancel",
     "usage: mbopt cancel JOB [--server HOST:PORT]\n"
     "\n"
     "Stops a queued or running job; its tasks are withdrawn from the workers.\n"},
    {"resume",
     "usage: mbopt resume JOB [--server HOST:PORT | --db PATH [--workers N] [--drivers FILE [--keep-runs]]]\n"
     "\n"
     "Continues an interrupted or cancelled job from its last durable record; the result is bit\n"
     "for bit the one an uninterrupted run gives (a running job is left alone). With --db,\n"
     "starts a local server and N workers on that database; an external scene's job needs\n"
     "--drivers FILE (and --keep-runs) as `mbopt run` had them.\n"},
    {"results",
     "usage: mbopt results JOB [--csv | --json | --point K [--json]] [--server HOST:PORT | --db PATH]\n"
     "\n"
     "The job's result (outcome, objective, design) and its cycle history; for a sweep or sample\n"
     "its designs, for a Pareto front its points.\n"
     "\n"
     "options:\n"
     "  --csv                 the cycle history (designs, points) as CSV\n"
     "  --json                result and history as one JSON object\n"
     "  --point K             a Pareto front's point K (1-based) in full: level, objectives,\n"
     "                        design, every constraint\n"},
    {"report",
     "usage: mbopt report JOB [-o FILE] [--no-responses] [--no-mechanism] [--plot X:Y ...]\n"
     "                        [--deflection-scale K] [--server HOST:PORT | --db PATH]\n"
     "\n"
     "Writes a self-contained HTML page of the job: history plots, tables, the responses of the\n"
     "initial and final designs, the mechanism drawn at both.\n"
     "\n"
     "options:\n"
     "  -o, --output FILE     the page (default: JOB.html)\n"
     "  --no-responses        leave out the response plots (no analyses are run for them)\n"
     "  --plot X:Y            also plot output or response Y against X at both designs, besides\n"
     "                        the study's `plots`; repeatable\n"
     "  --no-mechanism        leave out the drawing of the mechanism (no motion is solved for it)\n"
     "  --deflection-scale K  draw the flexible links' deflection K times its size (default 1)\n"
     "  --point K             a Pareto front's page: mark point K as the chosen design and show it\n"},
    {"draw",
     "usage: mbopt draw FILE [-o OUT.html] [--case NAME] [--set NAME=VALUE ...] [--deflection-scale K]\n"
     "\n"
     "Writes a self-contained HTML page with the drawing of a scene (FILE a .scene.textproto) or\n"
     "of a study's scene at its initial design (once per load case, with the parameters each\n"
     "case sets, headed by its name): multibody, linkage and spatial scenes (these in four\n"
     "views) over their time grid, animated (slider and play button), lumped scenes as a\n"
     "schematic. No server is needed; the drawing is computed by mbopt-worker (found as for\n"
     "`mbopt report`).\n"
     "Exit 0 drawn, 4 drawn up to where the motion stopped (the page says why), 2 bad input.\n"
     "\n"
     "options:\n"
     "  -o, --output FILE     the page (default: FILE's name with .html, in this folder)\n"
     "  --case NAME           only the study's load case NAME\n"
     "  --set NAME=VALUE      a design variable (scaled) or a scene parameter (its unit); repeatable\n"
     "  --deflection-scale K  draw the flexible links' deflection K times its size (default 1:\n"
     "                        true to scale); the page says so\n"},
};

bool TalksToServer(std::string_view command) {
  return command != "run" && command != "validate" && command != "draw";
}
bool ReadsDatabases(std::string_view command) {
  return command == "watch" || command == "status" || command == "list" || command == "results" ||
         command == "report" || command == "resume";
}

}  // namespace

std::optional<std::string> CommandHelp(std::string_view command) {
  for (const Help& h : kHelp) {
    if (command != h.command) continue;
    std::string text = h.text;
    if (TalksToServer(command)) {
      text += "\nconnection options:\n";
      text += kServerOptions;
      if (ReadsDatabases(command)) text += kDbOption;
    }
    text += "\nmore: docs/cli.md\n";
    return text;
  }
  return std::nullopt;
}

bool AsksForHelp(int argc, const char* const* argv) {
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) return true;
  }
  return false;
}

}  // namespace mbopt::client
