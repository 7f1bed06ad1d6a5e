#include "client/report/drawing_views.h"

#include <cmath>

namespace mbopt::report {
namespace {

using Axis = std::array<double, 3>;

double Dot(const Axis& a, double x, double y, double z) { return a[0] * x + a[1] * y + a[2] * z; }

spec::DrawingDirection Turned(const spec::DrawingDirection& d, const DrawingView& view) {
  return spec::DrawingDirection{Dot(view.right, d.x, d.y, d.z), Dot(view.up, d.x, d.y, d.z),
                                Dot(view.toward, d.x, d.y, d.z)};
}

std::vector<DrawingView> MakeViews() {
  // The isometric view looks along -(1, 1, 1) with z up on the picture:
  // right = z x toward normalized, up = toward x right; x then runs to the
  // lower left, y to the lower right, z straight up.
  const double s2 = 1.0 / std::sqrt(2.0), s3 = 1.0 / std::sqrt(3.0), s6 = 1.0 / std::sqrt(6.0);
  return {
      DrawingView{"top: x-y, seen from +z", {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0, 0, false},
      DrawingView{"isometric, seen from +x +y +z", {-s2, s2, 0}, {-s6, -s6, 2 * s6}, {s3, s3, s3}, 1, 0, true},
      DrawingView{"front: x-z, seen from -y", {1, 0, 0}, {0, 0, 1}, {0, -1, 0}, 0, 1, false},
      DrawingView{"right side: y-z, seen from +x", {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 1, 1, false},
  };
}

}  // namespace

const std::vector<DrawingView>& SpatialDrawingViews() {
  static const std::vector<DrawingView> views = MakeViews();
  return views;
}

spec::SceneDrawing InView(const spec::SceneDrawing& drawing, const DrawingView& view) {
  spec::SceneDrawing out = drawing;
  for (std::vector<spec::DrawingPosition>& instant : out.points_m) {
    for (spec::DrawingPosition& p : instant) {
      const double x = p.x_m, y = p.y_m, z = p.z_m;
      p = spec::DrawingPosition{Dot(view.right, x, y, z), Dot(view.up, x, y, z), Dot(view.toward, x, y, z)};
    }
  }
  for (spec::SceneDrawing::Joint& joint : out.joints) {
    for (spec::DrawingDirection& d : joint.axis_directions) d = Turned(d, view);
    for (spec::DrawingDirection& d : joint.second_axis_directions) d = Turned(d, view);
  }
  for (spec::SceneDrawing::Load& load : out.loads) {
    const spec::DrawingDirection d =
        Turned(spec::DrawingDirection{load.direction_x, load.direction_y, load.direction_z}, view);
    load.direction_x = d.x;
    load.direction_y = d.y;
    load.direction_z = d.z;
    for (spec::DrawingDirection& moving : load.directions) moving = Turned(moving, view);
  }
  return out;
}

}  // namespace mbopt::report
