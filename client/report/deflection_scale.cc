#include "client/report/deflection_scale.h"

#include <charconv>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "client/report/number_format.h"

namespace mbopt::report {

spec::SceneDrawing MagnifyDeflection(spec::SceneDrawing d, double scale) {
  if (scale == 1.0 || d.lines.empty()) return d;
  for (std::vector<spec::DrawingPosition>& at : d.points_m) {
    // Chords from the drawn positions, not from points already moved (a
    // point two lines share).
    const std::vector<spec::DrawingPosition> drawn = at;
    for (const spec::SceneDrawing::Line& line : d.lines) {
      const size_t n = line.points.size() - 1;
      if (line.points.size() < 3) continue;
      const spec::DrawingPosition& a = drawn[static_cast<size_t>(line.points.front())];
      const spec::DrawingPosition& b = drawn[static_cast<size_t>(line.points.back())];
      for (size_t k = 1; k < n; ++k) {
        const double f = static_cast<double>(k) / static_cast<double>(n);
        const spec::DrawingPosition& p = drawn[static_cast<size_t>(line.points[k])];
        const double cx = a.x_m + (b.x_m - a.x_m) * f, cy = a.y_m + (b.y_m - a.y_m) * f,
                     cz = a.z_m + (b.z_m - a.z_m) * f;
        at[static_cast<size_t>(line.points[k])] =
            spec::DrawingPosition{cx + scale * (p.x_m - cx), cy + scale * (p.y_m - cy), cz + scale * (p.z_m - cz)};
      }
    }
  }
  const std::string said = "the flexible links' deflection is drawn " + FormatValue(scale, 6) +
                           " times its size (--deflection-scale): each centre line's offset from the straight line "
                           "between its ends, magnified";
  d.note = d.note.empty() ? said : d.note + "; " + said;
  return d;
}

bool ParseDeflectionScale(const std::string& text, double* scale) {
  double value = 0.0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (error != std::errc() || stop != end || !std::isfinite(value) || !(value > 0.0)) return false;
  *scale = value;
  return true;
}

}  // namespace mbopt::report
