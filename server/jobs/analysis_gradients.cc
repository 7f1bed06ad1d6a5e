#include "server/jobs/analysis_gradients.h"

#include <cmath>
#include <cstddef>

#include "absl/strings/str_cat.h"

namespace mbopt::jobs {
namespace {

// The first non-finite entry's index, or -1.
std::ptrdiff_t FirstNonFinite(const std::vector<double>& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return static_cast<std::ptrdiff_t>(i);
  }
  return -1;
}

Eigen::MatrixXd RowMajor(const std::vector<double>& values, Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = values[static_cast<size_t>(r * cols + c)];
  }
  return m;
}

}  // namespace

std::string GradientDefect(const slp::ProblemSpec& problem, const std::vector<double>& objective_gradients,
                           const std::vector<double>& constraint_gradients) {
  if (objective_gradients.empty() && constraint_gradients.empty()) return "";
  const size_t n = static_cast<size_t>(problem.num_variables());
  const size_t terms = static_cast<size_t>(problem.num_objective_terms);
  const size_t rows = static_cast<size_t>(problem.num_constraints());
  if (objective_gradients.size() != terms * n || constraint_gradients.size() != rows * n) {
    return absl::StrCat("gradients have ", objective_gradients.size(), " objective and ",
                        constraint_gradients.size(), " constraint entries; expected ", terms, " x ", n, " = ",
                        terms * n, " and ", rows, " x ", n, " = ", rows * n);
  }
  if (const std::ptrdiff_t i = FirstNonFinite(objective_gradients); i >= 0) {
    return absl::StrCat("objective gradient entry (", static_cast<size_t>(i) / n, ", ", static_cast<size_t>(i) % n,
                        ") is ", objective_gradients[static_cast<size_t>(i)]);
  }
  if (const std::ptrdiff_t i = FirstNonFinite(constraint_gradients); i >= 0) {
    const size_t row = static_cast<size_t>(i) / n;
    return absl::StrCat("constraint gradient entry (",
                        row < problem.constraint_names.size() ? problem.constraint_names[row] : absl::StrCat(row),
                        ", ", static_cast<size_t>(i) % n, ") is ", constraint_gradients[static_cast<size_t>(i)]);
  }
  return "";
}

void AttachGradients(const slp::ProblemSpec& problem, const std::vector<double>& objective_gradients,
                     const std::vector<double>& constraint_gradients, slp::AnalysisResult* result) {
  result->objective_gradients.resize(0, 0);
  result->constraint_gradients.resize(0, 0);
  if (objective_gradients.empty() && constraint_gradients.empty()) return;
  if (!GradientDefect(problem, objective_gradients, constraint_gradients).empty()) return;
  const Eigen::Index n = problem.num_variables();
  result->objective_gradients = RowMajor(objective_gradients, problem.num_objective_terms, n);
  result->constraint_gradients = RowMajor(constraint_gradients, problem.num_constraints(), n);
}

}  // namespace mbopt::jobs
