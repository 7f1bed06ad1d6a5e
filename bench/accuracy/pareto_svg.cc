#include "bench/accuracy/pareto_svg.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace mbopt::accuracy {
namespace {

constexpr double kWidth = 720, kHeight = 480;
constexpr double kLeft = 80, kRight = 200, kTop = 40, kBottom = 60;

std::string Escape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '&') out += "&amp;";
    else out += c;
  }
  return out;
}

// Text extent at font-size 10 in the generic sans-serif font, generous.
constexpr double kLabelCharWidth = 6.0, kLabelHeight = 10.0;

struct LabelBox {
  double left = 0, top = 0, right = 0, bottom = 0;
  bool Overlaps(const LabelBox& o) const {
    return left < o.right && o.left < right && top < o.bottom && o.top < bottom;
  }
};

struct LogAxis {
  double lo_decade = 0, hi_decade = 1;  // log10 range, whole decades
  double Fraction(double v) const { return (std::log10(v) - lo_decade) / (hi_decade - lo_decade); }
};

LogAxis AxisFor(double lo, double hi) {
  LogAxis a;
  a.lo_decade = std::floor(std::log10(lo));
  a.hi_decade = std::ceil(std::log10(hi));
  if (a.hi_decade <= a.lo_decade) a.hi_decade = a.lo_decade + 1;
  return a;
}

std::string DecadeLabel(int d) {
  if (d >= 0 && d <= 2) return absl::StrFormat("%g", std::pow(10.0, d));
  if (d < 0 && d >= -2) return absl::StrFormat("%g", std::pow(10.0, d));
  return absl::StrFormat("1e%d", d);
}

}  // namespace

std::vector<int> ParetoFront(const std::vector<PlotPoint>& points) {
  std::vector<int> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (points[a].wall_seconds != points[b].wall_seconds) return points[a].wall_seconds < points[b].wall_seconds;
    return points[a].error < points[b].error;
  });
  std::vector<int> front;
  double best_error = INFINITY;
  for (const int i : order) {
    if (points[i].error < best_error) {
      front.push_back(i);
      best_error = points[i].error;
    }
  }
  return front;
}

