// Analysis of a linkage scene (spec::LinkageModel) at one design point: the
// linkage side of the analysis engine. Picks the cheapest formulation the
// requested outputs allow:
//  - kinematic: only positions and rotations requested (no time steps);
//  - kinetostatic: forces, stresses or drive torque of rigid links;
//  - elastodynamic: the same for a linkage with flexible links (beam
//    elements on the rigid motion, integrated with CVODES BDF).
// A mechanism that cannot assemble, locks or changes branch, and an
// integrator failure, give status kFailed with a reason naming the time and
// the joint or link; never a number. Pure: no I/O, no threads.
#pragma once

#include <vector>

#include "spec/scene.h"
#include "spec/analysis_report.h"

namespace mbopt::solve {

// `scene.model` must hold a LinkageModel; `parameter_values_si` has one SI
// value per scene parameter.
spec::AnalysisReport AnalyzeLinkage(const spec::Scene& scene,
                                      const std::vector<double>& parameter_values_si);

}  // namespace mbopt::solve
