#include "spec/layout.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/status_macros.h"
#include "spec/limits.h"
#include "spec/responses.h"

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


ValueRef At(int output, int series, int instant, double sign) {
  return ValueRef{output, series, instant, sign, Over::kInstant, instant, instant};
}

Over OverOf(Reduction r) {
  switch (r) {
    case Reduction::kRms: return Over::kRms;
    case Reduction::kIntegral: return Over::kIntegral;
    case Reduction::kRange: return Over::kRange;
    case Reduction::kMean: return Over::kMean;
    default: return Over::kInstant;
  }
}

// The value of a whole-series reduction (FINAL: the window's last instant).
ValueRef SeriesRef(int output, int series, Reduction reduction, const std::pair<int, int>& window) {
  ValueRef ref = At(output, series, window.second, 1.0);
  if (reduction != Reduction::kFinal) {
    ref.over = OverOf(reduction);
    ref.first = window.first;
    ref.last = window.second;
  }
  return ref;
}

// The grid instants inside `window`, as [first, last]; an error naming
// `field` when none is, or when the output has no time series.
absl::StatusOr<std::pair<int, int>> WindowInstants(const Study& study, const std::string& field, const TimeWindow& window,
                                                   const std::vector<double>& instants_s, bool scalar_output,
                                                   bool needs_series) {
  if (scalar_output) {
    if (!window.whole_grid() || needs_series) {
      return LayoutError(study, field, "a scalar output (mass, an external value) has no time series to window or reduce");
    }
    return std::pair<int, int>{0, 0};
  }
  const double span = instants_s.empty() ? 0.0 : instants_s.back() - instants_s.front();
  const double slack = 1e-9 * std::max(span, 1e-300);  // instants are computed, limits typed
  int first = -1, last = -1;
  for (int i = 0; i < static_cast<int>(instants_s.size()); ++i) {
    const double t = instants_s[static_cast<size_t>(i)];
    if (window.from_s && t < *window.from_s - slack) continue;
    if (window.to_s && t > *window.to_s + slack) continue;
    if (first < 0) first = i;
    last = i;
  }
  if (first < 0) {
    return LayoutError(study, field + ".window",
                       absl::StrFormat("holds no instant of the time grid (%g s to %g s)",
                                       instants_s.empty() ? 0.0 : instants_s.front(),
                                       instants_s.empty() ? 0.0 : instants_s.back()));
  }
  return std::pair<int, int>{first, last};
}

}  // namespace

double RefValue(const ValueRef& ref, const std::vector<double>& f, const std::vector<double>& t,
                std::vector<double>* weights) {
  const size_t first = static_cast<size_t>(ref.over == Over::kInstant ? ref.instant : ref.first);
  const size_t last = static_cast<size_t>(ref.over == Over::kInstant ? ref.instant : ref.last);
  const size_t count = last - first + 1;
  if (weights != nullptr) weights->assign(count, 0.0);
  double value = 0.0;
  switch (ref.over) {
    case Over::kInstant:
      value = f[first];
      if (weights != nullptr) (*weights)[0] = 1.0;
      break;
    case Over::kMean:
      for (size_t i = first; i <= last; ++i) value += f[i];
      value /= static_cast<double>(count);
      if (weights != nullptr) weights->assign(count, 1.0 / static_cast<double>(count));
      break;
    case Over::kRms: {
      double sum = 0.0;
      for (size_t i = first; i <= last; ++i) sum += f[i] * f[i];
      value = std::sqrt(sum / static_cast<double>(count));
      if (weights != nullptr && value > 0.0) {
        for (size_t i = first; i <= last; ++i) (*weights)[i - first] = f[i] / (static_cast<double>(count) * value);
      }
      break;
    }
    case Over::kIntegral:
      for (size_t i = first; i < last; ++i) {
        const double h = t[i + 1] - t[i];
        value += 0.5 * h * (f[i] + f[i + 1]);
        if (weights != nullptr) {
          (*weights)[i - first] += 0.5 * h;
          (*weights)[i + 1 - first] += 0.5 * h;
        }
      }
      break;
    case Over::kRange: {
      size_t hi = first, lo = first;
      for (size_t i = first; i <= last; ++i) {
        if (f[i] > f[hi]) hi = i;
        if (f[i] < f[lo]) lo = i;
      }
      value = f[hi] - f[lo];
      if (weights != nullptr && hi != lo) {
        (*weights)[hi - first] = 1.0;
        (*weights)[lo - first] = -1.0;
      }
      break;
    }
  }
  if (weights != nullptr) {
    for (double& w : *weights) w *= ref.sign;
  }
  return ref.sign * value;
}

