// The symbols of a spatial drawing's parts as SVG, in one view
// (client/report/drawing_views.h): each takes its place in pixels and its
// directions in the view's axes (x right, y up, z toward the viewer), so
// an axis that points at the viewer shrinks to nothing, as on a drawing
// sheet.
//
//  - revolute joint: a pin on its axis' centre line; prismatic: a block on
//    its dashed axis; cylindrical: both; point on line: a pin in a slot
//    along the line; spherical: a ball in its socket; universal: the cross
//    with its two arms; planar and point-on-plane: a patch of the plane
//    (filled, or dashed), the point on it; fixed: a filled square;
//  - a force: an arrow ending at its point; a torque: a double-headed
//    arrow along its axis (right hand); one seen end-on: a circle with a
//    dot (toward the viewer) or a cross (away);
//  - a bushing: a rubber block between its two frames' origins.
#pragma once

#include <string>

#include "spec/scene_drawing.h"

namespace mbopt::report {

// A point of the picture (px, +y down).
struct ScreenPoint {
  double x = 0.0, y = 0.0;
};

// `axis` and `second_axis` (a universal joint's arm on body b) in view
// axes, or null where the joint has none.
std::string SpatialJointSvg(const ScreenPoint& at, const spec::SceneDrawing::Joint& joint,
                            const spec::DrawingDirection* axis, const spec::DrawingDirection* second_axis,
                            const std::string& color, const std::string& fill);

// `direction`: the force's direction or the torque's axis in view axes.
std::string SpatialLoadSvg(const ScreenPoint& at, const spec::SceneDrawing::Load& load,
                           const spec::DrawingDirection& direction);

std::string BushingSvg(const ScreenPoint& a, const ScreenPoint& b, const std::string& name, const std::string& color);

}  // namespace mbopt::report
