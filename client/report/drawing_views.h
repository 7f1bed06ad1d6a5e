// How a spatial drawing (spec::SceneDrawing with `spatial`, world
// coordinates) becomes pictures: the views an engineer expects on a
// drawing sheet, in third-angle arrangement,
//
//   top (x-y, seen from +z)         isometric (seen from +x +y +z)
//   front (x-z, seen from -y)       right side (y-z, seen from +x)
//
// so the front and top views share their horizontal x and the front and
// side views their vertical z. With vehicle axes (x forward, y left, z up)
// the "right side" view is the one from ahead of the vehicle.
//
// A view is a rotation: InView turns every position and direction of a
// drawing into the view's axes (x to the right of the picture, y up, z
// toward the viewer), and the picture is that drawing's x and y; z says
// what lies in front. The data keep world coordinates; only drawing turns.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "spec/scene_drawing.h"

namespace mbopt::report {

struct DrawingView {
  std::string label;  // what the picture shows, e.g. "front: x-z, seen from -y"
  // World-axes unit vectors of the picture's right, up and toward the
  // viewer (a right-handed triple: right x up = toward).
  std::array<double, 3> right{}, up{}, toward{};
  // Where the view sits on the sheet: column and row of a 2 x 2 grid,
  // row 0 at the top.
  int column = 0, row = 0;
  // Orthographic views share one scale, so lengths compare across them;
  // the isometric view is scaled to fit its place.
  bool isometric = false;
};

// The four views above, in the order top, isometric, front, side.
const std::vector<DrawingView>& SpatialDrawingViews();

// `drawing` in the view's axes: positions (x_m right, y_m up, z_m toward
// the viewer), joint axes and load directions turned alike; everything else
// as it was. A planar drawing (z = 0) works too.
spec::SceneDrawing InView(const spec::SceneDrawing& drawing, const DrawingView& view);

}  // namespace mbopt::report