Dimension SignalDimension(const Study& study, int signal) {
  if (signal < 0 || signal >= study.num_signals()) return Dimension::kAny;
  if (signal >= study.num_case_signals()) {
    return study.responses[static_cast<size_t>(signal - study.num_case_signals())].dimension;
  }
  return OutputDimension(study.scene.outputs[static_cast<size_t>(signal) % study.scene.outputs.size()]);
}

namespace {

// A value's unit as reported: as written, else SI by its dimension; an
// integral over time carries an extra s.
std::string ValueUnit(const Study& study, const std::string& unit, int signal, Reduction reduction) {
  std::string text = unit.empty() ? SiUnitName(SignalDimension(study, signal)) : unit;
  if (reduction == Reduction::kIntegral) text = text.empty() ? "s" : text + " s";
  return text;
}

}  // namespace

std::string ReportedObjectiveUnit(const Study& study) {
  const Objective& o = study.objective;
  std::vector<std::string> units;
  switch (o.form) {
    case Objective::Form::kMinimizeMaxOf:
    case Objective::Form::kMinimize:
      return ValueUnit(study, o.unit, o.output, o.reduction);
    case Objective::Form::kWeightedSum:
    case Objective::Form::kMaxOver:
      for (const WeightedTerm& t : o.sum_terms) units.push_back(ValueUnit(study, t.unit, t.output, t.reduction));
      break;
    case Objective::Form::kTargetDistance:
      for (const TargetTerm& t : o.terms) units.push_back(ValueUnit(study, t.unit, t.output, Reduction::kFinal));
      break;
    case Objective::Form::kFeasible:
      return "";
  }
  if (units.empty()) return "";
  for (const std::string& unit : units) {
    if (unit != units.front()) return "";
  }
  return units.front();
}

double EqualityRowScale(const Constraint& constraint) {
  const double value_si = std::abs(constraint.equals.value_or(0.0) * constraint.si_per_unit);
  const double half_band_si =
      constraint.lower && constraint.upper ? 0.5 * (*constraint.upper - *constraint.lower) * constraint.si_per_unit : 0.0;
  return std::max({value_si, std::abs(constraint.si_per_unit), half_band_si});
}

