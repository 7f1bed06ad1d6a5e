#include "client/args.h"

#include <cerrno>
#include <cstdlib>

#include "absl/status/status.h"

namespace mbopt::client {

std::string ParsedArgs::Value(const std::string& option, const std::string& fallback) const {
  auto it = values.find(option);
  return it == values.end() ? fallback : it->second;
}

absl::StatusOr<std::optional<int>> ParsedArgs::IntValue(const std::string& option,
                                                        int min) const {
  auto it = values.find(option);
  if (it == values.end()) return std::optional<int>();
  const std::string& text = it->second;
  char* end = nullptr;
  errno = 0;
  long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < min || v > 1000000) {
    return absl::InvalidArgumentError(option + " expects an integer >= " + std::to_string(min) +
                                      ", got '" + text + "'");
  }
  return std::optional<int>(static_cast<int>(v));
}

absl::StatusOr<ParsedArgs> ParseArgs(const std::vector<std::string>& args, const ArgSpec& spec) {
  ParsedArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() < 2 || a.compare(0, 2, "--") != 0 || a == "--") {
      out.positional.push_back(a);
      continue;
    }
    std::string name = a, value;
    bool has_inline_value = false;
    if (auto eq = a.find('='); eq != std::string::npos) {
      name = a.substr(0, eq);
      value = a.substr(eq + 1);
      has_inline_value = true;
    }
    if (spec.flags.count(name)) {
      if (has_inline_value) return absl::InvalidArgumentError(name + " takes no value");
      out.flags.insert(name);
    } else if (spec.value_options.count(name)) {
      if (!has_inline_value) {
        if (i + 1 >= args.size()) return absl::InvalidArgumentError(name + " needs a value");
        value = args[++i];
      }
      out.values[name] = value;
    } else {
      return absl::InvalidArgumentError("unknown option " + name);
    }
  }
  return out;
}

}  // namespace mbopt::client
