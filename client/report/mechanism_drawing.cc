#include "client/report/mechanism_drawing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "client/report/drawing_views.h"
#include "client/report/html_escape.h"
#include "client/report/load_case_drawings.h"
#include "client/report/number_format.h"
#include "client/report/spatial_symbols.h"

namespace mbopt::report {
namespace {

using spec::SceneDrawing;

// The figure's width and its largest height (px): the page's column.
constexpr double kWidthPx = 720.0;
constexpr double kMaxHeightPx = 520.0;
constexpr double kMinHeightPx = 180.0;
constexpr double kMarginPx = 36.0;
// Symbols keep their size on screen whatever the scene's size.
constexpr double kPinRadiusPx = 4.5;
constexpr double kBodyWidthPx = 14.0;
constexpr double kAxisHalfLengthPx = 46.0;
constexpr double kGroundWidthPx = 22.0;
// Frames of the animation follow one another this often (ms): about the
// rate at which a slider's steps still read as motion.
constexpr int kFrameIntervalMs = 60;

struct Px {
  double x = 0.0, y = 0.0;
};

// World (m, +y up) to the SVG's pixels (+y down), one scale for both axes.
struct Mapping {
  double scale = 1.0;  // px per m
  double x0 = 0.0, y0 = 0.0;  // world point at the origin of the drawing area
  double width = kWidthPx, height = kMinHeightPx;
  double offset_x = 0.0, offset_y = 0.0;
  Px operator()(const spec::DrawingPosition& p) const {
    return Px{offset_x + (p.x_m - x0) * scale, offset_y + (y0 - p.y_m) * scale};
  }
};

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f", std::isfinite(v) ? v : 0.0);
  return buffer;
}

std::string Pair(const Px& p) { return Num(p.x) + "," + Num(p.y); }

bool Finite(const spec::DrawingPosition& p) { return std::isfinite(p.x_m) && std::isfinite(p.y_m); }

// The drawings a figure's axes hold: its layers' and the `extent` it shares.
std::vector<const SceneDrawing*> AxesDrawings(const std::vector<DrawingLayer>& layers,
                                              const std::vector<const SceneDrawing*>& extent) {
  std::vector<const SceneDrawing*> drawings;
  for (const DrawingLayer& layer : layers) drawings.push_back(layer.drawing);
  for (const SceneDrawing* d : extent) {
    if (d != nullptr) drawings.push_back(d);
  }
  return drawings;
}

Mapping MapOf(const std::vector<const SceneDrawing*>& drawings) {
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min, y_min = x_min, y_max = -x_min;
  for (const SceneDrawing* drawing : drawings) {
    for (const std::vector<spec::DrawingPosition>& instant : drawing->points_m) {
      for (const spec::DrawingPosition& p : instant) {
        if (!Finite(p)) continue;
        x_min = std::min(x_min, p.x_m);
        x_max = std::max(x_max, p.x_m);
        y_min = std::min(y_min, p.y_m);
        y_max = std::max(y_max, p.y_m);
      }
    }
  }
  Mapping m;
  if (!std::isfinite(x_min)) return m;
  // A drawing of one point, or of points on a line, still gets an area.
  const double size = std::max({x_max - x_min, y_max - y_min, 1e-6});
  const double dx = std::max(x_max - x_min, 0.05 * size), dy = std::max(y_max - y_min, 0.05 * size);
  const double inner_width = kWidthPx - 2 * kMarginPx;
  m.scale = std::min(inner_width / dx, (kMaxHeightPx - 2 * kMarginPx) / dy);
  m.height = std::max(kMinHeightPx, dy * m.scale + 2 * kMarginPx);
  m.x0 = 0.5 * (x_min + x_max) - dx / 2;
  m.y0 = 0.5 * (y_min + y_max) + dy / 2;
  m.offset_x = kMarginPx + 0.5 * (inner_width - dx * m.scale);
  m.offset_y = 0.5 * (m.height - dy * m.scale);
  return m;
}

// The convex hull (Andrew's monotone chain), counter-clockwise.
std::vector<Px> Hull(std::vector<Px> p) {
  std::sort(p.begin(), p.end(), [](const Px& a, const Px& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  p.erase(std::unique(p.begin(), p.end(), [](const Px& a, const Px& b) { return a.x == b.x && a.y == b.y; }), p.end());
  if (p.size() < 3) return p;
  auto cross = [](const Px& o, const Px& a, const Px& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::vector<Px> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
    h[k++] = p[i - 1];
  }
  h.resize(k - 1);
  return h;
}

std::string Points(const std::vector<Px>& points) {
  std::string out;
  for (const Px& p : points) out += (out.empty() ? "" : " ") + Pair(p);
  return out;
}

// A body: its points' hull drawn with a wide round stroke in the fill
// colour (so two points make a bar, one a disc), then its outline.
std::string BodySvg(const std::vector<Px>& points, const DrawingLayer& layer) {
  const std::vector<Px> hull = Hull(points);
  if (hull.empty()) return "";
  if (hull.size() == 1) {
    return "<circle cx=\"" + Num(hull[0].x) + "\" cy=\"" + Num(hull[0].y) + "\" r=\"" + Num(kBodyWidthPx / 2) +
           "\" fill=\"" + layer.fill + "\" stroke=\"" + layer.color + "\" stroke-width=\"1.2\"/>";
  }
  const std::string shape = hull.size() == 2 ? "polyline" : "polygon";
  return "<" + shape + " points=\"" + Points(hull) + "\" fill=\"" + layer.fill + "\" stroke=\"" + layer.fill +
         "\" stroke-width=\"" + Num(kBodyWidthPx) + "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"/>" + "<" +
         shape + " points=\"" + Points(hull) + "\" fill=\"none\" stroke=\"" + layer.color +
         "\" stroke-width=\"1.2\" stroke-linejoin=\"round\"/>";
}

Px Along(const Px& a, const Px& b, double f) { return Px{a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)}; }

// A spring (zigzag), a damper (a pot and its piston) or both side by side
// between a and b; neither: a dashed line (an actuator).
std::string ElementSvg(Px a, Px b, const SceneDrawing::Element& e, const DrawingLayer& layer) {
  if (e.bushing) return BushingSvg(ScreenPoint{a.x, a.y}, ScreenPoint{b.x, b.y}, e.name, layer.color);
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  if (!(length > 1e-9)) return "";
  const Px u{(b.x - a.x) / length, (b.y - a.y) / length};
  const Px n{-u.y, u.x};
  const std::string stroke = "stroke=\"" + layer.color + "\" stroke-width=\"1.4\" fill=\"none\"";
  auto shifted = [&](const Px& p, double s) { return Px{p.x + s * n.x, p.y + s * n.y}; };
  auto spring = [&](double side) {
    std::vector<Px> zig{shifted(a, side), shifted(Along(a, b, 0.2), side)};
    constexpr int kTurns = 8;
    const double amplitude = std::min(6.0, 0.25 * length);
    for (int k = 1; k < 2 * kTurns; ++k) {
      zig.push_back(shifted(Along(a, b, 0.2 + 0.6 * k / (2.0 * kTurns)), side + (k % 2 == 1 ? amplitude : -amplitude)));
    }
    zig.push_back(shifted(Along(a, b, 0.8), side));
    zig.push_back(shifted(b, side));
    return "<polyline points=\"" + Points(zig) + "\" " + stroke + "/>";
  };
  auto damper = [&](double side) {
    const double w = 5.0;
    const Px pot_bottom = shifted(Along(a, b, 0.35), side), pot_top = shifted(Along(a, b, 0.7), side);
    const Px piston = shifted(Along(a, b, 0.55), side);
    std::string out = "<polyline points=\"" + Pair(shifted(a, side)) + " " + Pair(pot_bottom) + "\" " + stroke + "/>";
    out += "<polyline points=\"" + Pair(shifted(pot_top, w)) + " " + Pair(shifted(pot_bottom, w)) + " " +
           Pair(shifted(pot_bottom, -w)) + " " + Pair(shifted(pot_top, -w)) + "\" " + stroke + "/>";
    out += "<polyline points=\"" + Pair(shifted(piston, 0.7 * w)) + " " + Pair(shifted(piston, -0.7 * w)) + "\" " +
           stroke + "/>";
    out += "<polyline points=\"" + Pair(piston) + " " + Pair(shifted(b, side)) + "\" " + stroke + "/>";
    return out;
  };
  std::string out = "<g class=\"element\"><title>" + EscapeHtml(e.name) + "</title>";
  if (e.spring && e.damper) {
    out += spring(-8.0) + damper(8.0);
  } else if (e.spring) {
    out += spring(0.0);
  } else if (e.damper) {
    out += damper(0.0);
  } else {
    out += "<polyline points=\"" + Pair(a) + " " + Pair(b) + "\" " + stroke + " stroke-dasharray=\"5 3\"/>";
  }
  return out + "</g>";
}

std::string JointSvg(const Px& at, const SceneDrawing::Joint& joint, double axis_angle_rad, const DrawingLayer& layer) {
  std::string out = "<g class=\"joint\"><title>" + EscapeHtml(joint.name) + "</title>";
  const std::string stroke = "stroke=\"" + layer.color + "\" stroke-width=\"1.4\"";
  // The axis in pixels: +y is down on screen.
  const Px u{std::cos(axis_angle_rad), -std::sin(axis_angle_rad)};
  auto point = [&](double along, double across) {
    return Px{at.x + along * u.x - across * u.y, at.y + along * u.y + across * u.x};
  };
  switch (joint.kind) {
    case SceneDrawing::JointKind::kPin:
      out += "<circle class=\"pin\" cx=\"" + Num(at.x) + "\" cy=\"" + Num(at.y) + "\" r=\"" + Num(kPinRadiusPx) +
             "\" fill=\"#ffffff\" " + stroke + "/>";
      break;
    case SceneDrawing::JointKind::kFixed:
      out += "<rect class=\"fixed\" x=\"" + Num(at.x - 4) + "\" y=\"" + Num(at.y - 4) +
             "\" width=\"8\" height=\"8\" fill=\"" + layer.color + "\"/>";
      break;
    case SceneDrawing::JointKind::kSlider:
      out += "<polyline class=\"axis\" points=\"" + Pair(point(-kAxisHalfLengthPx, 0)) + " " +
             Pair(point(kAxisHalfLengthPx, 0)) + "\" " + stroke + " stroke-dasharray=\"6 3\" fill=\"none\"/>";
      out += "<polygon class=\"slider\" points=\"" +
             Points({point(-11, -7), point(11, -7), point(11, 7), point(-11, 7)}) + "\" fill=\"" + layer.fill + "\" " +
             stroke + "/>";
      out += "<circle cx=\"" + Num(at.x) + "\" cy=\"" + Num(at.y) + "\" r=\"2\" fill=\"" + layer.color + "\"/>";
      break;
    case SceneDrawing::JointKind::kPinInSlot:
      for (const double side : {-kPinRadiusPx - 1.5, kPinRadiusPx + 1.5}) {
        out += "<polyline class=\"slot\" points=\"" + Pair(point(-kAxisHalfLengthPx, side)) + " " +
               Pair(point(kAxisHalfLengthPx, side)) + "\" " + stroke + " fill=\"none\"/>";
      }
      out += "<circle class=\"pin\" cx=\"" + Num(at.x) + "\" cy=\"" + Num(at.y) + "\" r=\"" + Num(kPinRadiusPx) +
             "\" fill=\"#ffffff\" " + stroke + "/>";
      break;
    case SceneDrawing::JointKind::kSpherical:
    case SceneDrawing::JointKind::kUniversal:
    case SceneDrawing::JointKind::kCylindrical:
    case SceneDrawing::JointKind::kPlanar:
    case SceneDrawing::JointKind::kPointOnPlane:
      break;  // spatial kinds only: SpatialJointSvg draws them
  }
  return out + "</g>";
}

// A rotational spring (a spiral) and/or damper (an arc with a bar across)
// around a pin.
std::string RotationalElementSvg(const Px& at, const SceneDrawing::Joint& joint, const DrawingLayer& layer) {
  const std::string stroke = "stroke=\"" + layer.color + "\" stroke-width=\"1.2\" fill=\"none\"";
  std::string out = "<g class=\"rotational\"><title>" + EscapeHtml(joint.name) + ": rotational " +
                    (joint.rotational_spring && joint.rotational_damper ? "spring and damper"
                     : joint.rotational_spring                          ? "spring"
                                                                        : "damper") +
                    "</title>";
  if (joint.rotational_spring) {
    // Two turns from just outside the pin to 15 px.
    std::vector<Px> spiral;
    constexpr int kSteps = 48;
    for (int k = 0; k <= kSteps; ++k) {
      const double angle = 4.0 * std::numbers::pi * k / kSteps;
      const double radius = kPinRadiusPx + 2.0 + (15.0 - kPinRadiusPx - 2.0) * k / kSteps;
      spiral.push_back(Px{at.x + radius * std::cos(angle), at.y - radius * std::sin(angle)});
    }
    out += "<polyline class=\"rotational-spring\" points=\"" + Points(spiral) + "\" " + stroke + "/>";
  }
  if (joint.rotational_damper) {
    const double r = joint.rotational_spring ? 19.0 : 12.0;
    // The lower half circle, and a bar across it at its middle.
    out += "<path class=\"rotational-damper\" d=\"M " + Pair(Px{at.x - r, at.y}) + " A " + Num(r) + " " + Num(r) +
           " 0 0 0 " + Pair(Px{at.x + r, at.y}) + "\" " + stroke + "/>";
    out += "<polyline points=\"" + Pair(Px{at.x, at.y + r - 4}) + " " + Pair(Px{at.x, at.y + r + 4}) + "\" " + stroke +
           "/>";
  }
  return out + "</g>";
}

// A force: an arrow along its direction ending at its point; a torque: an
// arc arrow around the body's centre of mass, turning its way.
std::string LoadSvg(const Px& at, const SceneDrawing::Load& load) {
  const std::string color = "#7d3c98";
  std::string out = "<g class=\"load\"><title>" + EscapeHtml(load.name) + "</title>";
  auto head = [&](const Px& tip, const Px& u) {
    const Px left{tip.x - 7 * u.x - 4 * u.y, tip.y - 7 * u.y + 4 * u.x};
    const Px right{tip.x - 7 * u.x + 4 * u.y, tip.y - 7 * u.y - 4 * u.x};
    return "<polygon points=\"" + Points({tip, left, right}) + "\" fill=\"" + color + "\"/>";
  };
  if (load.kind == SceneDrawing::LoadKind::kForce) {
    const double norm = std::hypot(load.direction_x, load.direction_y);
    const Px u = norm > 0 ? Px{load.direction_x / norm, -load.direction_y / norm} : Px{0, 1};
    const Px tail{at.x - 34 * u.x, at.y - 34 * u.y};
    out += "<polyline points=\"" + Pair(tail) + " " + Pair(at) + "\" stroke=\"" + color +
           "\" stroke-width=\"1.8\" fill=\"none\"/>" + head(at, u);
  } else {
    // Three quarters of a circle of 13 px, counter-clockwise on screen for
    // a positive torque, the head at its end.
    constexpr double kRadius = 13.0;
    const bool ccw = load.direction_x >= 0.0;
    const double sign = ccw ? 1.0 : -1.0;
    const double start = -0.25 * std::numbers::pi, sweep = 1.5 * std::numbers::pi;
    auto on_arc = [&](double angle) {
      return Px{at.x + kRadius * std::cos(angle), at.y - kRadius * std::sin(angle)};
    };
    const double end = start + sign * sweep;
    const Px from = on_arc(start), to = on_arc(end);
    out += "<path d=\"M " + Pair(from) + " A " + Num(kRadius) + " " + Num(kRadius) + " 0 1 " + (ccw ? "0" : "1") + " " +
           Pair(to) + "\" stroke=\"" + color + "\" stroke-width=\"1.8\" fill=\"none\"/>";
    // The tangent at the end, in the direction of travel (+y down).
    const Px tangent{-sign * std::sin(end), -sign * std::cos(end)};
    out += head(Px{to.x + 3 * tangent.x, to.y + 3 * tangent.y}, tangent);
  }
  return out + "</g>";
}

// A ground point: a short base line under it, hatched.
std::string GroundSvg(const Px& at, const DrawingLayer& layer) {
  const double y = at.y + kPinRadiusPx + 3.0, half = kGroundWidthPx / 2;
  std::string out = "<g class=\"ground\"><polyline points=\"" + Pair(at) + " " + Pair(Px{at.x, y}) + "\" stroke=\"" +
                    layer.color + "\" stroke-width=\"1.2\" fill=\"none\"/>";
  out += "<polyline points=\"" + Pair(Px{at.x - half, y}) + " " + Pair(Px{at.x + half, y}) + "\" stroke=\"" +
         layer.color + "\" stroke-width=\"1.6\" fill=\"none\"/>";
  for (double x = at.x - half + 4; x <= at.x + half + 0.1; x += 5) {
    out += "<polyline points=\"" + Pair(Px{x, y}) + " " + Pair(Px{x - 5, y + 6}) + "\" stroke=\"" + layer.color +
           "\" stroke-width=\"1\" fill=\"none\"/>";
  }
  return out + "</g>";
}

// An input point: an arrow along its direction, ending at it.
std::string InputSvg(const Px& at, const SceneDrawing::Input& input) {
  const double norm = std::hypot(input.direction_x, input.direction_y);
  const Px u = norm > 0 ? Px{input.direction_x / norm, -input.direction_y / norm} : Px{0, -1};
  const Px tail{at.x - 28 * u.x, at.y - 28 * u.y};
  const Px left{at.x - 7 * u.x - 4 * u.y, at.y - 7 * u.y + 4 * u.x};
  const Px right{at.x - 7 * u.x + 4 * u.y, at.y - 7 * u.y - 4 * u.x};
  return "<g class=\"input\"><title>" + EscapeHtml(input.name) + "</title><polyline points=\"" + Pair(tail) + " " +
         Pair(at) + "\" stroke=\"#b03a2e\" stroke-width=\"1.6\" fill=\"none\"/><polygon points=\"" +
         Points({at, left, right}) + "\" fill=\"#b03a2e\"/></g>";
}

// One layer at one instant.
std::string LayerFrameSvg(const DrawingLayer& layer, size_t instant, const Mapping& map) {
  const SceneDrawing& d = *layer.drawing;
  const std::vector<spec::DrawingPosition>& at = d.points_m[instant];
  auto px = [&](int point) { return map(at[static_cast<size_t>(point)]); };
  std::string out = "<g class=\"layer\"";
  if (layer.opacity < 1.0) out += " opacity=\"" + FormatValue(layer.opacity, 3) + "\"";
  out += ">";
  // A view of a spatial drawing paints the bodies farthest from the viewer
  // first (by their points' mean depth), so nearer ones cover them.
  std::vector<const SceneDrawing::Body*> bodies;
  for (const SceneDrawing::Body& body : d.bodies) bodies.push_back(&body);
  if (d.spatial) {
    // Non-finite points (a motion that blew up) are left out, so the order
    // stays a strict weak one.
    auto depth = [&](const SceneDrawing::Body* body) {
      double sum = 0.0;
      int finite = 0;
      for (const int p : body->points) {
        const double z = at[static_cast<size_t>(p)].z_m;
        if (!std::isfinite(z)) continue;
        sum += z;
        ++finite;
      }
      return finite == 0 ? 0.0 : sum / finite;
    };
    std::stable_sort(bodies.begin(), bodies.end(),
                     [&](const SceneDrawing::Body* a, const SceneDrawing::Body* b) { return depth(a) < depth(b); });
  }
  for (const SceneDrawing::Body* body_ptr : bodies) {
    const SceneDrawing::Body& body = *body_ptr;
    std::vector<Px> points;
    for (const int p : body.points) {
      if (Finite(at[static_cast<size_t>(p)])) points.push_back(px(p));
    }
    out += "<g class=\"body\"><title>" + EscapeHtml(body.name) + "</title>" + BodySvg(points, layer) + "</g>";
  }
  for (const SceneDrawing::Line& line : d.lines) {
    std::vector<Px> points;
    for (const int p : line.points) points.push_back(px(p));
    out += "<g class=\"flexible\"><title>" + EscapeHtml(line.name) + "</title><polyline points=\"" + Points(points) +
           "\" stroke=\"" + layer.color + "\" stroke-width=\"3\" fill=\"none\" stroke-linejoin=\"round\"/></g>";
  }
  for (const SceneDrawing::Element& e : d.elements) out += ElementSvg(px(e.a), px(e.b), e, layer);
  for (const SceneDrawing::Input& input : d.inputs) out += InputSvg(px(input.point), input);
  for (const SceneDrawing::Joint& joint : d.joints) {
    if (joint.rotational_spring || joint.rotational_damper) out += RotationalElementSvg(px(joint.point), joint, layer);
  }
  for (const SceneDrawing::Load& load : d.loads) {
    if (!d.spatial) {
      out += LoadSvg(px(load.point), load);
      continue;
    }
    const Px c = px(load.point);
    const spec::DrawingDirection direction = instant < load.directions.size()
                                                 ? load.directions[instant]
                                                 : spec::DrawingDirection{load.direction_x, load.direction_y,
                                                                          load.direction_z};
    out += SpatialLoadSvg(ScreenPoint{c.x, c.y}, load, direction);
  }
  // The points themselves, small, under the joints.
  for (size_t p = 0; p < at.size(); ++p) {
    const Px c = px(static_cast<int>(p));
    out += "<circle cx=\"" + Num(c.x) + "\" cy=\"" + Num(c.y) + "\" r=\"1.6\" fill=\"" + layer.color +
           "\"><title>" + EscapeHtml(d.point_names[p]) + "</title></circle>";
  }
  for (const SceneDrawing::Joint& joint : d.joints) {
    if (d.spatial) {
      const Px c = px(joint.point);
      const spec::DrawingDirection* axis =
          instant < joint.axis_directions.size() ? &joint.axis_directions[instant] : nullptr;
      const spec::DrawingDirection* second =
          instant < joint.second_axis_directions.size() ? &joint.second_axis_directions[instant] : nullptr;
      out += SpatialJointSvg(ScreenPoint{c.x, c.y}, joint, axis, second, layer.color, layer.fill);
      continue;
    }
    const double axis = instant < joint.axis_angle_rad.size() ? joint.axis_angle_rad[instant] : 0.0;
    out += JointSvg(px(joint.point), joint, axis, layer);
  }
  return out + "</g>";
}

// The legend: one line per labelled layer.
std::string LegendSvg(const std::vector<DrawingLayer>& layers) {
  std::string out;
  double y = 16;
  for (const DrawingLayer& layer : layers) {
    if (layer.label.empty()) continue;
    out += "<rect x=\"10\" y=\"" + Num(y - 9) + "\" width=\"14\" height=\"9\" fill=\"" + layer.fill + "\" stroke=\"" +
           layer.color + "\"/><text x=\"30\" y=\"" + Num(y) + "\" font-size=\"12\">" + EscapeHtml(layer.label) +
           "</text>\n";
    y += 16;
  }
  return out;
}

// The <svg> of planar drawings: one picture, x to the right and y up.
std::string PlanarSheetSvg(const std::vector<DrawingLayer>& layers, const std::vector<size_t>& frames,
                           const std::vector<const SceneDrawing*>& extent) {
  const Mapping map = MapOf(AxesDrawings(layers, extent));
  std::string out = "<svg class=\"drawing\" width=\"" + Num(map.width) + "\" height=\"" + Num(map.height) +
                    "\" viewBox=\"0 0 " + Num(map.width) + " " + Num(map.height) + "\" role=\"img\">\n";
  out += "<rect x=\"0\" y=\"0\" width=\"" + Num(map.width) + "\" height=\"" + Num(map.height) +
         "\" fill=\"#fcfcfc\" stroke=\"#dddddd\"/>\n";
  // Ground does not move: drawn once per layer, under the frames.
  for (const DrawingLayer& layer : layers) {
    for (const int p : layer.drawing->ground_points) {
      out += GroundSvg(map(layer.drawing->points_m[0][static_cast<size_t>(p)]), layer);
    }
  }
  out += "\n";
  for (size_t f = 0; f < frames.size(); ++f) {
    out += "<g class=\"frame\"" + std::string(f == 0 ? "" : " display=\"none\"") + ">";
    for (const DrawingLayer& layer : layers) {
      out += LayerFrameSvg(layer, std::min(frames[f], layer.drawing->points_m.size() - 1), map);
    }
    out += "</g>\n";
  }
  return out + LegendSvg(layers) + "</svg>\n";
}

// The sheet of a spatial drawing: four views (drawing_views.h) on a 2 x 2
// grid of cells half the figure wide, each frame showing the same instant
// in all four.
constexpr double kMaxCellHeightPx = 300.0;
constexpr double kMinCellHeightPx = 150.0;

std::string SpatialSheetSvg(const std::vector<DrawingLayer>& layers, const std::vector<size_t>& frames,
                            const std::vector<const SceneDrawing*>& extent) {
  const std::vector<DrawingView>& views = SpatialDrawingViews();
  std::vector<std::vector<SceneDrawing>> viewed(views.size());
  struct Span {
    double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min, y_min = x_min, y_max = -x_min;
  };
  std::vector<Span> spans(views.size());
  double size = 1e-6;
  for (size_t v = 0; v < views.size(); ++v) {
    auto hold = [&spans, v](const SceneDrawing& drawing) {
      for (const std::vector<spec::DrawingPosition>& instant : drawing.points_m) {
        for (const spec::DrawingPosition& p : instant) {
          if (!Finite(p)) continue;
          spans[v].x_min = std::min(spans[v].x_min, p.x_m);
          spans[v].x_max = std::max(spans[v].x_max, p.x_m);
          spans[v].y_min = std::min(spans[v].y_min, p.y_m);
          spans[v].y_max = std::max(spans[v].y_max, p.y_m);
        }
      }
    };
    for (const DrawingLayer& layer : layers) {
      viewed[v].push_back(InView(*layer.drawing, views[v]));
      hold(viewed[v].back());
    }
    // The shared drawings count for the axes only: viewed, held, dropped.
    for (const SceneDrawing* shared : extent) hold(InView(*shared, views[v]));
    if (std::isfinite(spans[v].x_min)) {
      size = std::max({size, spans[v].x_max - spans[v].x_min, spans[v].y_max - spans[v].y_min});
    } else {
      spans[v] = Span{0.0, 0.0, 0.0, 0.0};
    }
  }
  // A view of points on a line still gets an area, as a planar drawing.
  auto width_of = [&](size_t v) { return std::max(spans[v].x_max - spans[v].x_min, 0.05 * size); };
  auto height_of = [&](size_t v) { return std::max(spans[v].y_max - spans[v].y_min, 0.05 * size); };
  const double cell_width = kWidthPx / 2, inner_width = cell_width - 2 * kMarginPx;
  double scale = std::numeric_limits<double>::infinity();
  for (size_t v = 0; v < views.size(); ++v) {
    if (views[v].isometric) continue;
    scale = std::min({scale, inner_width / width_of(v), (kMaxCellHeightPx - 2 * kMarginPx) / height_of(v)});
  }
  double row_height[2] = {kMinCellHeightPx, kMinCellHeightPx};
  for (size_t v = 0; v < views.size(); ++v) {
    if (views[v].isometric) continue;
    double& h = row_height[views[v].row];
    h = std::max(h, height_of(v) * scale + 2 * kMarginPx);
  }
  std::vector<Mapping> maps(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    const double h = row_height[views[v].row], top = views[v].row == 0 ? 0.0 : row_height[0];
    Mapping& m = maps[v];
    m.scale = views[v].isometric ? std::min(inner_width / width_of(v), (h - 2 * kMarginPx) / height_of(v)) : scale;
    m.x0 = 0.5 * (spans[v].x_min + spans[v].x_max) - width_of(v) / 2;
    m.y0 = 0.5 * (spans[v].y_min + spans[v].y_max) + height_of(v) / 2;
    m.offset_x = views[v].column * cell_width + kMarginPx + 0.5 * (inner_width - width_of(v) * m.scale);
    m.offset_y = top + 0.5 * (h - height_of(v) * m.scale);
  }
  const double width = kWidthPx, height = row_height[0] + row_height[1];
  std::string out = "<svg class=\"drawing spatial\" width=\"" + Num(width) + "\" height=\"" + Num(height) +
                    "\" viewBox=\"0 0 " + Num(width) + " " + Num(height) + "\" role=\"img\">\n";
  out += "<rect x=\"0\" y=\"0\" width=\"" + Num(width) + "\" height=\"" + Num(height) +
         "\" fill=\"#fcfcfc\" stroke=\"#dddddd\"/>\n";
  for (size_t v = 0; v < views.size(); ++v) {
    const double x = views[v].column * cell_width, top = views[v].row == 0 ? 0.0 : row_height[0];
    const double h = row_height[views[v].row];
    out += "<g class=\"view\"><rect x=\"" + Num(x) + "\" y=\"" + Num(top) + "\" width=\"" + Num(cell_width) +
           "\" height=\"" + Num(h) + "\" fill=\"none\" stroke=\"#e4e4e4\"/><text x=\"" + Num(x + 8) + "\" y=\"" +
           Num(top + h - 8) + "\" font-size=\"11\" fill=\"#666666\">" + EscapeHtml(views[v].label) + "</text>";
    // Ground does not move: drawn once per layer, under the frames.
    for (size_t l = 0; l < layers.size(); ++l) {
      DrawingLayer layer = layers[l];
      layer.drawing = &viewed[v][l];
      for (const int p : layer.drawing->ground_points) {
        out += GroundSvg(maps[v](layer.drawing->points_m[0][static_cast<size_t>(p)]), layer);
      }
    }
    out += "</g>\n";
  }
  for (size_t f = 0; f < frames.size(); ++f) {
    out += "<g class=\"frame\"" + std::string(f == 0 ? "" : " display=\"none\"") + ">";
    for (size_t v = 0; v < views.size(); ++v) {
      for (size_t l = 0; l < layers.size(); ++l) {
        DrawingLayer layer = layers[l];
        layer.drawing = &viewed[v][l];
        out += LayerFrameSvg(layer, std::min(frames[f], layer.drawing->points_m.size() - 1), maps[v]);
      }
    }
    out += "</g>\n";
  }
  return out + LegendSvg(layers) + "</svg>\n";
}

}  // namespace

std::vector<size_t> FrameInstants(size_t instants) {
  std::vector<size_t> picked;
  if (instants <= static_cast<size_t>(kMaxDrawingFrames)) {
    for (size_t i = 0; i < instants; ++i) picked.push_back(i);
    return picked;
  }
  for (int k = 0; k < kMaxDrawingFrames; ++k) {
    picked.push_back(static_cast<size_t>(std::llround(static_cast<double>(k) * static_cast<double>(instants - 1) /
                                                      (kMaxDrawingFrames - 1))));
  }
  return picked;
}

std::string MechanismFigureHtml(const std::vector<DrawingLayer>& layers_in, const std::string& id,
                                const std::vector<const SceneDrawing*>& extent_in) {
  std::vector<DrawingLayer> layers;
  for (const DrawingLayer& layer : layers_in) {
    if (layer.drawing != nullptr && !layer.drawing->points_m.empty()) layers.push_back(layer);
  }
  std::string out = "<div class=\"mechanism\" id=\"" + EscapeHtml(id) + "\">\n";
  if (layers.empty()) return out + "<p class=\"note\">Nothing to draw.</p>\n</div>\n";
  size_t instants = 0;
  const std::vector<double>* times = nullptr;
  bool spatial = false;
  for (const DrawingLayer& layer : layers) {
    spatial = spatial || layer.drawing->spatial;
    if (layer.drawing->points_m.size() > instants) {
      instants = layer.drawing->points_m.size();
      times = &layer.drawing->times_s;
    }
  }
  const std::vector<size_t> frames = FrameInstants(instants);
  std::vector<const SceneDrawing*> extent;
  for (const SceneDrawing* d : extent_in) {
    // Only drawings of the figure's kind: a plane's axes are not a view's.
    if (d != nullptr && !d->points_m.empty() && d->spatial == spatial) extent.push_back(d);
  }
  out += spatial ? SpatialSheetSvg(layers, frames, extent) : PlanarSheetSvg(layers, frames, extent);
  if (spatial) {
    out += "<p class=\"note\">Views of world axes in third-angle arrangement: top (x-y) above front (x-z), the "
           "right side (y-z, seen from +x) beside the front, one scale for the three; the isometric view is scaled "
           "to fit.</p>\n";
  }
  std::string time_list;
  for (const size_t f : frames) {
    time_list += (time_list.empty() ? "" : ",") + std::string("\"") +
                 FormatValue(f < times->size() ? (*times)[f] : 0.0, 6) + "\"";
  }
  const std::string first_time = FormatValue(times->empty() ? 0.0 : (*times)[frames[0]], 6);
  // One frame (a schematic, a grid of one instant) has nothing to animate.
  const bool animated = frames.size() > 1;
  out += "<div class=\"controls\">";
  if (animated) {
    out += "<button type=\"button\">Play</button> <input type=\"range\" min=\"0\" max=\"" +
           std::to_string(frames.size() - 1) +
           "\" value=\"0\" step=\"1\" style=\"width: 420px; vertical-align: middle\"> ";
  }
  out += "<span class=\"time\">t = " + first_time + " s</span>";
  if (frames.size() < instants) {
    out += " <span class=\"note\">(" + std::to_string(frames.size()) + " of " + std::to_string(instants) +
           " instants shown)</span>";
  }
  out += "</div>\n";
  for (const DrawingLayer& layer : layers) {
    if (!layer.drawing->note.empty()) {
      out += "<p class=\"note\">" + EscapeHtml(layer.label.empty() ? std::string("The drawing") : layer.label) +
             ": " + EscapeHtml(layer.drawing->note) + ".</p>\n";
    }
    if (!layer.drawing->failure.empty()) {
      out += "<p class=\"note\">" + EscapeHtml(layer.label.empty() ? std::string("The drawing") : layer.label) +
             ": the motion stops at t = " +
             FormatValue(layer.drawing->times_s.empty() ? 0.0 : layer.drawing->times_s.back(), 6) +
             " s: " + EscapeHtml(layer.drawing->failure) + "</p>\n";
    }
  }
  if (!animated) return out + "</div>\n";
  // One frame shown at a time; the slider picks it, the button steps
  // through them in a loop, and "#frame=N" in the page's address opens it
  // at frame N (a link to an instant, a screenshot of one).
  out += "<script>(function(){var root=document.getElementById(\"" + EscapeHtml(id) +
         "\");var frames=root.querySelectorAll(\"g.frame\");var slider=root.querySelector(\"input\");"
         "var button=root.querySelector(\"button\");var label=root.querySelector(\".time\");var times=[" +
         time_list +
         "];var shown=0,timer=null;function show(i){frames[shown].setAttribute(\"display\",\"none\");shown=i;"
         "frames[i].removeAttribute(\"display\");slider.value=i;label.textContent=\"t = \"+times[i]+\" s\";}"
         "slider.addEventListener(\"input\",function(){show(Number(slider.value));});"
         "button.addEventListener(\"click\",function(){if(timer!==null){clearInterval(timer);timer=null;"
         "button.textContent=\"Play\";return;}button.textContent=\"Pause\";timer=setInterval(function(){"
         "show((shown+1)%frames.length);}," +
         std::to_string(kFrameIntervalMs) +
         ");});root.showTime=function(t){var best=0;for(var i=1;i<times.length;i++){"
         "if(Math.abs(Number(times[i])-t)<Math.abs(Number(times[best])-t))best=i;}show(best);};"
         "var asked=/frame=([0-9]+)/.exec(location.hash);"
         "if(asked)show(Math.min(Number(asked[1]),frames.length-1));})();</script>\n";
  return out + "</div>\n";
}

std::string MechanismSectionHtml(const MechanismDrawings& mechanism) {
  if (!mechanism.cases.empty()) return LoadCaseSectionHtml(mechanism);
  if (!mechanism.initial && !mechanism.final && mechanism.note.empty()) return "";
  std::string out = "<h2>Mechanism</h2>\n";
  std::vector<DrawingLayer> layers;
  if (mechanism.initial) {
    layers.push_back(DrawingLayer{&*mechanism.initial, "initial design", "#7a7a7a", "#e6e6e6", 0.75});
  }
  if (mechanism.final) layers.push_back(DrawingLayer{&*mechanism.final, "final design", "#1f4e9a", "#c9d8f0", 1.0});
  if (!layers.empty()) {
    const bool schematic = layers.front().drawing->schematic;
    out += std::string("<p class=\"note\">The scene ") +
           (schematic ? "as a schematic (a lumped scene: its layout, not a motion)"
                      : "over its time grid (the slider or the play button moves it)") +
           " at the initial design (grey) and at the final design (blue), overlaid on the same axes.</p>\n";
    out += MechanismFigureHtml(layers, "mechanism");
  }
  if (!mechanism.note.empty()) out += "<p class=\"note\">" + EscapeHtml(mechanism.note) + "</p>\n";
  return out;
}

std::string SceneDrawingPageHtml(const spec::SceneDrawing& drawing, const std::string& source) {
  std::string out =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
      EscapeHtml(drawing.scene_name) +
      "</title>\n<style>\nbody { font-family: sans-serif; margin: 1.5em; color: #222; }\n"
      "p.note { color: #555; }\n.controls { margin: 0.4em 0; }\n.controls input { width: 420px; vertical-align: middle; }\n"
      "</style>\n</head>\n<body>\n<h1>" +
      EscapeHtml(drawing.scene_name) + "</h1>\n<p class=\"note\">" + EscapeHtml(source) + ": " +
      (drawing.schematic ? std::string("schematic (a lumped scene: its layout, not a motion)")
                         : std::to_string(drawing.times_s.size()) + " instants of the time grid") +
      "</p>\n";
  DrawingLayer layer;
  layer.drawing = &drawing;
  out += MechanismFigureHtml({layer}, "drawing");
  return out + "</body>\n</html>\n";
}

}  // namespace mbopt::report
