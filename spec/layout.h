// The optimization layout of a study: how the outputs of one analysis become
// the objective terms and the one-sided constraint rows g_h <= c_h that the
// SLP core sees. Computed from the study alone (no analysis needed), so the
// server can build its problem before any worker has run; and applied to an
// analysis' outputs by ComputeStudyValues.
//
// Conventions (also in docs/study.md):
//  - Shapes: every output has `series` time series (a bending-stress output
//    has one per stress node, see OutputShapeOf) of `instants` values: the
//    grid's points, or 1 for a scalar output (mass).
//  - Objective, minimize_max_of: min-max form. Terms, instant-major and then
//    series: MAX gives f(t_i); MAX_ABS gives f(t_i) and -f(t_i) (two terms
//    per instant and series). F = max of the terms.
//  - Objective, minimize: scalar form, one term: the final value of the
//    output (its only value for a scalar output); the output must have one
//    series.
//  - Objective, target_distance: scalar form, one term:
//    F = sqrt(sum_k w_k (o_k(final) / unit_k - target_k)^2).
//  - No objective (a study that finds a feasible design): scalar form, one
//    term, F = 0 at every design.
//  - Objective values (terms and F) are reported in objective.unit, except
//    target_distance, whose F is in the terms' own units.
//  - Constraint rows, for every instant (instant-major, then series):
//    MAX: f <= c ("upper"); MIN: -f <= -c ("lower"); MAX_ABS: f <= c
//    ("upper") and -f <= c ("lower"); FINAL: f(t_last) <= c ("upper").
//    g and c are SI; scale = |c| (1 when c = 0), so the normalized value
//    (g - c) / scale is docs/method.md's g/c - 1. The two rows of an
//    equality (`equals: v tolerance: t`) are scaled by the size of the
//    value instead (EqualityRowScale), so a narrow band is a tight limit on
//    the quantity, not a violation of thousands of band widths, and hold
//    the band's middle half, v -+ t/2 (the outer quarters are the violation
//    a converged design may keep, jobs::SlpOptionsFromStudy).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/study.h"
#include "spec/units.h"

namespace mbopt::spec {

struct OutputShape {
  int series = 1;
  int instants = 1;
  std::vector<std::string> series_labels;  // one per series
  bool scalar = false;  // one value per analysis (mass), not a time series
};

// What the engine produces for scene output `output`. Bending stress: the
// link's stations are the nodes of its beam elements (flexible.elements
// elements, or 6 for a rigid link), numbered 0..n from joint_a; a series is
// reported for every node where the moment is not zero by a pin: interior
// nodes, plus the end at the driver's pivot when the link is the driven one
// (clamped to the drive). Labels are "node j".
OutputShape OutputShapeOf(const Scene& scene, int output);

// Number of stress stations (elements) of a rigid link; see OutputShapeOf.
inline constexpr int kRigidLinkStressElements = 6;

// The physical dimension of an output's values (for unit checks).
Dimension OutputDimension(const Output& output);

// The dimension of a signal (Study::SignalName): its output's, or the one
// its response's `unit` gives; kAny when not known.
Dimension SignalDimension(const Study& study, int signal);

// The unit the objective's value F is reported in: the objective's `unit`,
// else the SI unit of its output's dimension ("" for a dimensionless or
// unknown one, never a bare "SI"); with several terms (a weighted sum, the
// largest of several, a distance to targets) their unit when every term
// has the same one, else "". An INTEGRAL is in that unit times s. "" for a
// study without an objective.
std::string ReportedObjectiveUnit(const Study& study);

// kSumOfMax: F = sum over groups of the group's largest term (a weighted sum
// with peaks; StudyLayout::objective_group_sizes).
enum class ObjectiveForm { kScalar, kMinMax, kSumOfMax };

// A reference to one value of an analysis: output, series, sign, and either
// one instant or a reduction of the series over the instants [first, last].
enum class Over { kInstant, kRms, kIntegral, kRange, kMean };
struct ValueRef {
  int output = -1;
  int series = 0;
  int instant = 0;  // kInstant; otherwise `last` (the time a row is shown at)
  double sign = 1.0;
  Over over = Over::kInstant;
  int first = 0;
  int last = 0;
};

// The value `ref` takes on `series` (one output series, SI) with the grid's
// `instants_s`; with `weights`, also d value / d series[first + k] for k in
// [0, last - first] (RANGE: +1 at the first maximum, -1 at the first
// minimum; RMS of all zeros: 0).
double RefValue(const ValueRef& ref, const std::vector<double>& series, const std::vector<double>& instants_s,
                std::vector<double>* weights = nullptr);

// ConstraintRow::constraint of the rows of a Pareto front's second
// objective (StudyLayout::second_objective_factors).
inline constexpr int kSecondObjectiveRow = -2;

struct ConstraintRow {
  std::string name;     // e.g. "s1@t=1.750s upper"
  // Index into study.constraints; kSecondObjectiveRow for a row of a
  // Pareto front's second objective, which has no limit of the study's
  // (limit_si 0, scale 1, left out of StudyValues::max_violation).
  int constraint = -1;
  ValueRef value;       // g_h = sign * f, or sign * a reduction of f (SI)
  double limit_si = 0;  // c_h
  double scale = 1;     // > 0
  double time_s = 0;    // the instant (0 for scalar outputs)
};

// The scale of both rows of an equality constraint, SI: the size of the
// value held, |v|, with floors for a value at or near zero: one of the
// constraint's unit (1 SI without a unit), and the band's half-width t.
// Scaling by the bounds v -+ t instead makes the normalized violation of a
// band around 0 count in band widths: with t = 1e-5 a start 0.02 away is
// 2,000 times over, every trial is rejected and the move limits collapse.
double EqualityRowScale(const Constraint& constraint);

struct StudyLayout {
  ObjectiveForm objective_form = ObjectiveForm::kScalar;
  // kMinMax: one per term. kScalar with minimize: the one value. kScalar
  // with target_distance: empty (the term combines several outputs); with
  // no objective: empty (F = 0).
  std::vector<ValueRef> objective_terms;
  // kMinMax, kSumOfMax and minimize: one per objective term, the factor from
  // its SI value to the term (1 / unit, and a kMaxOver or kSumOfMax term's
  // weight; |weight| for a minimum with a negative weight).
  std::vector<double> objective_term_factors;
  // kScalar with minimize_sum: one per term of study.objective.sum_terms.
  std::vector<ValueRef> sum_refs;
  // kSumOfMax: one group per term of study.objective.sum_terms, in order: the
  // number of objective_terms whose largest is that term's value (1 for a
  // whole-series term, the window's instants and series for a peak).
  std::vector<int> objective_group_sizes;
  std::vector<ConstraintRow> rows;
  // A Pareto front's second objective (Study::pareto.trades_objective): the
  // last rows of `rows`, one factor each, the second objective being
  // F2 = sum_h factor_h * g_h (second_objective_sums: a weighted sum of
  // one-value terms) or F2 = max_h factor_h * g_h (every other form; then
  // each factor is > 0, a maximized value's row has sign -1), in the
  // objective's unit. Empty for other studies.
  std::vector<double> second_objective_factors;
  bool second_objective_sums = false;
  // One per signal: the scene's outputs, then the study's responses.
  std::vector<OutputShape> outputs;
  std::vector<double> instants_s;    // the grid