OutputShape OutputShapeOf(const Scene& scene, int output) {
  OutputShape shape;
  const Output& out = scene.outputs[static_cast<size_t>(output)];
  const auto* external = std::get_if<ExternalResultOutput>(&out.kind);
  shape.scalar = std::holds_alternative<MassOutput>(out.kind) || (external != nullptr && !external->series);
  shape.instants = shape.scalar ? 1 : static_cast<int>(scene.time_grid.Instants().size());
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
                        [](const BodyAccelerationOutput& b) {
                          using Q = BodyAccelerationOutput::Quantity;
                          return b.quantity == Q::kDisplacement ? Dimension::kLength
                                 : b.quantity == Q::kVelocity   ? Dimension::kVelocity
                                                                : Dimension::kAcceleration;
                        },
                        [](const BendingStressOutput&) { return Dimension::kPressure; },
                        [](const DriveTorqueOutput&) { return Dimension::kTorque; },
                        [](const MassOutput&) { return Dimension::kMass; },
                        // The driver's own SI quantity, unknown here.
                        [](const ExternalResultOutput&) { return Dimension::kAny; },
                        // The FMU's own units, unknown here: a limit is written in SI.
                        [](const FmuVariableOutput&) { return Dimension::kAny; },
                        [](const SpatialOutput& s) {
                          using Q = SpatialOutput::Quantity;
                          switch (s.quantity) {
                            case Q::kMarkerPosition: return Dimension::kLength;
                            case Q::kMarkerVelocity: return Dimension::kVelocity;
                            case Q::kMarkerAcceleration: return Dimension::kAcceleration;
                            case Q::kBodyOrientation: return Dimension::kAngle;
                            case Q::kJointCoordinate: return s.linear ? Dimension::kLength : Dimension::kAngle;
                            case Q::kJointRate: return s.linear ? Dimension::kVelocity : Dimension::kAngularVelocity;
                            case Q::kJointSlide: return Dimension::kLength;
                            case Q::kJointSlideRate: return Dimension::kVelocity;
                            case Q::kSpringLength: return Dimension::kLength;
                            case Q::kSpringForce: return Dimension::kForce;
                            case Q::kKineticEnergy:
                            case Q::kPotentialEnergy: return Dimension::kEnergy;
                            case Q::kBodyAngularVelocity: return Dimension::kAngularVelocity;
                            case Q::kJointReaction:
                            case Q::kBushingForce: return Dimension::kForce;
                            case Q::kDriverEffort: return s.linear ? Dimension::kForce : Dimension::kTorque;
                            case Q::kJointReactionMoment:
                            case Q::kBushingMoment:
                            case Q::kRotationalSpringTorque: return Dimension::kTorque;
                          }
                          return Dimension::kAny;
                        },
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
                            case Q::kPotentialEnergy: return Dimension::kEnergy;
                          }
                          return Dimension::kAny;
                        },
                    },
                    output.kind);
}

namespace {

// The shapes of every signal; a response whose reads disagree gets the shape
// of the last one (MakeStudyLayout refuses it).
std::vector<OutputShape> SignalShapes(const Study& study, std::vector<std::string>* errors) {
  const Scene& scene = study.scene;
  std::vector<OutputShape> shapes;
  for (int c = 0; c < study.num_cases(); ++c) {
    for (size_t o = 0; o < scene.outputs.size(); ++o) shapes.push_back(OutputShapeOf(scene, static_cast<int>(o)));
  }
  const int instants = static_cast<int>(scene.time_grid.Instants().size());
  for (size_t r = 0; r < study.responses.size(); ++r) {
    absl::StatusOr<OutputShape> shape = ResponseShape(study, static_cast<int>(r), shapes, instants);
    if (!shape.ok()) {
      if (errors != nullptr) errors->push_back(std::string(shape.status().message()));
      shape = OutputShape{1, instants, {study.responses[r].name}, false};
    }
    shapes.push_back(*std::move(shape));
  }
  return shapes;
}

}  // namespace

StudyFootprint EstimateStudyFootprint(const Study& study) {
  const std::vector<OutputShape> shapes = SignalShapes(study, nullptr);
  const int num_signals = static_cast<int>(shapes.size());
  auto values = [&](int output) -> std::int64_t {
    if (output < 0 || output >= num_signals) return 0;
    const OutputShape& shape = shapes[static_cast<size_t>(output)];
    return static_cast<std::int64_t>(shape.series) * shape.instants;
  };
  StudyFootprint f;
  const Objective& objective = study.objective;
  f.objective_terms = objective.form == Objective::Form::kMinimizeMaxOf
                          ? values(objective.output) * (objective.reduction == Reduction::kMaxAbs ? 2 : 1)
                          : 1;
  if (objective.form == Objective::Form::kMaxOver || objective.form == Objective::Form::kWeightedSum) {
    f.objective_terms = 0;
    for (const WeightedTerm& term : objective.sum_terms) {
      f.objective_terms += IsWholeSeriesReduction(term.reduction)
                               ? 1
                               : values(term.output) * (term.reduction == Reduction::kMaxAbs ? 2 : 1);
    }
  }
  // Each row's name holds its constraint's name (docs/study.md, "Limits").
  std::int64_t row_name_bytes = 0;
  for (const Constraint& c : study.constraints) {
    const std::int64_t all = values(c.output);
    const std::int64_t series = c.output >= 0 && c.output < num_signals ? shapes[static_cast<size_t>(c.output)].series : 0;
    const std::int64_t before = f.constraint_rows;
    if (IsWholeSeriesReduction(c.reduction)) {
      f.constraint_rows += series * std::max(1, (c.upper ? 1 : 0) + (c.lower ? 1 : 0));
    } else {
      f.constraint_rows += c.reduction == Reduction::kMaxAbs ? 2 * all : all;
    }
    row_name_bytes += (f.constraint_rows - before) * static_cast<std::int64_t>(c.name.size());
  }
  const std::int64_t n = static_cast<std::int64_t>(study.variables.size());
  const std::int64_t per_value = 8 * ((n + 1)            // x0's and the perturbations' values
                                      + n                // the linearization's gradient
                                      + 5 * (n + 2) / 2) // the dense LP row and the solver's copy
                                 + 120;                  // the row's layout entry and the
                                                         // name's instant and node
  std::int64_t series_values = 0;
  for (int signal = 0; signal < num_signals; ++signal) series_values += values(signal);
  f.series_bytes = 8 * series_values * (study.optimizer.simulator_sensitivities ? n + 1 : 1);
  if (const auto* fmu = std::get_if<FmuModel>(&study.scene.model); fmu != nullptr && fmu->archive != nullptr) {
    f.archive_bytes = static_cast<std::int64_t>(fmu->archive->size());
  }
  f.memory_bytes =
      (f.objective_terms + f.constraint_rows) * per_value + row_name_bytes + f.series_bytes + f.archive_bytes;
  return f;
}

