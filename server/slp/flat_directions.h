// Flat directions: design variables that change nothing where a run ended.
// A variable whose derivatives of the objective's ruling terms and of the
// active constraints all vanish cannot be improved on and cannot be blamed;
// users usually meant it to matter (a parameter bound to an effect the scene
// does not declare, a time window that never sees it), so the run says so.
#pragma once

#include <vector>

#include "server/slp/cycle_lp.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"

namespace mbopt::slp {

// A relative sensitivity at or below this is no sensitivity: a change of a
// variable by its whole typical size moves no response by more than this
// share of its own scale. A parameter a simulation ignores gives exactly 0;
// the margin covers the rounding of a finite difference of equal values
// computed along different paths.
inline constexpr double kFlatRelativeSensitivity = 1e-8;

// Indices of the variables that are flat in `lin`: neither held (a held
// variable's derivative is unknown, not zero) nor sensitive. Ruling terms
// are those within convergence_violation_tolerance (relative) of F; active
// constraints those whose normalized value is above
// -convergence_violation_tolerance.
std::vector<int> FlatVariables(const ProblemSpec& spec, const SlpOptions& options,
                               const Linearization& lin);

}  // namespace mbopt::slp