  int num_objective_terms() const {
    return objective_form == ObjectiveForm::kScalar ? 1 : static_cast<int>(objective_terms.size());
  }
  int num_constraints() const { return static_cast<int>(rows.size()); }
};

// What laying a study out will cost, counted from its shapes before any row
// exists: objective terms, constraint rows, and the memory for them (values,
// gradients, a batch of finite-difference results, the LP and the solver's
// copy of it, the rows' names) and for the series of one analysis.
struct StudyFootprint {
  std::int64_t objective_terms = 0;
  std::int64_t constraint_rows = 0;
  // The series one analysis holds: every output of every load case and
  // every response (and their derivatives with simulator sensitivities).
  std::int64_t series_bytes = 0;
  // The FMU archive the study carries, held with it by server and workers.
  std::int64_t archive_bytes = 0;
  std::int64_t memory_bytes = 0;  // all of it, series and archive included
};
StudyFootprint EstimateStudyFootprint(const Study& study);

// InvalidArgument (naming the study file and the field) if the study's
// objective or constraints cannot be laid out, or would need more memory
// than kMaxStudyMemoryBytes (spec/limits.h), e.g. minimize_max_of with
// reduction MIN, or minimize on a multi-series output.
absl::StatusOr<StudyLayout> MakeStudyLayout(const Study& study);

// The study's values at one analysis.
struct StudyValues {
  std::vector<double> objective_terms;    // num_objective_terms, objective unit
  std::vector<double> constraint_values;  // g_h, SI, aligned with layout.rows
  double objective = 0;                   // F, objective unit
  double max_violation = 0;               // max_h (g_h - c_h) / scale_h; > 0 violated; 0 if no rows
  int worst_row = -1;                     // row of max_violation; -1 if no rows
};

// `outputs_si[o]` points at signal o's series, [series][instant], SI (as
// spec::OutputValues::series): the scene's outputs and then the responses
// (spec/responses.h). InvalidArgument if a shape differs from the
// layout's; a non-finite value is passed through (the optimizer rejects it).
absl::StatusOr<StudyValues> ComputeStudyValues(
    const Study& study, const StudyLayout& layout,
    const std::vector<const std::vector<std::vector<double>>*>& outputs_si);

}  // namespace mbopt::spec