namespace {

// The rows of a Pareto front's second objective (StudyLayout::
// second_objective_factors), laid out as the study's objective would be
// were it the second: a study that is the same but for its objective, and
// without constraints or front, gives the terms, which become rows.
absl::Status AppendSecondObjectiveRows(const Study& study, StudyLayout* layout) {
  Study alone = study;
  alone.objective = study.second_objective;
  alone.constraints.clear();
  alone.pareto = Pareto{};
  alone.design_set = DesignSet{};
  absl::StatusOr<StudyLayout> laid = MakeStudyLayout(alone);
  if (!laid.ok()) {
    // Its errors name the study's objective's fields; they are the front's.
    const std::string prefix = absl::StrCat(study.source_file.empty() ? "study" : study.source_file, ": ");
    std::string what(laid.status().message());
    if (absl::StartsWith(what, prefix)) what = what.substr(prefix.size());
    return LayoutError(study, "pareto." + what.substr(0, what.find(": ")),
                       what.find(": ") == std::string::npos ? what : what.substr(what.find(": ") + 2));
  }
  std::vector<ValueRef> refs;
  std::vector<double> factors;
  const Objective& second = study.second_objective;
  if (laid->objective_form == ObjectiveForm::kMinMax) {
    refs = laid->objective_terms;
    factors = laid->objective_term_factors;
  } else if (laid->objective_form == ObjectiveForm::kScalar && second.form == Objective::Form::kWeightedSum) {
    refs = laid->sum_refs;
    for (const WeightedTerm& term : second.sum_terms) factors.push_back(term.weight / term.si_per_unit);
    layout->second_objective_sums = true;
  } else if (laid->objective_form == ObjectiveForm::kScalar && second.form == Objective::Form::kMinimize) {
    refs = laid->objective_terms;
    factors = laid->objective_term_factors;
  } else {
    return LayoutError(study, "pareto.objective",
                       "a second objective is a largest of values or a sum of one-value terms (not a distance to "
                       "targets, nor a sum of peaks)");
  }
  for (size_t k = 0; k < refs.size(); ++k) {
    ValueRef ref = refs[k];
    double factor = factors[k];
    // A largest of values is bounded row by row, factor * g <= level, so a
    // factor below 0 (maximize) is folded into the row's sign.
    if (!layout->second_objective_sums && factor < 0) {
      ref.sign = -ref.sign;
      factor = -factor;
    }
    ConstraintRow row;
    row.name = absl::StrCat("second objective[", k, "]");
    row.constraint = kSecondObjectiveRow;
    row.value = ref;
    row.limit_si = 0;
    row.scale = 1;
    const auto instant = static_cast<size_t>(std::clamp(ref.instant, 0, static_cast<int>(layout->instants_s.size()) - 1));
    row.time_s = layout->instants_s.empty() ? 0.0 : layout->instants_s[instant];
    layout->rows.push_back(std::move(row));
    layout->second_objective_factors.push_back(factor);
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<StudyLayout> MakeStudyLayout(const Study& study) {
  const Scene& scene = study.scene;
  const StudyFootprint f = EstimateStudyFootprint(study);
  if (f.memory_bytes > kMaxStudyMemoryBytes) {
    return LayoutError(
        study, "constraints",
        absl::StrFormat("the study needs about %.1f GB of memory for its %d objective terms and %d constraint rows "
                        "with %d variables and %.1f GB of series (outputs of every load case, responses), more "
                        "than the limit of %.0f GB; use fewer time points (analysis.time_grid_points), fewer "
                        "constraints on time series, or fewer load cases and responses",
                        static_cast<double>(f.memory_bytes) / 1e9, f.objective_terms, f.constraint_rows,
                        study.variables.size(), static_cast<double>(f.series_bytes) / 1e9,
                        static_cast<double>(kMaxStudyMemoryBytes) / (1 << 30)));
  }
  StudyLayout layout;
  // A million rows grown by doubling would hold about twice their memory at
  // the last step; the estimate is their number or more (trimmed below).
  layout.rows.reserve(static_cast<size_t>(f.constraint_rows));
  layout.objective_terms.reserve(static_cast<size_t>(f.objective_terms));
  layout.instants_s = scene.time_grid.Instants();
  std::vector<std::string> shape_errors;
  layout.outputs = SignalShapes(study, &shape_errors);
  if (!shape_errors.empty()) return LayoutError(study, "responses", shape_errors.front());
  const int num_signals = study.num_signals();
  auto valid_output = [&](int o) { return o >= 0 && o < num_signals; };
  auto scalar = [&](int o) { return layout.outputs[static_cast<size_t>(o)].scalar; };

  const Objective& objective = study.objective;
  switch (objective.form) {
    case Objective::Form::kMinimizeMaxOf: {
      if (!valid_output(objective.output)) {
        return LayoutError(study, "objective.minimize_max_of", "names no scene output or response");
      }
      if (objective.reduction != Reduction::kMax && objective.reduction != Reduction::kMaxAbs) {
        return LayoutError(study, "objective.reduction",
                           "minimize_max_of needs REDUCTION_MAX or REDUCTION_MAX_ABS");
      }
      layout.objective_form = ObjectiveForm::kMinMax;
      const OutputShape& shape = layout.outputs[static_cast<size_t>(objective.output)];
      MBOPT_ASSIGN_OR_RETURN(const auto window,
                             WindowInstants(study, "objective", objective.window, layout.instants_s,
                                            scalar(objective.output), false));
      for (int i = window.first; i <= window.second; ++i) {
        for (int s = 0; s < shape.series; ++s) {
          layout.objective_terms.push_back(At(objective.output, s, i, 1.0));
          if (objective.reduction == Reduction::kMaxAbs) {
            layout.objective_terms.push_back(At(objective.output, s, i, -1.0));
          }
        }
      }
      break;
    }
    case Objective::Form::kMinimize: {
      if (!valid_output(objective.output)) {
        return LayoutError(study, objective.maximize ? "objective.maximize" : "objective.minimize",
                           "names no scene output or response");
      }
      const OutputShape& shape = layout.outputs[static_cast<size_t>(objective.output)];
      if (shape.series != 1) {
        return LayoutError(
            study, "objective.minimize",
            absl::StrCat("output \"", study.SignalName(objective.output), "\" has ", shape.series,
                         " series; minimize needs a single value"));
      }
      layout.objective_form = ObjectiveForm::kScalar;
      const bool reduced = objective.reduction != Reduction::kFinal;
      MBOPT_ASSIGN_OR_RETURN(const auto window,
                             WindowInstants(study, "objective", objective.window, layout.instants_s,
                                            scalar(objective.output), reduced));
      layout.objective_terms.push_back(SeriesRef(objective.output, 0, objective.reduction, window));
      break;
    }
    case Objective::Form::kWeightedSum: {
      if (objective.sum_terms.empty()) {
        return LayoutError(study, "objective.minimize_sum.terms", "needs at least one term");
      }
      const bool peaks = std::any_of(objective.sum_terms.begin(), objective.sum_terms.end(),
                                     [](const WeightedTerm& t) { return IsPeakReduction(t.reduction); });
      for (size_t k = 0; k < objective.sum_terms.size(); ++k) {
        const WeightedTerm& term = objective.sum_terms[k];
        const std::string field = absl::StrCat("objective.minimize_sum.terms[", k, "]");
        if (!valid_output(term.output)) return LayoutError(study, field, "names no scene output or response");
        const OutputShape& shape = layout.outputs[static_cast<size_t>(term.output)];
        const bool peak = IsPeakReduction(term.reduction);
        if (!peak && shape.series != 1) return LayoutError(study, field, "a term needs a single-series output");
        const bool reduced = !peak && term.reduction != Reduction::kFinal;
        MBOPT_ASSIGN_OR_RETURN(const auto window, WindowInstants(study, field, term.window, layout.instants_s,
                                                                 scalar(term.output), reduced));
        if (!peaks) {
          layout.sum_refs.push_back(SeriesRef(term.output, 0, term.reduction, window));
          continue;
        }
        // A sum with peaks: each term is a group of the min-max terms whose
        // largest is its value (study.h, IsPeakReduction).
        const size_t before = layout.objective_terms.size();
        if (!peak) {
          layout.objective_terms.push_back(SeriesRef(term.output, 0, term.reduction, window));
          layout.objective_term_factors.push_back(term.weight / term.si_per_unit);
        } else {
          const double sign = term.reduction == Reduction::kMin ? -1.0 : 1.0;
          for (int i = window.first; i <= window.second; ++i) {
            for (int s = 0; s < shape.series; ++s) {
              layout.objective_terms.push_back(At(term.output, s, i, sign));
              if (term.reduction == Reduction::kMaxAbs) layout.objective_terms.push_back(At(term.output, s, i, -1.0));
            }
          }
          layout.objective_term_factors.resize(layout.objective_terms.size(),
                                               std::abs(term.weight) / term.si_per_unit);
        }
        layout.objective_group_sizes.push_back(static_cast<int>(layout.objective_terms.size() - before));
      }
      layout.objective_form = peaks ? ObjectiveForm::kSumOfMax : ObjectiveForm::kScalar;
      break;
    }
    case Objective::Form::kMaxOver: {
      if (objective.sum_terms.empty()) {
        return LayoutError(study, "objective.minimize_max_over.terms", "needs at least one term");
      }
      for (size_t k = 0; k < objective.sum_terms.size(); ++k) {
        const WeightedTerm& term = objective.sum_terms[k];
        const std::string field = absl::StrCat("objective.minimize_max_over.terms[", k, "]");
        if (!valid_output(term.output)) return LayoutError(study, field, "names no scene output or response");
        const OutputShape& shape = layout.outputs[static_cast<size_t>(term.output)];
        const double factor = term.weight / term.si_per_unit;
        const bool whole = IsWholeSeriesReduction(term.reduction);
        MBOPT_ASSIGN_OR_RETURN(
            const auto window, WindowInstants(study, field, term.window, layout.instants_s, scalar(term.output),
                                              whole && term.reduction != Reduction::kFinal));
        for (int s = 0; s < shape.series; ++s) {
          if (whole) {
            layout.objective_terms.push_back(SeriesRef(term.output, s, term.reduction, window));
            layout.objective_term_factors.push_back(factor);
            continue;
          }
          for (int i = window.first; i <= window.second; ++i) {
            layout.objective_terms.push_back(At(term.output, s, i, 1.0));
            layout.objective_term_factors.push_back(factor);
            if (term.reduction == Reduction::kMaxAbs) {
              layout.objective_terms.push_back(At(term.output, s, i, -1.0));
              layout.objective_term_factors.push_back(factor);
            }
          }
        }
      }
      layout.objective_form = ObjectiveForm::kMinMax;
      break;
    }
    case Objective::Form::kFeasible:
      // One constant term (F = 0); without a constraint there is nothing to find.
      if (study.constraints.empty()) {
        return LayoutError(study, "objective",
                           "a study without an objective finds a design that meets its constraints, and it has "
                           "none: add constraints, or an objective");
      }
      layout.objective_form = ObjectiveForm::kScalar;
      break;
    case Objective::Form::kTargetDistance: {
      if (objective.terms.empty()) {
        return LayoutError(study, "objective.target_distance.terms", "needs at least one term");
      }
      for (size_t k = 0; k < objective.terms.size(); ++k) {
        const TargetTerm& term = objective.terms[k];
        if (!valid_output(term.output)) {
          return LayoutError(study, absl::StrCat("objective.target_distance.terms[", k, "]"),
                             "names no scene output or response");
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

  if (objective.form == Objective::Form::kMinimizeMaxOf || objective.form == Objective::Form::kMinimize) {
    layout.objective_term_factors.assign(layout.objective_terms.size(),
                                         objective.ReportedSign() / objective.si_per_unit);
  }

  const int decimals = TimeDecimals(layout.instants_s);
  for (size_t k = 0; k < study.constraints.size(); ++k) {
    const Constraint& constraint = study.constraints[k];
    if (!valid_output(constraint.output)) {
      return LayoutError(study, absl::StrCat("constraints[", k, "].output"),
                         "names no scene output or response");
    }
    const OutputShape& shape = layout.outputs[static_cast<size_t>(constraint.output)];
    const bool scalar_output = scalar(constraint.output);
    const std::string field = absl::StrCat("constraints[", k, "]");
    const bool reduced = IsWholeSeriesReduction(constraint.reduction) && constraint.reduction != Reduction::kFinal;
    MBOPT_ASSIGN_OR_RETURN(const auto window, WindowInstants(study, field, constraint.window, layout.instants_s,
                                                             scalar_output, reduced));
    const bool equality = constraint.equals.has_value();
    const double equality_scale = equality ? EqualityRowScale(constraint) : 1.0;
    auto add = [&](ValueRef value, double limit, const std::string& name, double t) {
      ConstraintRow row;
      row.name = name;
      row.constraint = static_cast<int>(k);
      row.value = value;
      row.limit_si = limit;
      row.scale = equality ? equality_scale : limit != 0.0 ? std::abs(limit) : 1.0;
      row.time_s = t;
      layout.rows.push_back(std::move(row));
    };
    if (IsWholeSeriesReduction(constraint.reduction)) {
      // One value per series, bounded from either side.
      const double t = scalar_output ? 0.0 : layout.instants_s[static_cast<size_t>(window.second)];
      for (int s = 0; s < shape.series; ++s) {
        ValueRef ref = SeriesRef(constraint.output, s, constraint.reduction, window);
        auto name = [&](const char* side) {
          if (!reduced) {  // FINAL: named by its instant, like the rows of an instant
            return RowName(constraint.name, shape, s, !scalar_output || shape.instants > 1, t, decimals, side);
          }
          return (shape.series > 1 ? absl::StrCat(constraint.name, "[", shape.series_labels[s], "]")
                                   : constraint.name) +
                 " " + side;
        };
        // Neither bound given: `limit` from above, as FINAL always had it.
        std::optional<double> upper =
            constraint.upper || constraint.lower ? constraint.upper : std::optional<double>(constraint.limit);
        std::optional<double> lower = constraint.lower;
        if (equality && upper && lower) {
          // The rows hold the middle half of the band; the other half is the
          // violation a converged design may keep (SlpOptionsFromStudy), so
          // that a converged design lies inside the band as written.
          const double quarter_band = 0.25 * (*upper - *lower);
          upper = *constraint.equals + quarter_band;
          lower = *constraint.equals - quarter_band;
        }
        if (upper) add(ref, *upper * constraint.si_per_unit, name("upper"), t);
        if (lower) {
          ref.sign = -1.0;
          add(ref, -*lower * constraint.si_per_unit, name("lower"), t);
        }
      }
      continue;
    }
    const double c = constraint.limit * constraint.si_per_unit;
    for (int i = window.first; i <= window.second; ++i) {
      const double t = scalar_output ? 0.0 : layout.instants_s[static_cast<size_t>(i)];
      for (int s = 0; s < shape.series; ++s) {
        auto name = [&](const char* side) {
          return RowName(constraint.name, shape, s, !scalar_output || shape.instants > 1, t, decimals, side);
        };
        switch (constraint.reduction) {
          case Reduction::kMax:
            add(At(constraint.output, s, i, 1.0), c, name("upper"), t);
            break;
          case Reduction::kMin:
            add(At(constraint.output, s, i, -1.0), -c, name("lower"), t);
            break;
          case Reduction::kMaxAbs:
            add(At(constraint.output, s, i, 1.0), c, name("upper"), t);
            add(At(constraint.output, s, i, -1.0), c, name("lower"), t);
            break;
          default:
            break;
        }
      }
    }
  }
  if (study.pareto.trades_objective) MBOPT_RETURN_IF_ERROR(AppendSecondObjectiveRows(study, &layout));
  if (layout.rows.capacity() > layout.rows.size() + layout.rows.size() / 4) layout.rows.shrink_to_fit();
  if (layout.objective_terms.capacity() > layout.objective_terms.size() + layout.objective_terms.size() / 4) {
    layout.objective_terms.shrink_to_fit();
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
          "output \"", study.SignalName(static_cast<int>(o)), "\" does not have the layout's shape (",
          shape.series, " series of ", shape.instants, " values)"));
    }
  }
  auto value = [&](const ValueRef& ref) {
    return RefValue(ref, (*outputs_si[static_cast<size_t>(ref.output)])[static_cast<size_t>(ref.series)],
                    layout.instants_s);
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
  } else if (objective.form == Objective::Form::kFeasible) {
    values.objective = 0.0;
    values.objective_terms = {0.0};
  } else if (objective.form == Objective::Form::kWeightedSum && layout.objective_form == ObjectiveForm::kScalar) {
    double sum = 0.0;
    for (size_t k = 0; k < objective.sum_terms.size(); ++k) {
      const WeightedTerm& term = objective.sum_terms[k];
      sum += term.weight * value(layout.sum_refs[k]) / term.si_per_unit;
    }
    values.objective = sum;
    values.objective_terms = {sum};
  } else {
    values.objective_terms.reserve(layout.objective_terms.size());
    for (size_t k = 0; k < layout.objective_terms.size(); ++k) {
      values.objective_terms.push_back(value(layout.objective_terms[k]) * layout.objective_term_factors[k]);
    }
    // F: the largest term, or with groups the sum of each group's largest.
    const std::vector<int> one_group = {static_cast<int>(values.objective_terms.size())};
    const std::vector<int>& groups = layout.objective_group_sizes.empty() ? one_group : layout.objective_group_sizes;
    values.objective = 0.0;
    size_t next = 0;
    for (int size : groups) {
      double group_max = -std::numeric_limits<double>::infinity();
      for (int k = 0; k < size; ++k, ++next) {
        const double term = values.objective_terms[next];
        // A NaN term makes F NaN: it must not hide behind max().
        if (!std::isnan(group_max) && (std::isnan(term) || term > group_max)) group_max = term;
      }
      values.objective = groups.size() == 1 ? group_max : values.objective + group_max;
    }
  }

  values.constraint_values.reserve(layout.rows.size());
  const bool bounded = std::any_of(layout.rows.begin(), layout.rows.end(),
                                   [](const ConstraintRow& row) { return row.constraint >= 0; });
  values.max_violation = bounded ? -std::numeric_limits<double>::infinity() : 0.0;
  for (size_t h = 0; h < layout.rows.size(); ++h) {
    const ConstraintRow& row = layout.rows[h];
    const double g = value(row.value);
    values.constraint_values.push_back(g);
    // A second objective's row has no limit of the study's: only a front's
    // points bound it, each at its own level.
    if (row.constraint < 0) continue;
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
