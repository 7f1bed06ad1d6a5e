#include "client/report/spatial_symbols.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "client/report/html_escape.h"

namespace mbopt::report {
namespace {

using spec::SceneDrawing;
using Px = ScreenPoint;

// Sizes on screen (px), those of the planar symbols where they match.
constexpr double kPinRadiusPx = 4.5;
constexpr double kAxisHalfLengthPx = 46.0;
constexpr double kArmHalfLengthPx = 12.0;
constexpr double kPlaneHalfSizePx = 13.0;
constexpr double kLoadLengthPx = 34.0;
// Below this share of its length on the picture, a direction is drawn as
// seen end-on: a dot or a cross.
constexpr double kEndOnShare = 0.25;
const char kLoadColor[] = "#7d3c98";

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.1f", std::isfinite(v) ? v : 0.0);
  return buffer;
}

std::string Pair(const Px& p) { return Num(p.x) + "," + Num(p.y); }

std::string Points(const std::vector<Px>& points) {
  std::string out;
  for (const Px& p : points) out += (out.empty() ? "" : " ") + Pair(p);
  return out;
}

// A direction of view axes on the picture: its unit (+y down) and the share
// of its length that shows.
struct OnScreen {
  Px unit{1.0, 0.0};
  double share = 0.0;
};
OnScreen Project(const spec::DrawingDirection& d) {
  OnScreen s;
  s.share = std::hypot(d.x, d.y);
  if (s.share > 1e-9) s.unit = Px{d.x / s.share, -d.y / s.share};
  return s;
}

Px Offset(const Px& at, const Px& unit, double along, double across = 0.0) {
  return Px{at.x + along * unit.x - across * unit.y, at.y + along * unit.y + across * unit.x};
}

std::string Line(const Px& a, const Px& b, const std::string& attributes) {
  return "<polyline points=\"" + Pair(a) + " " + Pair(b) + "\" " + attributes + " fill=\"none\"/>";
}

std::string Circle(const Px& c, double r, const std::string& attributes) {
  return "<circle cx=\"" + Num(c.x) + "\" cy=\"" + Num(c.y) + "\" r=\"" + Num(r) + "\" " + attributes + "/>";
}

// A centre line (long dash, dot) along the axis through `at`.
std::string CentreLine(const Px& at, const OnScreen& axis, double half_length, const std::string& color) {
  if (axis.share * half_length < 1.0) return "";
  return Line(Offset(at, axis.unit, -half_length * axis.share), Offset(at, axis.unit, half_length * axis.share),
              "class=\"axis\" stroke=\"" + color + "\" stroke-width=\"1\" stroke-dasharray=\"8 3 2 3\"");
}

// A block along the axis: long where the axis lies in the picture, square
// where it points at the viewer.
std::string Block(const Px& at, const OnScreen& axis, const std::string& color, const std::string& fill) {
  const double half = 11.0 * std::max(axis.share, 0.6);
  return "<polygon class=\"slider\" points=\"" +
         Points({Offset(at, axis.unit, -half, -7), Offset(at, axis.unit, half, -7), Offset(at, axis.unit, half, 7),
                 Offset(at, axis.unit, -half, 7)}) +
         "\" fill=\"" + fill + "\" stroke=\"" + color + "\" stroke-width=\"1.4\"/>";
}

// Two unit vectors spanning the plane normal to `n` (view axes), as they
// show on the picture.
void PlaneSpan(const spec::DrawingDirection& n, Px* e1, Px* e2) {
  const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
  // The axis least aligned with n keeps the cross product well sized.
  double r[3] = {0, 0, 0};
  r[ax <= ay && ax <= az ? 0 : (ay <= az ? 1 : 2)] = 1.0;
  double u[3] = {n.y * r[2] - n.z * r[1], n.z * r[0] - n.x * r[2], n.x * r[1] - n.y * r[0]};
  const double norm = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  if (norm > 0) {
    for (double& c : u) c /= norm;
  }
  const double v[3] = {n.y * u[2] - n.z * u[1], n.z * u[0] - n.x * u[2], n.x * u[1] - n.y * u[0]};
  *e1 = Px{u[0], -u[1]};
  *e2 = Px{v[0], -v[1]};
}

std::string PlanePatch(const Px& at, const spec::DrawingDirection& normal, bool filled, const std::string& color,
                       const std::string& fill) {
  Px e1, e2;
  PlaneSpan(normal, &e1, &e2);
  const double h = kPlaneHalfSizePx;
  auto corner = [&](double s1, double s2) {
    return Px{at.x + h * (s1 * e1.x + s2 * e2.x), at.y + h * (s1 * e1.y + s2 * e2.y)};
  };
  return "<polygon class=\"plane\" points=\"" + Points({corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)}) +
         "\" fill=\"" + (filled ? fill : std::string("none")) + "\" fill-opacity=\"0.7\" stroke=\"" + color +
         "\" stroke-width=\"1\"" + (filled ? "" : " stroke-dasharray=\"3 2\"") + "/>";
}

