// An `fmu` model: the archive, its interface and the parameters set on it.
#include "spec/io/scene_converter.h"

#include <cmath>
#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spec/io/fmu_archive_contents.h"
#include "spec/limits.h"

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
  if (!m.archive().empty()) {
    // Read from the bytes here, never taken from the message: what the
    // server matches and what workers cache under is what the bytes hold.
    if (static_cast<std::int64_t>(m.archive().size()) > kMaxFmuArchiveBytes) {
      errors_.Add(w, "archive",
                  absl::StrCat(m.archive().size(), " bytes; an FMU a study carries may have ",
                               kMaxFmuArchiveBytes >> 20, " MiB at most"));
    } else if (absl::StatusOr<FmuArchiveContents> contents = ReadFmuArchiveContents(m.archive()); !contents.ok()) {
      errors_.Add(w, "archive", absl::StrCat("the bytes of ", out.path, ": ", contents.status().message()));
    } else if (contents->platforms.empty()) {
      errors_.Add(w, "archive",
                  absl::StrCat(out.path, " has no binaries (no binaries/<platform>/ folder holding a file): no "
                               "worker can load it"));
    } else {
      out.archive = std::make_shared<const std::string>(m.archive());
      out.archive_sha256 = contents->sha256;
      out.platforms = contents->platforms;
    }
  }
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
