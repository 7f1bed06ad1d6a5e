#include "spec/io/parse_hints.h"

#include <array>
#include <string_view>

#include "absl/strings/str_cat.h"

namespace mbopt::spec::io {
namespace {

struct Hint {
  std::string_view when;  // a part of the parser's message
  std::string_view what_to_write;
};

constexpr std::string_view kMultibodyJoints =
    "a linkage's joints are all pins (name, position_m, ground); for a slider, a weld or a pin in a slot write the "
    "mechanism as a `multibody` scene, whose joints take `kind: JOINT_PRISMATIC`, `JOINT_FIXED` or "
    "`JOINT_POINT_ON_LINE` (docs/scene.md)";

// REDUCTION_EQUAL also catches REDUCTION_EQUALS and _EQUALITY.
constexpr std::array<Hint, 3> kHints = {{
    {"\"mbopt.v1.Joint\" has no field named \"type\"", kMultibodyJoints},
    {"\"mbopt.v1.Joint\" has no field named \"kind\"", kMultibodyJoints},
    {"value of \"REDUCTION_EQUAL",
     "to hold a value, write `equals: <value>` (and `tolerance: <half-width>`, or leave it out for 1e-4 of the "
     "value) with a reduction that gives one value: REDUCTION_FINAL, REDUCTION_MEAN, REDUCTION_RMS, "
     "REDUCTION_INTEGRAL or REDUCTION_RANGE (docs/study.md)"},
}};

}  // namespace

std::string WithParseHint(const std::string& message) {
  for (const Hint& hint : kHints) {
    if (message.find(hint.when) != std::string::npos) return absl::StrCat(message, " (", std::string(hint.what_to_write), ")");
  }
  return message;
}

}  // namespace mbopt::spec::io
