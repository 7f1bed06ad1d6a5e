#include "spec/layout.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spec/limits.h"

namespace mbopt::spec {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

absl::Status LayoutError(const Study& study, const std::string& field, const std::string& what) {
  return absl::InvalidArgumentError(absl::StrCat(
      study.source_file.empty() ? "study" : study.source_file, ": ", field, ": ", what));
}

// Enough decimals that neighbouring grid instants get different names.
int TimeDecimals(const std::vector<double>& instants) {
  double step = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < instants.size(); ++i) {
    step = std::min(step, std::abs(instants[i] - instants[i - 1]));
  }
  if (!std::isfinite(step) || step <= 0) return 3;
  return std::clamp(static_cast<int>(std::ceil(-std::log10(step))) + 1, 3, 9);
}

std::string RowName(const std::string& constraint, const OutputShape& shape, int series,
                    bool time_series, double t, int decimals, const char* side) {
  std::string name = constraint;
  if (shape.series > 1) absl::StrAppend(&name, "[", shape.series_labels[series], "]");
  if (time_series) absl::StrAppend(&name, absl::StrFormat("@t=%.*fs", decimals, t));
  absl::StrAppend(&name, " ", side);
  return name;
}

}  // namespace

OutputShape OutputShapeOf(const Scene& scene, int output) {
  OutputShape shape;
  const Output& out = scene.outputs[static_cast<size_t>(output)];
  shape.instants = std::holds_alternative<MassOutput>(out.kind)
                       ? 1
                       : static_cast<int>(scene.time_grid.Instants().size());
  if (const auto* stress = std::get_if<BendingStressOutput>(&out.kind)) {
    // A flexible link of a multibody model: every node, 0 (end a) to n (end b).
    const auto* multibody = std::get_if<MultibodyModel>(&scene.model);
    if (multibody != nullptr && stress->link >= 0 &&
        stress->link < static_cast<int>(multibody->flexible_links.size())) {
      const int elements = multibody->flexible_links[static_cast<size_t>(stress->link)].elements;
      shape.series_labels.clear();
      for (int j = 0; j <= elements; ++j) shape.series_labels.push_back(absl::StrCat("node ", j));
      shape.series = elements + 1;
      return shape;
    }
    const auto* linkage = std::get_if<LinkageModel>(&scene.model);
    if (linkage != nullptr && stress->link >= 0 &&
        stress->link < static_cast<int>(linkage->links.size())) {
      const Link& link = linkage->links[static_cast<size_t>(stress->link)];
      const int elements =
          link.flexible_elements > 0 ? link.flexible_elements : kRigidLinkStressElements;
      const bool driven = linkage->driver.link == stress->link;
      const int pivot = linkage->driver.pivot_joint;
      shape.series_labels.clear();
      for (int j = 0; j <= elements; ++j) {
        const bool end_a = j == 0, end_b = j == elements;
        if (end_a && !(driven && link.joint_a == pivot)) continue;
        if (end_b && !(driven && link.joint_b == pivot)) continue;
        shape.series_labels.push_back(absl::StrCat("node ", j));
      }
      shape.series = static_cast<int>(shape.series_labels.size());
      return shape;
    }
  }
  shape.series = 1;
  shape.series_labels = {out.name};
  return shape;
}

Dimension OutputDimension(const Output& output) {
  return std::visit(Overloaded{
                        [](const PointPositionOutput&) { return Dimension::kLength; },
                        [](const LinkRotationOutput&) { return Dimension::kAngle; },
                        [](const ElementDeflectionOutput&) { return Dimension::kLength; },
                        [](const BodyAccelerationOutput&) { return Dimension::kAcceleration; },
                        [](const BendingStressOutput&) { return Dimension::kPressure; },
                        [](const DriveTorqueOutput&) { return Dimension::kTorque; },
                        [](const MassOutput&) { return Dimension::kMass; },
                        [](const MultibodyOutput& m) {
                          using Q = MultibodyOutput::Quantity;
                          switch (m.quantity) {
                            case Q::kMarkerPosition: return Dimension::kLength;
                            case Q::kMarkerVelocity: return Dimension::kVelocity;
                            case Q::kMarkerAcceleration: return Dimension::kAcceleration;
                            case Q::kJointCoordinate: return m.linear ? Dimension::kLength : Dimension::kAngle;
                            case Q::kJointRate: return m.linear ? Dimension::kVelocity : Dimension::kAngularVelocity;
                            case Q::kJointReaction: return Dimension::kForce;
                            case Q::kDriverEffort: return m.linear ? Dimension::kForce : Dimension::kTorque;
                            case Q::kSpringLength: return Dimension::kLength;
                            case Q::kSpringForce: return Dimension::kForce;
                            case Q::kKineticEnergy:
                            case Q::kPotentialEnergy: return Dimension::kAny;
                          }
                          return Dimension::kAny;
                        },
                    },
                    output.kind);
}

