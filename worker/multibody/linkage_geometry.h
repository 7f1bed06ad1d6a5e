// The drawing of a linkage scene (spec::LinkageModel) over its time grid:
// each link as a bar between its pins with its points, the pins, the ground
// pins hatched. The motion is the rigid linkage's kinematics on the
// multibody engine, as the linkage analysis solves it (the driver turning
// at most 10 degrees between two solved instants, so the assembly branch is
// followed). A linkage its analysis follows elastically is drawn with the
// deflection that analysis computes. In the floating-frame formulation
// (UsesFloatingFrame, linkage_analysis.h): each moving link as its centre
// line through its nodes, each pin moved by its elastic displacement, the
// links' own points on the chord between the moved pins. In the
// co-rotational one (UsesCorotational): each moving link as its centre
// line through its nodes, the analysis' own coordinates, and between them
// each element's cubic shape in its co-rotated frame (beam_shape.h); the
// pins where the analysis puts them, the links' own points on the chord
// between them. A linkage with flexible links whose outputs are all
// positions and rotations is analysed kinematically (no deflection
// computed): drawn rigid, with a note that says so. Computed only when
// asked: an analysis keeps no elastic motion unless a drawing asks for it.
// Pure.
#pragma once

#include <vector>

#include "spec/scene.h"
#include "spec/scene_drawing.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::multibody {

spec::SceneDrawing DrawLinkageScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                    budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::multibody