std::string ParetoSvg(const std::string& title, const std::vector<PlotPoint>& points,
                      double error_floor) {
  double t_lo = INFINITY, t_hi = 0, e_hi = error_floor * 10;
  for (const PlotPoint& p : points) {
    t_lo = std::min(t_lo, p.wall_seconds);
    t_hi = std::max(t_hi, p.wall_seconds);
    e_hi = std::max(e_hi, p.error);
  }
  if (!(t_lo > 0)) t_lo = 1e-3;
  if (!(t_hi > t_lo)) t_hi = t_lo * 10;
  const LogAxis xa = AxisFor(t_lo, t_hi);
  const LogAxis ya = AxisFor(error_floor, e_hi);
  const double pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  auto X = [&](double t) { return kLeft + pw * xa.Fraction(t); };
  auto Y = [&](double e) { return kTop + ph * (1 - ya.Fraction(std::max(e, error_floor))); };

  std::string s = absl::StrFormat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" viewBox=\"0 0 %g %g\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n"
      "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
      "<text x=\"%g\" y=\"22\" font-size=\"15\" text-anchor=\"middle\">%s</text>\n",
      kWidth, kHeight, kWidth, kHeight, kLeft + pw / 2, Escape(title));
  // Grid and decade ticks.
  for (int d = static_cast<int>(xa.lo_decade); d <= static_cast<int>(xa.hi_decade); ++d) {
    const double x = X(std::pow(10.0, d));
    absl::StrAppendFormat(&s,
                          "<line x1=\"%.1f\" y1=\"%g\" x2=\"%.1f\" y2=\"%g\" stroke=\"#ddd\"/>\n"
                          "<text x=\"%.1f\" y=\"%g\" text-anchor=\"middle\">%s</text>\n",
                          x, kTop, x, kTop + ph, x, kTop + ph + 18, DecadeLabel(d));
  }
  for (int d = static_cast<int>(ya.lo_decade); d <= static_cast<int>(ya.hi_decade); ++d) {
    const double y = Y(std::pow(10.0, d));
    absl::StrAppendFormat(&s,
                          "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                          "<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\">%s</text>\n",
                          kLeft, y, kLeft + pw, y, kLeft - 6, y + 4, DecadeLabel(d));
  }
  absl::StrAppendFormat(&s,
                        "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n"
                        "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">wall time of the optimization [s]</text>\n"
                        "<text transform=\"translate(18 %g) rotate(-90)\" text-anchor=\"middle\">"
                        "relative objective error vs reference (floor %.0e)</text>\n",
                        kLeft, kTop, pw, ph, kLeft + pw / 2, kHeight - 14, kTop + ph / 2, error_floor);
  // The front as a staircase (each point dominates to its right).
  const std::vector<int> front = ParetoFront(points);
  if (!front.empty()) {
    std::string path;
    for (size_t k = 0; k < front.size(); ++k) {
      const PlotPoint& p = points[front[k]];
      if (k == 0) {
        absl::StrAppendFormat(&path, "M %.1f %.1f", X(p.wall_seconds), Y(p.error));
      } else {
        absl::StrAppendFormat(&path, " H %.1f V %.1f", X(p.wall_seconds), Y(p.error));
      }
    }
    absl::StrAppendFormat(&path, " H %g", kLeft + pw);
    absl::StrAppend(&s, "<path d=\"", path, "\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" stroke-dasharray=\"5 3\"/>\n");
  }
  std::vector<bool> on_front(points.size(), false);
  for (const int i : front) on_front[i] = true;
  for (size_t i = 0; i < points.size(); ++i) {
    const PlotPoint& p = points[i];
    const double x = X(p.wall_seconds), y = Y(p.error);
    const char* fill = p.violated ? "white" : (on_front[i] ? "#1f77b4" : "#888");
    const char* stroke = p.violated ? "#d62728" : (on_front[i] ? "#1f77b4" : "#888");
    if (p.is_default) {
      absl::StrAppendFormat(&s, "<rect x=\"%.1f\" y=\"%.1f\" width=\"10\" height=\"10\" fill=\"%s\" stroke=\"%s\" stroke-width=\"2\"/>\n",
                            x - 5, y - 5, fill, stroke);
    } else {
      absl::StrAppendFormat(&s, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4.5\" fill=\"%s\" stroke=\"%s\" stroke-width=\"1.5\"/>\n",
                            x, y, fill, stroke);
    }
  }
  // Labels after the markers, the front, the default and violated points
  // first; a label that would overlap one already placed (settings with the
  // same error and similar times crowd into a row) tries the other corners
  // of its point and is left out if none is free: the table lists them all.
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    auto rank = [&](size_t i) { return on_front[i] || points[i].is_default || points[i].violated ? 0 : 1; };
    return rank(a) < rank(b);
  });
  std::vector<LabelBox> placed;
  for (const size_t i : order) {
    const PlotPoint& p = points[i];
    const double x = X(p.wall_seconds), y = Y(p.error);
    const double w = kLabelCharWidth * static_cast<double>(p.label.size());
    // Baseline positions: right above, right below, left above, left below.
    const double corners[4][3] = {{x + 7, y - 5, 0}, {x + 7, y + 13, 0}, {x - 7 - w, y - 5, 1}, {x - 7 - w, y + 13, 1}};
    for (const auto& c : corners) {
      const LabelBox box{c[0], c[1] - kLabelHeight, c[0] + w, c[1] + 2};
      if (box.left < kLeft || box.right > kLeft + pw || box.top < kTop) continue;
      if (std::any_of(placed.begin(), placed.end(), [&](const LabelBox& o) { return box.Overlaps(o); })) continue;
      placed.push_back(box);
      absl::StrAppendFormat(&s, "<text x=\"%.1f\" y=\"%.1f\" font-size=\"10\" fill=\"#333\">%s</text>\n",
                            c[0], c[1], Escape(p.label));
      break;
    }
  }
  // Legend.
  const double lx = kLeft + pw + 16;
  absl::StrAppendFormat(&s,
                        "<circle cx=\"%g\" cy=\"%g\" r=\"4.5\" fill=\"#1f77b4\"/>"
                        "<text x=\"%g\" y=\"%g\">on the Pareto front</text>\n"
                        "<circle cx=\"%g\" cy=\"%g\" r=\"4.5\" fill=\"#888\"/>"
                        "<text x=\"%g\" y=\"%g\">dominated</text>\n"
                        "<circle cx=\"%g\" cy=\"%g\" r=\"4.5\" fill=\"white\" stroke=\"#d62728\" stroke-width=\"1.5\"/>"
                        "<text x=\"%g\" y=\"%g\">re-check violated</text>\n"
                        "<text x=\"%g\" y=\"%g\">(&gt; 0.5 %%)</text>\n"
                        "<rect x=\"%g\" y=\"%g\" width=\"10\" height=\"10\" fill=\"#888\"/>"
                        "<text x=\"%g\" y=\"%g\">study default</text>\n",
                        lx, kTop + 10, lx + 10, kTop + 14, lx, kTop + 30, lx + 10, kTop + 34, lx,
                        kTop + 50, lx + 10, kTop + 54, lx + 10, kTop + 68, lx - 5, kTop + 80, lx + 10,
                        kTop + 89);
  absl::StrAppend(&s, "</svg>\n");
  return s;
}

}  // namespace mbopt::accuracy