// The end-on sign of a vector: a circle with a dot (toward the viewer) or a
// cross (away from the viewer).
std::string EndOn(const Px& at, double z, double r, const std::string& color) {
  std::string out = Circle(at, r, "fill=\"#ffffff\" stroke=\"" + color + "\" stroke-width=\"1.6\"");
  if (z >= 0.0) return out + Circle(at, 1.8, "fill=\"" + color + "\"");
  const double c = 0.7 * r;
  const std::string stroke = "stroke=\"" + color + "\" stroke-width=\"1.4\"";
  return out + Line(Px{at.x - c, at.y - c}, Px{at.x + c, at.y + c}, stroke) +
         Line(Px{at.x - c, at.y + c}, Px{at.x + c, at.y - c}, stroke);
}

std::string Head(const Px& tip, const Px& u, const std::string& color) {
  const Px left{tip.x - 7 * u.x - 4 * u.y, tip.y - 7 * u.y + 4 * u.x};
  const Px right{tip.x - 7 * u.x + 4 * u.y, tip.y - 7 * u.y - 4 * u.x};
  return "<polygon points=\"" + Points({tip, left, right}) + "\" fill=\"" + color + "\"/>";
}

}  // namespace

std::string SpatialJointSvg(const ScreenPoint& at, const SceneDrawing::Joint& joint,
                            const spec::DrawingDirection* axis_direction,
                            const spec::DrawingDirection* second_axis_direction, const std::string& color,
                            const std::string& fill) {
  const OnScreen axis = axis_direction != nullptr ? Project(*axis_direction) : OnScreen{};
  const std::string stroke = "stroke=\"" + color + "\" stroke-width=\"1.4\"";
  const std::string pin = Circle(at, kPinRadiusPx, "class=\"pin\" fill=\"#ffffff\" " + stroke);
  std::string out = "<g class=\"joint\"><title>" + EscapeHtml(joint.name) + "</title>";
  switch (joint.kind) {
    case SceneDrawing::JointKind::kPin:
      out += CentreLine(at, axis, 0.6 * kAxisHalfLengthPx, color) + pin;
      break;
    case SceneDrawing::JointKind::kSlider:
      out += Line(Offset(at, axis.unit, -kAxisHalfLengthPx * axis.share),
                  Offset(at, axis.unit, kAxisHalfLengthPx * axis.share),
                  "class=\"axis\" " + stroke + " stroke-dasharray=\"6 3\"");
      out += Block(at, axis, color, fill) + Circle(at, 2, "fill=\"" + color + "\"");
      break;
    case SceneDrawing::JointKind::kCylindrical:
      out += CentreLine(at, axis, kAxisHalfLengthPx, color) + Block(at, axis, color, fill) + pin;
      break;
    case SceneDrawing::JointKind::kPinInSlot:
      for (const double side : {-kPinRadiusPx - 1.5, kPinRadiusPx + 1.5}) {
        out += Line(Offset(at, axis.unit, -kAxisHalfLengthPx * axis.share, side),
                    Offset(at, axis.unit, kAxisHalfLengthPx * axis.share, side), "class=\"slot\" " + stroke);
      }
      out += pin;
      break;
    case SceneDrawing::JointKind::kSpherical:
      out += Circle(at, 6.5, "class=\"socket\" fill=\"#ffffff\" " + stroke) +
             Circle(at, 3.2, "class=\"ball\" fill=\"" + color + "\"");
      break;
    case SceneDrawing::JointKind::kUniversal: {
      // The cross: each arm with a short fork tick at its ends.
      for (const spec::DrawingDirection* arm : {axis_direction, second_axis_direction}) {
        if (arm == nullptr) continue;
        const OnScreen s = Project(*arm);
        const double h = kArmHalfLengthPx * s.share;
        out += Line(Offset(at, s.unit, -h), Offset(at, s.unit, h), "class=\"arm\" " + stroke);
        for (const double end : {-h, h}) {
          if (h < 2.0) continue;
          out += Line(Offset(at, s.unit, end, -3), Offset(at, s.unit, end, 3), stroke);
        }
      }
      out += Circle(at, 2.5, "fill=\"" + color + "\"");
      break;
    }
    case SceneDrawing::JointKind::kPlanar:
    case SceneDrawing::JointKind::kPointOnPlane: {
      const bool planar = joint.kind == SceneDrawing::JointKind::kPlanar;
      if (axis_direction != nullptr) out += PlanePatch(at, *axis_direction, planar, color, fill);
      out += planar ? pin : Circle(at, 2.5, "fill=\"" + color + "\"");
      break;
    }
    case SceneDrawing::JointKind::kFixed:
      out += "<rect class=\"fixed\" x=\"" + Num(at.x - 4) + "\" y=\"" + Num(at.y - 4) +
             "\" width=\"8\" height=\"8\" fill=\"" + color + "\"/>";
      break;
  }
  return out + "</g>";
}

