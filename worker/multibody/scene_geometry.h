// The drawing of a multibody scene (spec::MultibodyModel) over its time grid:
// each body's markers (and its centre of mass when it has fewer than two),
// every joint with its kind and, for a slider or a pin in a slot, its axis,
// spring and damper end points, ground markers, moving input points and the
// flexible links' deformed centre lines through their nodes.
//
// Computed only when asked, apart from the scene's analysis: the motion is
// solved as the analysis solves it (the same model, assembly and choice of
// kinematics, static equilibrium or forward dynamics), but no output is
// evaluated and AnalyzeMultibodyScene does no work for a drawing. Pure: no
// I/O, no threads.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "spec/scene.h"
#include "spec/scene_drawing.h"
#include "worker/budget/analysis_budget.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/model.h"

namespace mbopt::multibody {

// The parts of the drawing of `scene` (compiled to `model` by CompileModel
// at the parameter values `p`, SI) and, per drawing point, the model point
// it follows.
struct MultibodyDrawingLayout {
  spec::SceneDrawing drawing;  // parts only: no instant yet
  std::vector<Point> points;   // [drawing point]
  std::vector<int> axis_joints;  // [drawing joint]: the model joint of a slider or pin in a slot, else -1
};
MultibodyDrawingLayout LayoutMultibodyDrawing(const spec::Scene& scene, const std::vector<double>& p,
                                              const Model& model);

// Appends instant t_s with the coordinates q to layout->drawing.
void AppendDrawingInstant(const Mechanism& mechanism, double t_s, const Eigen::VectorXd& q,
                          MultibodyDrawingLayout* layout);

// The drawing of a multibody scene at the parameter values (SI) over its
// time grid. A scene that does not compile or assemble, or whose motion
// stops, gives the instants drawn so far and `failure` saying why.
spec::SceneDrawing DrawMultibodyScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                      budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::multibody
