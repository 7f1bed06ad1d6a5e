#include "spec/io/pareto_convert.h"

#include <algorithm>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace mbopt::spec::io {
namespace {

std::string ConstraintNames(const Study& study) {
  std::string names;
  for (const Constraint& c : study.constraints) absl::StrAppend(&names, names.empty() ? "" : ", ", "\"", c.name, "\"");
  return names.empty() ? "(none)" : names;
}

// Why constraint `c` cannot be a second objective, or "" when it can: its
// rows must all bound a value from above by one level, which the front
// then moves.
std::string WhyNotTradable(const Constraint& c) {
  if (c.equals.has_value()) return "it holds a value (equals); a front needs a limit it can move";
  if (c.reduction == Reduction::kMin) return "it is a lower limit (REDUCTION_MIN); a front moves an upper limit";
  if (IsWholeSeriesReduction(c.reduction)) {
    if (c.lower.has_value()) return "it has a lower bound; a front moves a constraint bounded from above only";
    if (!c.upper.has_value()) return "it has no upper bound";
  }
  return "";
}

}  // namespace

Pareto ConvertPareto(const v1::Study& m, const Study& study, const Where& where, Errors* errors) {
  Pareto pareto;
  if (!m.has_pareto()) return pareto;
  const Where w = where.Child("pareto");
  const v1::Pareto& p = m.pareto();
  if (!study.design_set.empty()) {
    errors->Add(where, "pareto", "a study has a Pareto front or a sweep or sample, not both");
  }
  if (study.objective.form == Objective::Form::kFeasible) {
    errors->Add(where, "pareto", "a Pareto front trades the study's objective against a constraint: add an objective");
  }
  pareto.points = p.points() == 0 ? kDefaultParetoPoints : p.points();
  if (pareto.points < kMinParetoPoints || pareto.points > kMaxParetoPoints) {
    errors->Add(w, "points",
                absl::StrFormat("must be between %d and %d (the two ends included), got %d", kMinParetoPoints,
                                kMaxParetoPoints, p.points()));
  }
  pareto.refine = p.refine();
  if (pareto.refine < 0 || (pareto.points >= kMinParetoPoints && pareto.refine > pareto.points - 1)) {
    errors->Add(w, "refine",
                absl::StrFormat("must be between 0 and %d (one point in each segment of the %d points' front at "
                                "most), got %d",
                                std::max(pareto.points - 1, 0), pareto.points, p.refine()));
  }
  if (p.against().empty()) {
    errors->Add(w, "against",
                absl::StrCat("name the constraint whose largest value is the second objective; the study's "
                             "constraints: ",
                             ConstraintNames(study)));
    return pareto;
  }
  int found = -1;
  for (size_t k = 0; k < study.constraints.size(); ++k) {
    if (study.constraints[k].name == p.against()) found = static_cast<int>(k);
  }
  if (found < 0) {
    errors->Add(w, "against",
                absl::StrCat("unknown constraint \"", p.against(), "\"; the study's constraints: ",
                             ConstraintNames(study)));
    return pareto;
  }
  if (const std::string why = WhyNotTradable(study.constraints[static_cast<size_t>(found)]); !why.empty()) {
    errors->Add(w, "against", absl::StrCat("constraint \"", p.against(), "\" cannot be traded: ", why));
    return pareto;
  }
  pareto.constraint = found;
  return pareto;
}

std::string DescribePareto(const Study& study) {
  const Constraint& c = study.constraints[static_cast<size_t>(study.pareto.constraint)];
  return absl::StrCat("a Pareto front of the objective against the largest value of ", c.name,
                      c.unit.empty() ? "" : absl::StrCat(" (", c.unit, ")"), ", ", study.pareto.points,
                      " points",
                      study.pareto.refine == 0 ? ""
                                               : absl::StrCat(" and ", study.pareto.refine, " more where it bends"),
                      " (epsilon-constraint method)");
}

}  // namespace mbopt::spec::io
