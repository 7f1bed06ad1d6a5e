#include "client/report/svg_line_plot.h"

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

constexpr double kMarginLeftPx = 78.0;
constexpr double kMarginRightPx = 220.0;  // legend column
constexpr double kMarginTopPx = 30.0;
constexpr double kMarginBottomPx = 46.0;
constexpr double kLegendRowPx = 18.0;
// Half the width of the bar that marks a limit at one instant.
constexpr double kInstantBarHalfPx = 9.0;
// What fits the legend column at the legend's font size.
constexpr std::size_t kLegendMaxChars = 24;

struct Frame {
  double left, right, top, bottom;  // plot area in px
  PlotAxis x;
  PlotAxis y;

  double Px(double fraction) const { return left + fraction * (right - left); }
  double Py(double fraction) const { return bottom - fraction * (bottom - top); }
};

std::string C(double v) { return FormatCoordinate(v); }

std::string Attr(const std::string& text) { return EscapeHtml(text); }

bool UsableForRange(double x, double y, bool log_y) {
  return std::isfinite(x) && std::isfinite(y) && (!log_y || y > 0);
}

void AppendLine(std::string& out, double x1, double y1, double x2, double y2,
                const std::string& style_attrs) {
  out += "<line x1=\"" + C(x1) + "\" y1=\"" + C(y1) + "\" x2=\"" + C(x2) + "\" y2=\"" + C(y2) +
         "\" " + style_attrs + "/>\n";
}

void AppendText(std::string& out, double x, double y, const std::string& anchor,
                const std::string& text, const std::string& extra = "") {
  out += "<text x=\"" + C(x) + "\" y=\"" + C(y) + "\" text-anchor=\"" + anchor + "\"" +
         (extra.empty() ? "" : " " + extra) + ">" + EscapeHtml(text) + "</text>\n";
}

void AppendMarker(std::string& out, MarkerShape shape, double r, const std::string& color,
                  double px, double py) {
  if (shape == MarkerShape::kNone) return;
  const bool hollow = shape == MarkerShape::kHollowCircle;
  out += "<circle cx=\"" + C(px) + "\" cy=\"" + C(py) + "\" r=\"" + C(r) + "\" fill=\"" +
         (hollow ? std::string("white") : Attr(color)) + "\" stroke=\"" + Attr(color) +
         "\" stroke-width=\"" + (hollow ? "1.6" : "1") + "\"/>\n";
}

// A downward triangle with its tip on the bottom edge: a value <= 0 on a log
// axis.
void AppendFloorMarker(std::string& out, const std::string& color, double px, double bottom) {
  out += "<polygon points=\"" + C(px - 4) + "," + C(bottom - 7) + " " + C(px + 4) + "," +
         C(bottom - 7) + " " + C(px) + "," + C(bottom) + "\" fill=\"white\" stroke=\"" +
         Attr(color) + "\" stroke-width=\"1.4\"/>\n";
}

void AppendSeries(std::string& out, const PlotSeries& s, const Frame& f, bool& any_floor) {
  const std::size_t n = std::min(s.x.size(), s.y.size());
  std::vector<std::pair<double, double>> segment;
  auto flush = [&]() {
    if (s.draw_line && segment.size() >= 2) {
      out += "<polyline fill=\"none\" stroke=\"" + Attr(s.color) + "\" stroke-width=\"1.8\"";
      if (!s.dash.empty()) out += " stroke-dasharray=\"" + Attr(s.dash) + "\"";
      out += " points=\"";
      for (std::size_t k = 0; k < segment.size(); ++k) {
        if (k > 0) out += ' ';
        out += C(segment[k].first) + "," + C(segment[k].second);
      }
      out += "\"/>\n";
    }
    segment.clear();
  };
  std::vector<std::pair<double, double>> markers;
  std::vector<double> floor_markers;
  std::string labels;
  for (std::size_t i = 0; i < n; ++i) {
    const double fx = f.x.Fraction(s.x[i]);
    const double fy = f.y.Fraction(s.y[i]);
    if (std::isfinite(fx) && std::isfinite(fy)) {
      const std::pair<double, double> p{f.Px(fx), f.Py(fy)};
      segment.push_back(p);
      markers.push_back(p);
      if (i < s.point_labels.size() && !s.point_labels[i].empty()) {
        AppendText(labels, p.first + s.marker_radius_px + 2, p.second - s.marker_radius_px - 2, "start",
                   s.point_labels[i], "class=\"point-label\"");
      }
      continue;
    }
    flush();
    if (std::isfinite(fx) && f.y.kind == AxisKind::kLog && std::isfinite(s.y[i]) && s.y[i] <= 0) {
      floor_markers.push_back(f.Px(fx));
    }
  }
  flush();
  for (const auto& [px, py] : markers) AppendMarker(out, s.marker, s.marker_radius_px, s.color, px, py);
  out += labels;
  for (double px : floor_markers) AppendFloorMarker(out, s.color, px, f.bottom);
  if (!floor_markers.empty()) any_floor = true;
}