StudyFootprint EstimateStudyFootprint(const Study& study) {
  const Scene& scene = study.scene;
  const int num_outputs = static_cast<int>(scene.outputs.size());
  auto values = [&](int output) -> std::int64_t {
    if (output < 0 || output >= num_outputs) return 0;
    const OutputShape shape = OutputShapeOf(scene, output);
    return static_cast<std::int64_t>(shape.series) * shape.instants;
  };
  StudyFootprint f;
  const Objective& objective = study.objective;
  f.objective_terms = objective.form == Objective::Form::kMinimizeMaxOf
                          ? values(objective.output) * (objective.reduction == Reduction::kMaxAbs ? 2 : 1)
                          : 1;
  for (const Constraint& c : study.constraints) {
    const std::int64_t all = values(c.output);
    const std::int64_t series = c.output >= 0 && c.output < num_outputs ? OutputShapeOf(scene, c.output).series : 0;
    switch (c.reduction) {
      case Reduction::kFinal: f.constraint_rows += series; break;
      case Reduction::kMaxAbs: f.constraint_rows += 2 * all; break;
      default: f.constraint_rows += all; break;
    }
  }
  const std::int64_t n = static_cast<std::int64_t>(study.variables.size());
  const std::int64_t per_value = 8 * ((n + 1)            // x0's and the perturbations' values
                                      + n                // the linearization's gradient
                                      + 5 * (n + 2) / 2) // the dense LP row and the solver's copy
                                 + 120;                  // the row's layout entry and name
  f.memory_bytes = (f.objective_terms + f.constraint_rows) * per_value;
  return f;
}

absl::StatusOr<StudyLayout> MakeStudyLayout(const Study& study) {
  const Scene& scene = study.scene;
  if (const StudyFootprint f = EstimateStudyFootprint(study); f.memory_bytes > kMaxStudyMemoryBytes) {
    return LayoutError(
        study, "constraints",
        absl::StrFormat("the study needs about %.1f GB of memory for its %d objective terms and %d constraint rows "
                        "with %d variables, more than the limit of %.0f GB; use fewer time points "
                        "(analysis.time_grid_points) or fewer constraints on time series",
                        static_cast<double>(f.memory_bytes) / 1e9, f.objective_terms, f.constraint_rows,
                        study.variables.size(), static_cast<double>(kMaxStudyMemoryBytes) / (1 << 30)));
  }
  StudyLayout layout;
  layout.instants_s = scene.time_grid.Instants();
  for (size_t o = 0; o < scene.outputs.size(); ++o) {
    layout.outputs.push_back(OutputShapeOf(scene, static_cast<int>(o)));
  }
  const int num_outputs = static_cast<int>(scene.outputs.size());
  auto valid_output = [&](int o) { return o >= 0 && o < num_outputs; };

  const Objective& objective = study.objective;
  switch (objective.form) {
    case Objective::Form::kMinimizeMaxOf: {
      if (!valid_output(objective.output)) {
        return LayoutError(study, "objective.minimize_max_of", "names no scene output");
      }
      if (objective.reduction != Reduction::kMax && objective.reduction != Reduction::kMaxAbs) {
        return LayoutError(study, "objective.reduction",
                           "minimize_max_of needs REDUCTION_MAX or REDUCTION_MAX_ABS");
      }
      layout.objective_form = ObjectiveForm::kMinMax;
      const OutputShape& shape = layout.outputs[static_cast<size_t>(objective.output)];
      for (int i = 0; i < shape.instants; ++i) {
        for (int s = 0; s < shape.series; ++s) {
          layout.objective_terms.push_back({objective.output, s, i, 1.0});
          if (objective.reduction == Reduction::kMaxAbs) {
            layout.objective_terms.push_back({objective.output, s, i, -1.0});
          }
        }
      }
      break;
    }
    case Objective::Form::kMinimize: {
      if (!valid_output(objective.output)) {
        return LayoutError(study, "objective.minimize", "names no scene output");
      }
      const OutputShape& shape = layout.outputs[static_cast<size_t>(objective.output)];
      if (shape.series != 1) {
        return LayoutError(
            study, "objective.minimize",
            absl::StrCat("output \"", scene.outputs[objective.output].name, "\" has ", shape.series,
                         " series; minimize needs a single value"));
      }
      layout.objective_form = ObjectiveForm::kScalar;
      layout.objective_terms.push_back({objective.output, 0, shape.instants - 1, 1.0});
      break;
    }
    case Objective::Form::kTargetDistance: {
      if (objective.terms.empty()) {
        return LayoutError(study, "objective.target_distance.terms", "needs at least one term");
      }
      for (size_t k = 0; k < objective.terms.size(); ++k) {
        const TargetTerm& term = objective.terms[k];
        if (!valid_output(term.output)) {
          return LayoutError(study, absl::StrCat("objective.target_distance.terms[", k, "]"),
                             "names no scene output");
        }
        if (layout.outputs[static_cast<size_t>(term.output)].series != 1) {
          return LayoutError(study, absl::StrCat("objective.target_distance.terms[", k, "]"),
                             "a target term needs a single-series output");
        }
      }
      layout.objective_form = ObjectiveForm::kScalar;
      break;
    }
  }

  const int decimals = TimeDecimals(layout.instants_s);
  for (size_t k = 0; k < study.constraints.size(); ++k) {
    const Constraint& constraint = study.constraints[k];
    if (!valid_output(constraint.output)) {
      return LayoutError(study, absl::StrCat("constraints[", k, "].output"),
                         "names no scene output");
    }
    const OutputShape& shape = layout.outputs[static_cast<size_t>(constraint.output)];
    const bool time_series =
        shape.instants > 1 || !std::holds_alternative<MassOutput>(
                                  scene.outputs[static_cast<size_t>(constraint.output)].kind);
    const double c = constraint.limit * constraint.si_per_unit;
    const int first = constraint.reduction == Reduction::kFinal ? shape.instants - 1 : 0;
    for (int i = first; i < shape.instants; ++i) {
      const double t = std::holds_alternative<MassOutput>(
                           scene.outputs[static_cast<size_t>(constraint.output)].kind)
                           ? 0.0
                           : layout.instants_s[static_cast<size_t>(i)];
      for (int s = 0; s < shape.series; ++s) {
        auto add = [&](double sign, double limit, const char* side) {
          ConstraintRow row;
          row.name = RowName(constraint.name, shape, s, time_series, t, decimals, side);
          row.constraint = static_cast<int>(k);
          row.value = {constraint.output, s, i, sign};
          row.limit_si = limit;
          row.scale = limit != 0.0 ? std::abs(limit) : 1.0;
          row.time_s = t;
          layout.rows.push_back(std::move(row));
        };
        switch (constraint.reduction) {
          case Reduction::kMax:
          case Reduction::kFinal:
            add(1.0, c, "upper");
            break;
          case Reduction::kMin:
            add(-1.0, -c, "lower");
            break;
          case Reduction::kMaxAbs:
            add(1.0, c, "upper");
            add(-1.0, c, "lower");
            break;
        }
      }
    }
  }
  return layout;
}

