// Command-line parsing for the `mbopt` subcommands: positional arguments,
// `--name value` / `--name=value` options and boolean `--flag`s. Unknown
// options are usage errors, named in the message.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::client {

struct ArgSpec {
  std::set<std::string> value_options;  // e.g. "--server", "--workers"
  std::set<std::string> flags;          // e.g. "--watch", "--json"
};

struct ParsedArgs {
  std::vector<std::string> positional;
  std::map<std::string, std::string> values;
  std::set<std::string> flags;

  bool Has(const std::string& flag) const { return flags.count(flag) > 0; }
  std::string Value(const std::string& option, const std::string& fallback = "") const;
  // InvalidArgument if present and not an integer >= `min`.
  absl::StatusOr<std::optional<int>> IntValue(const std::string& option, int min) const;
};

absl::StatusOr<ParsedArgs> ParseArgs(const std::vector<std::string>& args, const ArgSpec& spec);

}  // namespace mbopt::client
