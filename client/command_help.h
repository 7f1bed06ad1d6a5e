// `mbopt COMMAND --help`: what each command does, its arguments and
// options, in a few lines (docs/cli.md has the whole story).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace mbopt::client {

// The help of `command`, or none for an unknown command.
std::optional<std::string> CommandHelp(std::string_view command);

// Whether the arguments after the command ask for its help (--help, -h).
bool AsksForHelp(int argc, const char* const* argv);

}  // namespace mbopt::client