absl::StatusOr<StudyValues> ComputeStudyValues(
    const Study& study, const StudyLayout& layout,
    const std::vector<const std::vector<std::vector<double>>*>& outputs_si) {
  if (outputs_si.size() != layout.outputs.size()) {
    return absl::InvalidArgumentError(absl::StrCat("analysis has ", outputs_si.size(),
                                                   " outputs, the layout expects ",
                                                   layout.outputs.size()));
  }
  for (size_t o = 0; o < outputs_si.size(); ++o) {
    const auto* series = outputs_si[o];
    const OutputShape& shape = layout.outputs[o];
    bool ok = series != nullptr && static_cast<int>(series->size()) == shape.series;
    for (size_t s = 0; ok && s < series->size(); ++s) {
      ok = static_cast<int>((*series)[s].size()) == shape.instants;
    }
    if (!ok) {
      return absl::InvalidArgumentError(absl::StrCat(
          "output \"", study.scene.outputs[o].name, "\" does not have the layout's shape (",
          shape.series, " series of ", shape.instants, " values)"));
    }
  }
  auto value = [&](const ValueRef& ref) {
    return ref.sign *
           (*outputs_si[static_cast<size_t>(ref.output)])[static_cast<size_t>(ref.series)]
                                                         [static_cast<size_t>(ref.instant)];
  };

  StudyValues values;
  const Objective& objective = study.objective;
  if (objective.form == Objective::Form::kTargetDistance) {
    double sum = 0.0;
    for (const TargetTerm& term : objective.terms) {
      const auto& series = (*outputs_si[static_cast<size_t>(term.output)])[0];
      const double o = series.back() / term.si_per_unit;
      sum += term.weight * (o - term.target) * (o - term.target);
    }
    values.objective = std::sqrt(sum);
    values.objective_terms = {values.objective};
  } else {
    values.objective_terms.reserve(layout.objective_terms.size());
    for (const ValueRef& ref : layout.objective_terms) {
      values.objective_terms.push_back(value(ref) / objective.si_per_unit);
    }
    values.objective = -std::numeric_limits<double>::infinity();
    for (double term : values.objective_terms) {
      // A NaN term makes F NaN: it must not hide behind max().
      if (std::isnan(term) || term > values.objective) values.objective = term;
      if (std::isnan(values.objective)) break;
    }
  }

  values.constraint_values.reserve(layout.rows.size());
  values.max_violation = layout.rows.empty() ? 0.0 : -std::numeric_limits<double>::infinity();
  for (size_t h = 0; h < layout.rows.size(); ++h) {
    const ConstraintRow& row = layout.rows[h];
    const double g = value(row.value);
    values.constraint_values.push_back(g);
    const double normalized = (g - row.limit_si) / row.scale;
    if (values.worst_row < 0 || normalized > values.max_violation || std::isnan(normalized)) {
      if (!std::isnan(values.max_violation)) {
        values.max_violation = normalized;
        values.worst_row = static_cast<int>(h);
      }
    }
  }
  return values;
}

}  // namespace mbopt::spec
