// An `external` model: the driver's name and its inputs.
#include "spec/io/scene_converter.h"

#include <algorithm>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "spec/io/declared_name.h"

namespace mbopt::spec::io {

ExternalModel SceneConverter::ConvertExternal(const v1::ExternalModel& m, const Where& w) {
  ExternalModel out;
  out.driver = m.driver();
  // The driver itself is the worker's to check (its declared parameters
  // are known only there); the name must at least be one a worker could
  // declare.
  if (m.driver().empty()) {
    errors_.Add(w, "driver", "missing: expected the name of an analysis driver a worker declares");
  } else if (!IsDriverName(m.driver())) {
    errors_.Add(w, "driver",
                absl::StrCat("\"", m.driver(), "\" is not a driver name: expected letters, digits, '_', '-' "
                             "and '.', not starting with '.', at most 100 characters"));
  }
  std::set<std::string> names;
  for (int i = 0; i < m.inputs_size(); ++i) {
    const v1::ExternalInput& in = m.inputs(i);
    const Where iw = w.Child("inputs", i);
    CheckDeclaredName(iw, in.name(), names.insert(in.name()).second,
                      {.missing = "an input needs the name of one of the driver's parameters", .duplicate = "input"}, &errors_);
    out.inputs.push_back({in.name(), Num(iw, "value", in.has_value(), in.value(), Dimension::kAny)});
  }
  return out;
}

bool SceneConverter::IsDriverName(const std::string& name) {
  if (name.empty() || name.size() > 100 || name[0] == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
           c == '.';
  });
}

}  // namespace mbopt::spec::io