std::string SpatialLoadSvg(const ScreenPoint& at, const SceneDrawing::Load& load,
                           const spec::DrawingDirection& direction) {
  const bool torque = load.kind == SceneDrawing::LoadKind::kTorque;
  std::string out = "<g class=\"load\"><title>" + EscapeHtml(load.name) + "</title>";
  const OnScreen s = Project(direction);
  if (s.share < kEndOnShare) {
    // A torque's sign keeps a second ring, so it is told from a force.
    out += EndOn(at, direction.z, 6.0, kLoadColor);
    if (torque) out += Circle(at, 9.0, "fill=\"none\" stroke=\"" + std::string(kLoadColor) + "\" stroke-width=\"1\"");
    return out + "</g>";
  }
  const double length = kLoadLengthPx * s.share;
  const std::string stroke = "stroke=\"" + std::string(kLoadColor) + "\" stroke-width=\"1.8\"";
  if (!torque) {
    // A force ends at its point.
    out += Line(Offset(at, s.unit, -length), at, stroke) + Head(at, s.unit, kLoadColor);
  } else {
    // A moment vector starts at the centre of mass, two heads at its tip.
    const Px tip = Offset(at, s.unit, length);
    out += Line(at, tip, stroke) + Head(tip, s.unit, kLoadColor) +
           Head(Offset(at, s.unit, length - 7), s.unit, kLoadColor);
  }
  return out + "</g>";
}

std::string BushingSvg(const ScreenPoint& a, const ScreenPoint& b, const std::string& name, const std::string& color) {
  const Px mid{0.5 * (a.x + b.x), 0.5 * (a.y + b.y)};
  const std::string stroke = "stroke=\"" + color + "\" stroke-width=\"1.2\"";
  std::string out = "<g class=\"bushing\"><title>" + EscapeHtml(name) + "</title>";
  out += Line(a, b, stroke);
  out += "<rect x=\"" + Num(mid.x - 6) + "\" y=\"" + Num(mid.y - 6) +
         "\" width=\"12\" height=\"12\" rx=\"3\" fill=\"#5a5a5a\" fill-opacity=\"0.55\" " + stroke + "/>";
  return out + "</g>";
}

}  // namespace mbopt::report
