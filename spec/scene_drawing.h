// The picture of a scene: where its parts are at every instant drawn, as
// plain data. The worker computes it only when asked (`mbopt-worker draw`),
// the file schema carries it (proto/mbopt/v1/drawing.proto), and the report
// draws it (client/report/mechanism_drawing.h); nothing here draws.
//
// Every part names points of one table, `point_names`, whose positions are
// given per instant (`points_m[instant]`, world axes, m). A schematic (a
// lumped scene: small motion about a layout that means nothing physically)
// has one instant, t = 0.
//
// A spatial scene's drawing (`spatial`) gives every position and direction
// in three world coordinates; a planar one leaves z at 0. The data stay in
// world axes either way: how three dimensions become a picture (the views
// the report draws side by side) is the drawing's business, not the data's.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace mbopt::spec {

struct DrawingPosition {
  double x_m = 0.0, y_m = 0.0;
  double z_m = 0.0;  // spatial drawings only
};

// A direction in world axes (unit), at one instant.
struct DrawingDirection {
  double x = 0.0, y = 0.0, z = 0.0;
};

struct SceneDrawing {
  // A rigid body (or a lumped body) drawn as the outline around its points.
  struct Body {
    std::string name;
    std::vector<int> points;
  };
  // The planar kinds, then those only spatial scenes have. In a spatial
  // drawing a pin is a revolute joint, a slider a prismatic one and a pin
  // in a slot a point-on-line joint.
  enum class JointKind {
    kPin, kSlider, kFixed, kPinInSlot,
    kSpherical, kUniversal, kCylindrical, kPlanar, kPointOnPlane
  };
  // A joint drawn at `point`; a slider's and a pin-in-slot's axis through it
  // at `axis_angle_rad[instant]` (world axes; empty for the others).
  // A pin with a rotational spring or damper (or both) drawn around it.
  //
  // Spatial drawings give the axis as a direction instead,
  // `axis_directions[instant]` (world axes, unit): the axis of a revolute,
  // prismatic, cylindrical or point-on-line joint, the normal of a planar or
  // point-on-plane joint's plane, a universal joint's first cross arm (on
  // body a), whose second arm (on body b) is `second_axis_directions`; empty
  // for a spherical or fixed joint, and in planar drawings.
  struct Joint {
    std::string name;
    JointKind kind = JointKind::kPin;
    int point = -1;
    std::vector<double> axis_angle_rad;
    bool rotational_spring = false, rotational_damper = false;
    std::vector<DrawingDirection> axis_directions = {}, second_axis_directions = {};
  };
  // A translational element between two points: spring zigzag, damper pot,
  // or both side by side; or a bushing (six stiffnesses and dampings
  // between two frames, spatial scenes) drawn as a block of rubber.
  struct Element {
    std::string name;
    int a = -1, b = -1;
    bool spring = false, damper = false;
    bool bushing = false;
  };
  // A flexible link's centre line through its nodes, in order.
  struct Line {
    std::string name;
    std::vector<int> points;
  };
  // A point that moves by a prescribed input (a road under a wheel): drawn
  // with an arrow along `direction` (unit).
  struct Input {
    std::string name;
    int point = -1;
    double direction_x = 0.0, direction_y = 1.0;
  };

  // An applied load: a force at `point` along (direction_x, direction_y)
  // (world axes, unit; drawn as an arrow ending at the point), or a torque
  // on the body whose centre of mass is `point` (direction_x: +1 counter-
  // clockwise, -1 clockwise). Its size is not drawn, only where and which way.
  //
  // Spatial drawings: (direction_x, direction_y, direction_z) is the force's
  // direction or the torque's axis (right hand), world axes, unit; a load
  // whose components are given in its body's axes turns with the body, and
  // `directions[instant]` then holds its direction at every instant (empty:
  // the direction holds).
  enum class LoadKind { kForce, kTorque };
  struct Load {
    std::string name;
    LoadKind kind = LoadKind::kForce;
    int point = -1;
    double direction_x = 0.0, direction_y = -1.0;
    double direction_z = 0.0;
    std::vector<DrawingDirection> directions = {};
  };

  std::string scene_name;
  bool schematic = false;
  std::vector<double> times_s;
  std::vector<std::string> point_names;
  std::vector<std::vector<DrawingPosition>> points_m;  // [instant][point]
  std::vector<Body> bodies;
  std::vector<Joint> joints;
  std::vector<Element> elements;
  std::vector<Line> lines;
  std::vector<Input> inputs;
  std::vector<Load> loads;
  std::vector<int> ground_points;  // hatched: fixed to the world
  // Empty when every instant of the grid was drawn; else why the motion
  // stopped (the instants before are kept).
  std::string failure;
  // Empty, or what the reader must know to read the drawing right (what it
  // leaves out, and why).
  std::string note;
  // A spatial scene: positions and directions have three components.
  bool spatial = false;

  // Appends a point (its positions are filled per instant) and returns its index.
  int AddPoint(std::string name) {
    point_names.push_back(std::move(name));
    return static_cast<int>(point_names.size()) - 1;
  }
};

}  // namespace mbopt::spec
