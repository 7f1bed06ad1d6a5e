// Factory for the COIN-OR CLP implementation of LpSolver. Callers see only
// the interface; ClpSimplex.hpp is included in clp_lp_solver.cc alone.
#pragma once

#include <memory>

#include "server/lp/linear_program.h"

namespace mbopt::lp {

std::unique_ptr<LpSolver> MakeClpLpSolver(const LpSolverOptions& options = {});

}  // namespace mbopt::lp