// The first `max_chars` characters of UTF-8 `text` (never splitting one).
std::string TruncateUtf8(const std::string& text, std::size_t max_chars) {
  std::size_t chars = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if ((byte & 0xC0) != 0x80) {
      if (chars == max_chars) return text.substr(0, i);
      ++chars;
    }
  }
  return text;
}

bool InLegend(const PlotSeries& s) { return s.in_legend && !s.x.empty() && !s.y.empty(); }

void AppendLegend(std::string& out, const PlotSpec& spec, const Frame& f) {
  double y = f.top + 6;
  const double x = f.right + 16;
  for (const PlotSeries& s : spec.series) {
    if (!InLegend(s)) continue;
    if (s.draw_line) {
      std::string style = "stroke=\"" + Attr(s.color) + "\" stroke-width=\"1.8\"";
      if (!s.dash.empty()) style += " stroke-dasharray=\"" + Attr(s.dash) + "\"";
      AppendLine(out, x, y, x + 26, y, style);
    }
    AppendMarker(out, s.marker, s.marker_radius_px, s.color, x + 13, y);
    const std::string shown = TruncateUtf8(s.name, kLegendMaxChars);
    if (shown.size() == s.name.size()) {
      AppendText(out, x + 34, y + 4, "start", s.name, "class=\"legend\"");
    } else {
      // Cut to fit the legend column; the full name shows on hover.
      out += "<text x=\"" + C(x + 34) + "\" y=\"" + C(y + 4) + "\" text-anchor=\"start\" class=\"legend\">" +
             "<title>" + EscapeHtml(s.name) + "</title>" + EscapeHtml(shown + "\u2026") + "</text>\n";
    }
    y += kLegendRowPx;
  }
}

}  // namespace

