#include "client/report/scalar_bars.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "client/report/html_escape.h"
#include "client/report/number_format.h"
#include "client/report/plot_axis.h"

namespace mbopt::report {
namespace {

constexpr double kWidthPx = 1000.0;
constexpr double kLeftPx = 130.0;   // room for the bar names
constexpr double kRightPx = 220.0;  // room for a value label past the longest bar
constexpr double kTopPx = 34.0;
constexpr double kBarPx = 22.0;
constexpr double kBarGapPx = 12.0;
constexpr double kBottomPx = 58.0;  // ticks, limit labels, axis label

std::string C(double v) { return FormatCoordinate(v); }

double LastValue(const std::vector<double>& values) {
  return values.empty() ? std::numeric_limits<double>::quiet_NaN() : values.back();
}

void Text(std::string& out, double x, double y, const char* anchor, const std::string& text, const char* cls) {
  out += "<text x=\"" + C(x) + "\" y=\"" + C(y) + "\" text-anchor=\"" + anchor + "\" class=\"" + cls + "\">" +
         EscapeHtml(text) + "</text>\n";
}

}  // namespace

std::string RenderScalarBarsSvg(const ResponsePlot& plot) {
  struct Bar {
    const char* name;
    const char* color;
    double value;
  };
  const Bar bars[] = {{"initial design", "#7f7f7f", LastValue(plot.initial)},
                      {plot.final_label.c_str(), "#1f77b4", LastValue(plot.final)}};
  // Bars start at 0, so 0 is always on the axis.
  double lo = 0.0, hi = 0.0;
  for (const Bar& b : bars) {
    if (std::isfinite(b.value)) lo = std::min(lo, b.value), hi = std::max(hi, b.value);
  }
  for (const ResponsePlot::Limit& l : plot.limits) {
    if (std::isfinite(l.value)) lo = std::min(lo, l.value), hi = std::max(hi, l.value);
  }
  const PlotAxis axis = MakeLinearAxis(lo, hi, 6);
  const double plot_right = kWidthPx - kRightPx;
  const double bottom = kTopPx + 2 * kBarPx + 3 * kBarGapPx;
  const double height = bottom + kBottomPx;
  auto px = [&](double v) { return kLeftPx + axis.Fraction(v) * (plot_right - kLeftPx); };
  const std::string unit = plot.unit.empty() ? std::string() : " " + plot.unit;

  std::string out = "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot scalar-bars\" width=\"" + C(kWidthPx) +
                    "\" height=\"" + C(height) + "\" viewBox=\"0 0 " + C(kWidthPx) + " " + C(height) +
                    "\" role=\"img\" aria-label=\"" + EscapeHtml(plot.title) + "\">\n";
  out += "<title>" + EscapeHtml(plot.title) + "</title>\n";
  Text(out, kLeftPx, 18, "start", plot.title, "plot-title");
  for (const AxisTick& t : axis.ticks) {
    const double x = px(t.value);
    out += "<line x1=\"" + C(x) + "\" y1=\"" + C(kTopPx) + "\" x2=\"" + C(x) + "\" y2=\"" + C(bottom) +
           "\" stroke=\"#e4e4e4\"/>\n";
    Text(out, x, bottom + 16, "middle", t.label, "tick");
  }
  Text(out, (kLeftPx + plot_right) / 2, height - 6, "middle",
       plot.unit.empty() ? "value (SI)" : "value [" + plot.unit + "]", "axis-label");
  const double zero = px(0.0);
  double y = kTopPx + kBarGapPx;
  for (const Bar& b : bars) {
    Text(out, kLeftPx - 8, y + kBarPx / 2 + 4, "end", b.name, "legend");
    if (std::isfinite(b.value)) {
      const double end = px(b.value);
      out += "<rect x=\"" + C(std::min(zero, end)) + "\" y=\"" + C(y) + "\" width=\"" + C(std::abs(end - zero)) +
             "\" height=\"" + C(kBarPx) + "\" fill=\"" + b.color + "\"/>\n";
      Text(out, std::max(zero, end) + 6, y + kBarPx / 2 + 4, "start", FormatValue(b.value) + unit, "legend");
    } else {
      Text(out, zero + 6, y + kBarPx / 2 + 4, "start", "no value", "no-data");
    }
    y += kBarPx + kBarGapPx;
  }
  out += "<line x1=\"" + C(zero) + "\" y1=\"" + C(kTopPx) + "\" x2=\"" + C(zero) + "\" y2=\"" + C(bottom) +
         "\" stroke=\"#444444\"/>\n";
  for (const ResponsePlot::Limit& l : plot.limits) {
    if (!std::isfinite(l.value)) continue;
    const double x = px(l.value);
    out += "<line x1=\"" + C(x) + "\" y1=\"" + C(kTopPx - 4) + "\" x2=\"" + C(x) + "\" y2=\"" + C(bottom) +
           "\" stroke=\"#d62728\" stroke-width=\"1.4\" stroke-dasharray=\"6 4\"/>\n";
    Text(out, x, bottom + 30, "middle", l.label + " " + FormatValue(l.value) + unit, "ref-label");
  }
  out += "</svg>\n";
  return out;
}

}  // namespace mbopt::report
