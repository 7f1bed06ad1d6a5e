#include "client/record_cells.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"

namespace mbopt::client {

std::string CellValue(double v, const char* missing) {
  return std::isfinite(v) ? absl::StrFormat("%.7g", v) : std::string(missing);
}

double TrialPhysical(const v1::CycleRecord& r, int i) {
  return i < r.x_trial_physical_size() ? r.x_trial_physical(i) : std::numeric_limits<double>::quiet_NaN();
}

double ConstraintViolation(const v1::CycleRecord& r, int c) {
  return c < r.constraint_violations_size() ? r.constraint_violations(c) : std::numeric_limits<double>::quiet_NaN();
}

std::string AlignedRows(const std::vector<std::vector<std::string>>& rows) {
  std::vector<size_t> widths;
  for (const auto& row : rows) {
    if (widths.size() < row.size()) widths.resize(row.size(), 0);
    for (size_t k = 0; k < row.size(); ++k) widths[k] = std::max(widths[k], row[k].size());
  }
  std::string out;
  for (const auto& row : rows) {
    for (size_t k = 0; k < row.size(); ++k) {
      out += k + 1 == row.size() ? "  " + row[k] : absl::StrFormat("%*s ", static_cast<int>(widths[k]), row[k]);
    }
    out += '\n';
  }
  return out;
}

}  // namespace mbopt::client
