// The `mbopt` subcommands. Each takes its arguments (after the subcommand
// name), prints what the user asked for on stdout and errors on stderr, and
// returns the process exit code (exit_codes.h, docs/cli.md).
#pragma once

#include <string>
#include <vector>

namespace mbopt::client {

using Args = std::vector<std::string>;

int SubmitCommand(const Args& args);
int WatchCommand(const Args& args);
int StatusCommand(const Args& args);
int ListCommand(const Args& args);
// `mbopt workers`: the server's registered workers, their slots,
// capabilities (drivers, FMU platform) and analyses done.
int WorkersCommand(const Args& args);
int CancelCommand(const Args& args);
int ResumeCommand(const Args& args);
int ResultsCommand(const Args& args);
int ReportCommand(const Args& args);   // `mbopt report`: HTML page of a job
int RunCommandMain(const Args& args);  // `mbopt run`
int ValidateCommand(const Args& args);  // `mbopt validate`: a study checked offline
int DrawCommand(const Args& args);      // `mbopt draw`: HTML drawing of a scene

// Prints "mbopt: <message>" on stderr and returns `exit_code`.
int Fail(const std::string& message, int exit_code);

}  // namespace mbopt::client
