// Gradients of an analysis as the service carries them: flat, row-major
// vectors (one row per objective term, resp. constraint row; one column per
// design variable, with respect to the SCALED variables), as in
// mbopt.v1.TaskResult and the analysis log (server/store/records.h). This is
// where they are checked against the problem's shape and turned into the
// SLP core's matrices. Pure.
//
// The service's rule: gradients that do not fit (wrong size, a NaN or
// infinite entry) are no gradients; the analysis' values still count and the
// optimizer falls back to finite differences for that cycle. The check is
// made once, when the result arrives, and the log keeps what the optimizer
// was given, so a replay hands it exactly the same again.
#pragma once

#include <string>
#include <vector>

#include "server/slp/problem.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

// Why the pair cannot be used ("" when it can). Both empty is "no
// gradients", which is not a defect. `constraint_gradients` may be empty
// when the problem has no constraint rows.
std::string GradientDefect(const slp::ProblemSpec& problem, const std::vector<double>& objective_gradients,
                           const std::vector<double>& constraint_gradients);

// Sets result->objective_gradients / constraint_gradients from the flat
// vectors, or leaves both empty when the pair is empty or has a defect.
void AttachGradients(const slp::ProblemSpec& problem, const std::vector<double>& objective_gradients,
                     const std::vector<double>& constraint_gradients, slp::AnalysisResult* result);

}  // namespace mbopt::jobs
