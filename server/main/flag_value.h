// The one rule of mbopt-server's command lines: an option takes its value
// after `=` or as the next argument.
#pragma once

#include <string>

namespace mbopt::server_main {

// Splits argv[*i] into `name` and `value`, advancing *i past a value taken
// from the next argument. false: the option has no value.
inline bool FlagValue(int argc, char** argv, int* i, std::string* name, std::string* value) {
  const std::string arg = argv[*i];
  const std::size_t eq = arg.find('=');
  if (eq != std::string::npos) {
    *name = arg.substr(0, eq);
    *value = arg.substr(eq + 1);
    return true;
  }
  *name = arg;
  if (*i + 1 >= argc) return false;
  *value = argv[++*i];
  return true;
}

}  // namespace mbopt::server_main
