// An `fmu` model: the archive, its interface and the parameters set on it.
#include "spec/io/scene_converter.h"

#include <cmath>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace mbopt::spec::io {

FmuModel SceneConverter::ConvertFmu(const v1::FmuModel& m, const Where& w) {
  FmuModel out;
  out.path = m.path();
  if (out.path.empty()) errors_.Add(w, "path", "missing: expected the .fmu file, e.g. `path: \"model.fmu\"`");
  switch (m.interface()) {
    case v1::FMU_INTERFACE_UNSPECIFIED:
    case v1::FMU_MODEL_EXCHANGE:
      out.co_simulation = false;
      break;
    case v1::FMU_CO_SIMULATION:
      out.co_simulation = true;
      break;
    default:
      errors_.Add(w, "interface", "expected FMU_MODEL_EXCHANGE or FMU_CO_SIMULATION");
  }
  if (m.communication_step_s() < 0.0 || !std::isfinite(m.communication_step_s())) {
    errors_.Add(w, "communication_step_s",
                absl::StrFormat("must be > 0 s (0 for the FMU's default step), got %g", m.communication_step_s()));
  } else if (m.communication_step_s() > 0.0 && !out.co_simulation) {
    errors_.Add(w, "communication_step_s", "applies to `interface: FMU_CO_SIMULATION` only");
  }
  out.communication_step_s = m.communication_step_s();
  std::set<std::string> seen;
  for (int i = 0; i < m.parameters_size(); ++i) {
    const v1::FmuParameter& p = m.parameters(i);
    const Where pw = w.Child("parameters", i);
    if (p.variable().empty()) errors_.Add(pw, "variable", "missing: expected the FMU parameter's name");
    if (!seen.insert(p.variable()).second) {
      errors_.Add(pw, "variable", absl::StrCat("FMU parameter \"", p.variable(), "\" is set twice"));
    }
    out.parameters.push_back({p.variable(), Num(pw, "value", p.has_value(), p.value(), Dimension::kAny)});
  }
  return out;
}

}  // namespace mbopt::spec::io
