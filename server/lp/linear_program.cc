#include "server/lp/linear_program.h"

namespace mbopt::lp {

const char* LpStatusName(LpStatus status) {
  switch (status) {
    case LpStatus::kOptimal:
      return "optimal";
    case LpStatus::kInfeasible:
      return "infeasible";
    case LpStatus::kUnbounded:
      return "unbounded";
    case LpStatus::kIterationLimit:
      return "iteration_limit";
    case LpStatus::kTimeLimit:
      return "time_limit";
    case LpStatus::kNumericalFailure:
      return "numerical_failure";
  }
  return "unknown";
}

}  // namespace mbopt::lp