std::string RenderLinePlotSvg(const PlotSpec& spec) {
  // Ranges from the drawable data (and the reference lines that ask for it).
  bool log_y = spec.log_y;
  if (log_y) {
    bool any_positive = false;
    for (const PlotSeries& s : spec.series) {
      for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
        any_positive = any_positive || UsableForRange(s.x[i], s.y[i], true);
      }
    }
    log_y = any_positive;
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double x_lo = kInf, x_hi = -kInf, y_lo = kInf, y_hi = -kInf;
  for (const PlotSeries& s : spec.series) {
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        // Points on the floor of a log axis still need their x.
        x_lo = std::min(x_lo, s.x[i]);
        x_hi = std::max(x_hi, s.x[i]);
      }
      if (UsableForRange(s.x[i], s.y[i], log_y)) {
        y_lo = std::min(y_lo, s.y[i]);
        y_hi = std::max(y_hi, s.y[i]);
      }
    }
  }
  const bool has_data = x_lo <= x_hi;
  if (has_data) {
    for (const ReferenceLine& r : spec.reference_lines) {
      if (r.extend_range && std::isfinite(r.y) && (!log_y || r.y > 0)) {
        y_lo = std::min(y_lo, r.y);
        y_hi = std::max(y_hi, r.y);
      }
    }
  }

  int legend_rows = 0;
  for (const PlotSeries& s : spec.series) legend_rows += InLegend(s) ? 1 : 0;
  const double width = spec.width_px;
  const double height = std::max(spec.height_px, kMarginTopPx + kMarginBottomPx + 12 +
                                                      legend_rows * kLegendRowPx);
  Frame f{kMarginLeftPx, width - kMarginRightPx, kMarginTopPx, height - kMarginBottomPx, {}, {}};

  std::string out;
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"plot\" width=\"" + C(width) +
         "\" height=\"" + C(height) + "\" viewBox=\"0 0 " + C(width) + " " + C(height) +
         "\" role=\"img\" aria-label=\"" + Attr(spec.title) + "\">\n";
  out += "<title>" + EscapeHtml(spec.title) + "</title>\n";
  AppendText(out, f.left, 18, "start", spec.title, "class=\"plot-title\"");
  out += "<rect x=\"" + C(f.left) + "\" y=\"" + C(f.top) + "\" width=\"" + C(f.right - f.left) +
         "\" height=\"" + C(f.bottom - f.top) + "\" fill=\"white\" stroke=\"#444444\"/>\n";

  if (!has_data) {
    AppendText(out, (f.left + f.right) / 2, (f.top + f.bottom) / 2, "middle", "no data to plot",
               "class=\"no-data\"");
    out += "</svg>\n";
    return out;
  }
  // has_data means a point with finite x and y, so y_lo <= y_hi here: on a
  // log axis one of them is > 0 (else log_y was dropped above).
  f.x = MakeLinearAxis(x_lo, x_hi, 8, spec.x_min_step);
  f.y = log_y ? MakeLogAxis(y_lo, y_hi) : MakeLinearAxis(y_lo, y_hi, 6);

  // Grid and ticks.
  for (const AxisTick& t : f.x.ticks) {
    const double px = f.Px(f.x.Fraction(t.value));
    AppendLine(out, px, f.top, px, f.bottom, "stroke=\"#e4e4e4\"");
    AppendLine(out, px, f.bottom, px, f.bottom + 5, "stroke=\"#444444\"");
    AppendText(out, px, f.bottom + 18, "middle", t.label, "class=\"tick\"");
  }
  for (const AxisTick& t : f.y.ticks) {
    const double py = f.Py(f.y.Fraction(t.value));
    AppendLine(out, f.left, py, f.right, py, "stroke=\"#e4e4e4\"");
    AppendLine(out, f.left - 5, py, f.left, py, "stroke=\"#444444\"");
    AppendText(out, f.left - 8, py + 4, "end", t.label, "class=\"tick\"");
  }
  AppendText(out, (f.left + f.right) / 2, height - 8, "middle", spec.x_label, "class=\"axis-label\"");
  const double label_x = 16, label_y = (f.top + f.bottom) / 2;
  AppendText(out, label_x, label_y, "middle", spec.y_label + (log_y ? " (log scale)" : ""),
             "class=\"axis-label\" transform=\"rotate(-90 " + C(label_x) + " " + C(label_y) + ")\"");

  for (const ReferenceLine& r : spec.reference_lines) {
    const double fy = f.y.Fraction(r.y);
    if (!std::isfinite(fy) || fy < -1e-9 || fy > 1 + 1e-9) continue;
    const double py = f.Py(fy);
    // The span within the axis: a limit over a window is drawn over it only.
    const double from = std::max(0.0, std::isfinite(r.x_from) ? f.x.Fraction(r.x_from) : 0.0);
    const double to = std::min(1.0, std::isfinite(r.x_to) ? f.x.Fraction(r.x_to) : 1.0);
    if (!(from <= to + 1e-9)) continue;  // outside the axis (or NaN)
    const double px_from = f.Px(from), px_to = f.Px(to);
    const std::string color = "stroke=\"" + Attr(r.color) + "\"";
    double label_right = px_to, label_left = px_from;
    if (r.x_from == r.x_to) {
      // One instant: a bar wide enough to see and a diamond on the value.
      AppendLine(out, px_from - kInstantBarHalfPx, py, px_from + kInstantBarHalfPx, py, color + " stroke-width=\"2\"");
      out += "<polygon points=\"" + C(px_from - 4) + "," + C(py) + " " + C(px_from) + "," + C(py - 4) + " " +
             C(px_from + 4) + "," + C(py) + " " + C(px_from) + "," + C(py + 4) + "\" fill=\"" + Attr(r.color) +
             "\"/>\n";
      label_right = px_from + kInstantBarHalfPx;
      label_left = px_from - kInstantBarHalfPx;
    } else {
      AppendLine(out, px_from, py, px_to, py, color + " stroke-width=\"1.2\" stroke-dasharray=\"6 4\"");
    }
    // The label sits inside the plot: at the span's right end, or left of
    // its left end when the span reaches the right edge and label_left is
    // asked for (close lines).
    if (r.label_left) {
      AppendText(out, label_left + 4, r.label_below ? py + 11 : py - 4, "start", r.label, "class=\"ref-label\"");
    } else {
      const bool room_right = label_right + 4 + 6.0 * static_cast<double>(r.label.size()) < f.right;
      AppendText(out, room_right && label_right < f.right - 4 ? label_right + 4 : label_right - 4,
                 r.label_below ? py + 11 : py - 4, room_right && label_right < f.right - 4 ? "start" : "end",
                 r.label, "class=\"ref-label\"");
    }
  }

  bool any_floor = false;
  for (const PlotSeries& s : spec.series) AppendSeries(out, s, f, any_floor);
  if (any_floor) {
    AppendText(out, f.right + 16, f.bottom - 4, "start",
               "\u25BD on the bottom edge: value \u2264 0", "class=\"note\"");
  }
  AppendLegend(out, spec, f);
  out += "</svg>\n";
  return out;
}

}  // namespace mbopt::report
