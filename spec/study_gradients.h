// The chain rule from an analysis' output derivatives to the derivatives of
// the study values (objective terms and constraint rows, spec/layout.h) with
// respect to the SCALED design variables: parameter value (SI) =
// scale * x * si_per_unit (Study::ParameterValuesAt), so
// d/dx_i = scale_i * si_per_unit_i * d/dp_i. Pure.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::spec {

// d p_si / d x_i for every design variable.
std::vector<double> ParameterSiPerScaledVariable(const Study& study);

struct StudyGradients {
  // [term][variable], objective unit per unit of x; aligned with
  // StudyValues::objective_terms.
  std::vector<std::vector<double>> objective_terms;
  // [row][variable], SI per unit of x; aligned with layout.rows.
  std::vector<std::vector<double>> constraint_rows;
};

// `outputs_si[o]`: output o as for ComputeStudyValues. `derivatives_si[i][o]`:
// d output o / d (SI value of variable i's parameter), same shape. A
// target_distance objective at F = 0 has no derivative: FailedPrecondition.
// InvalidArgument if a shape differs from the layout's.
absl::StatusOr<StudyGradients> ComputeStudyGradients(
    const Study& study, const StudyLayout& layout,
    const std::vector<const std::vector<std::vector<double>>*>& outputs_si,
    const std::vector<std::vector<const std::vector<std::vector<double>>*>>& derivatives_si);

}  // namespace mbopt::spec
