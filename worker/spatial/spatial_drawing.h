// The drawing of a spatial scene (spec::SpatialModel) over its time grid, in
// world coordinates (x, y, z): every declared marker (ground markers as
// ground), each body between its markers (its centre of mass when it has
// fewer than two), every joint at its frame b's origin with its kind and
// its axis' direction at each instant, spring-dampers and bushings between
// their points, rotational spring-dampers on their joints, point forces and
// torques with their directions. How three dimensions become a picture is
// left to whoever draws it (client/report/drawing_views.h).
//
// Computed only when asked, apart from the scene's analysis: the motion is
// solved as AnalyzeSpatialScene solves it (the same model and assembly,
// kinematics when every degree of freedom is driven, else IDAS forward
// dynamics, redundant joints included; the equilibrium configurations of a
// static scene), but no output is evaluated. Pure:
// no I/O, no threads.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "spec/scene.h"
#include "spec/scene_drawing.h"
#include "worker/budget/analysis_budget.h"
#include "worker/spatial/spatial_model.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {

// The parts of the drawing of `scene` (compiled to `model` by
// CompileSpatialModel at the parameter values `p`, SI) and what each
// drawing point and axis follows.
struct SpatialDrawingLayout {
  spec::SceneDrawing drawing;  // parts only: no instant yet
  std::vector<Point> points;   // [drawing point]
  // [drawing joint]: the body and the direction in its axes of the joint's
  // axis and of a universal joint's second arm (body kGround and a zero
  // direction: none drawn).
  struct Axis {
    int body = kGround;
    Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  };
  std::vector<Axis> axes, second_axes;
  // [drawing load]: the body a load given in body axes turns with, else -1
  // (its direction holds); and that direction in the body's axes.
  std::vector<int> load_bodies;
  std::vector<Eigen::Vector3d> load_body_directions;
};
SpatialDrawingLayout LayoutSpatialDrawing(const spec::Scene& scene, const std::vector<double>& p, const Model& model);

// Appends instant t_s with the coordinates q to layout->drawing.
void AppendSpatialDrawingInstant(const SpatialSystem& system, double t_s, const Eigen::VectorXd& q,
                                 SpatialDrawingLayout* layout);

// The drawing of a spatial scene at the parameter values (SI) over its time
// grid. A scene that does not compile or assemble, or whose motion stops,
// gives the instants drawn so far (the initial guess when it does not
// assemble) and `failure` saying why.
spec::SceneDrawing DrawSpatialScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                    budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::spatial
