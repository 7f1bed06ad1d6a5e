// The one check of a name that a scene or study declares (a parameter, a
// body, a joint, an output, a design variable, ...): given, not reserved, and
// not declared before among its kind.
#pragma once

#include <initializer_list>
#include <string>

#include "spec/io/locator.h"

namespace mbopt::spec::io {

struct DeclaredName {
  // The error for an empty name, or one of `reserved`: what is expected
  // ("a body needs a name other than \"ground\"").
  const char* missing;
  // What the name is, in "duplicate <duplicate> \"<name>\"" ("body name").
  const char* duplicate;
  // Names that mean something else where this name is used ("ground").
  std::initializer_list<const char*> reserved = {};
};

// Adds the errors of `name`, declared at `w`'s field `name`, to `errors`.
// `is_new` is whether the caller's table of names of this kind took it
// (false: it was declared before).
void CheckDeclaredName(const Where& w, const std::string& name, bool is_new, const DeclaredName& rule,
                       Errors* errors);

}  // namespace mbopt::spec::io
