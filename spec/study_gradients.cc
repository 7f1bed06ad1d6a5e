#include "spec/study_gradients.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "spec/responses.h"

namespace mbopt::spec {
namespace {


absl::Status CheckShapes(const Study& study, const StudyLayout& layout,
                         const std::vector<const Series*>& outputs, const char* what) {
  if (outputs.size() != layout.outputs.size()) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": ", outputs.size(),
                                                   " outputs, the layout expects ",
                                                   layout.outputs.size()));
  }
  for (size_t o = 0; o < outputs.size(); ++o) {
    const OutputShape& shape = layout.outputs[o];
    bool ok = outputs[o] != nullptr && static_cast<int>(outputs[o]->size()) == shape.series;
    for (size_t s = 0; ok && s < outputs[o]->size(); ++s) {
      ok = static_cast<int>((*outputs[o])[s].size()) == shape.instants;
    }
    if (!ok) {
      return absl::InvalidArgumentError(absl::StrCat(
          what, ": output \"", study.SignalName(static_cast<int>(o)), "\" does not have the layout's shape (",
          shape.series, " series of ", shape.instants, " values)"));
    }
  }
  return absl::OkStatus();
}

// d(value of ref) / d(parameter of variable i) for every variable: the
// reduction's weights at the analysed values (computed once per ref) times
// the output's derivatives over the same instants.
std::vector<double> RefGradient(const std::vector<const Series*>& values,
                                const std::vector<std::vector<const Series*>>& derivatives,
                                const std::vector<double>& instants_s, const ValueRef& ref) {
  const size_t o = static_cast<size_t>(ref.output);
  const size_t s = static_cast<size_t>(ref.series);
  std::vector<double> gradient(derivatives.size(), 0.0);
  if (ref.over == Over::kInstant) {
    for (size_t i = 0; i < derivatives.size(); ++i) {
      gradient[i] = ref.sign * (*derivatives[i][o])[s][static_cast<size_t>(ref.instant)];
    }
    return gradient;
  }
  std::vector<double> weights;
  RefValue(ref, (*values[o])[s], instants_s, &weights);
  const size_t first = static_cast<size_t>(ref.first);
  for (size_t i = 0; i < derivatives.size(); ++i) {
    const std::vector<double>& d = (*derivatives[i][o])[s];
    for (size_t k = 0; k < weights.size(); ++k) gradient[i] += weights[k] * d[first + k];
  }
  return gradient;
}

}  // namespace

std::vector<double> ParameterSiPerScaledVariable(const Study& study) {
  std::vector<double> factors;
  for (const DesignVariable& v : study.variables) {
    factors.push_back(v.scale *
                      study.scene.parameters[static_cast<size_t>(v.parameter)].si_per_unit);
  }
  return factors;
}

absl::StatusOr<StudyGradients> ComputeStudyGradients(
    const Study& study, const StudyLayout& layout, const std::vector<const Series*>& outputs_si,
    const std::vector<std::vector<const Series*>>& derivatives_si) {
  const size_t n = study.variables.size();
  if (derivatives_si.size() != n) {
    return absl::InvalidArgumentError(absl::StrCat("derivatives for ", derivatives_si.size(),
                                                   " variables, the study has ", n));
  }
  if (absl::Status s = CheckShapes(study, layout, outputs_si, "values"); !s.ok()) return s;
  for (size_t i = 0; i < n; ++i) {
    if (absl::Status s = CheckShapes(study, layout, derivatives_si[i], "derivatives"); !s.ok()) {
      return s;
    }
  }
  const std::vector<double> factor = ParameterSiPerScaledVariable(study);
  StudyGradients out;
  const Objective& objective = study.objective;
  if (objective.form == Objective::Form::kTargetDistance) {
    // F = sqrt(sum w (o/u - t)^2): dF = sum w (o/u - t) do/u / F.
    double sum = 0.0;
    for (const TargetTerm& term : objective.terms) {
      const double o = (*outputs_si[static_cast<size_t>(term.output)])[0].back() / term.si_per_unit;
      sum += term.weight * (o - term.target) * (o - term.target);
    }
    const double f = std::sqrt(sum);
    if (!(f > 0.0)) {
      return absl::FailedPreconditionError("target_distance objective is 0: no derivative");
    }
    std::vector<double> row(n, 0.0);
    for (size_t i = 0; i < n; ++i) {
      for (const TargetTerm& term : objective.terms) {
        const size_t o_index = static_cast<size_t>(term.output);
        const double o = (*outputs_si[o_index])[0].back() / term.si_per_unit;
        const double d = (*derivatives_si[i][o_index])[0].back() / term.si_per_unit;
        row[i] += term.weight * (o - term.target) * d / f;
      }
      row[i] *= factor[i];
    }
    out.objective_terms.push_back(std::move(row));
  } else if (objective.form == Objective::Form::kFeasible) {
    out.objective_terms.push_back(std::vector<double>(n, 0.0));  // F = 0 everywhere
  } else if (objective.form == Objective::Form::kWeightedSum && layout.objective_form == ObjectiveForm::kScalar) {
    std::vector<double> row(n, 0.0);
    for (size_t k = 0; k < objective.sum_terms.size(); ++k) {
      const WeightedTerm& term = objective.sum_terms[k];
      const std::vector<double> g = RefGradient(outputs_si, derivatives_si, layout.instants_s, layout.sum_refs[k]);
      for (size_t i = 0; i < n; ++i) row[i] += term.weight * g[i] / term.si_per_unit * factor[i];
    }
    out.objective_terms.push_back(std::move(row));
  } else {
    for (size_t k = 0; k < layout.objective_terms.size(); ++k) {
      std::vector<double> row = RefGradient(outputs_si, derivatives_si, layout.instants_s, layout.objective_terms[k]);
      for (size_t i = 0; i < n; ++i) row[i] = row[i] * layout.objective_term_factors[k] * factor[i];
      out.objective_terms.push_back(std::move(row));
    }
  }
  for (const ConstraintRow& c : layout.rows) {
    std::vector<double> row = RefGradient(outputs_si, derivatives_si, layout.instants_s, c.value);
    for (size_t i = 0; i < n; ++i) row[i] *= factor[i];
    out.constraint_rows.push_back(std::move(row));
  }
  return out;
}

}  // namespace mbopt::spec
