#include "spec/io/pareto_convert.h"

#include <algorithm>
#include <string>
#include <vector>

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

// Why objective `o` cannot be a front's second objective, or "" when it
// can. The epsilon-constraint method bounds the second objective by SLP
// constraint rows: a largest of values (every form but these) by one row
// per value, a sum of one-value terms by one row; neither holds a distance
// to targets (a square root of a sum) or a sum of peaks (each peak needs
// a bound variable of its own, which a row cannot carry).
std::string WhyNotSecondObjective(const Objective& o) {
  switch (o.form) {
    case Objective::Form::kFeasible:
      return "empty: expected `minimize`, `maximize`, `minimize_max_of`, `minimize_max_over` or `minimize_sum`";
    case Objective::Form::kTargetDistance:
      return "target_distance cannot be a second objective (a distance to targets is not bounded by constraint "
             "rows); write the distance as a response and `minimize` it";
    case Objective::Form::kWeightedSum:
      for (size_t k = 0; k < o.sum_terms.size(); ++k) {
        if (IsPeakReduction(o.sum_terms[k].reduction)) {
          return absl::StrCat("minimize_sum.terms[", k,
                              "] is a peak (REDUCTION_MAX, REDUCTION_MAX_ABS or REDUCTION_MIN); a sum that is a "
                              "second objective takes one-value terms only (FINAL, RMS, INTEGRAL, RANGE, MEAN); "
                              "for the largest of peaks use minimize_max_over");
        }
      }
      return "";
    default:
      return "";
  }
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
    errors->Add(where, "pareto",
                "a Pareto front trades the study's objective against a second objective: add an objective");
  }
  const bool three = p.against_size() == 2;
  if (p.against_size() > 2) {
    errors->Add(w, "against",
                absl::StrFormat("a front has two or three objectives: name one or two constraints, got %d",
                                p.against_size()));
    return pareto;
  }
  if (three) {
    pareto.points = p.points() == 0 ? kDefaultParetoGridLevels : p.points();
    if (pareto.points < kMinParetoGridLevels || pareto.points > kMaxParetoGridLevels) {
      errors->Add(w, "points",
                  absl::StrFormat("a front of three objectives has `points` levels of each bounded objective, "
                                  "from %d to %d, got %d",
                                  kMinParetoGridLevels, kMaxParetoGridLevels, p.points()));
    }
    if (p.refine() != 0) {
      errors->Add(w, "refine", "a front of three objectives is not refined (a grid of levels has no segments)");
    }
    if (p.refine_again() != 0) {
      errors->Add(w, "refine_again", "a front of three objectives is not refined (a grid of levels has no segments)");
    }
  } else {
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
    pareto.refine_again = p.refine_again();
    if (pareto.refine_again != 0 && pareto.refine <= 0) {
      errors->Add(w, "refine_again",
                  "refines the refined front again: set `refine` (the first generation of added points) too");
    } else if (pareto.refine_again < 0 || pareto.refine_again > pareto.points + pareto.refine - 1) {
      errors->Add(w, "refine_again",
                  absl::StrFormat("must be between 0 and %d (one point in each segment of the refined front of %d "
                                  "points at most), got %d",
                                  std::max(pareto.points + pareto.refine - 1, 0), pareto.points + pareto.refine,
                                  p.refine_again()));
    }
  }
  if (p.has_objective()) {
    if (p.against_size() > 0) {
      errors->Add(w, "against",
                  absl::StrCat(three ? "a front of three objectives trades two constraints (`against` twice), not "
                                       "an `objective`: "
                                     : "a front has one second objective: ",
                               "a constraint's largest value (`against: \"", p.against(0),
                               "\"`) or an `objective`, not both"));
      return pareto;
    }
    if (const std::string why = WhyNotSecondObjective(study.second_objective); !why.empty()) {
      errors->Add(w, "objective", why);
      return pareto;
    }
    pareto.trades_objective = true;
    return pareto;
  }
  if (p.against_size() == 0 || p.against(0).empty()) {
    errors->Add(w, "against",
                absl::StrCat("name the constraint whose largest value is the second objective (the study's "
                             "constraints: ",
                             ConstraintNames(study),
                             "), or write the second objective as the study's is (`objective { minimize: ... }`)"));
    return pareto;
  }
  std::vector<int> traded;
  for (const std::string& name : p.against()) {
    int found = -1;
    for (size_t k = 0; k < study.constraints.size(); ++k) {
      if (study.constraints[k].name == name) found = static_cast<int>(k);
    }
    if (found < 0) {
      errors->Add(w, "against",
                  absl::StrCat("unknown constraint \"", name, "\"; the study's constraints: ", ConstraintNames(study)));
      return pareto;
    }
    if (const std::string why = WhyNotTradable(study.constraints[static_cast<size_t>(found)]); !why.empty()) {
      errors->Add(w, "against", absl::StrCat("constraint \"", name, "\" cannot be traded: ", why));
      return pareto;
    }
    if (!traded.empty() && traded.front() == found) {
      errors->Add(w, "against",
                  absl::StrCat("constraint \"", name,
                               "\" is named twice; a front of three objectives trades two different constraints"));
      return pareto;
    }
    traded.push_back(found);
  }
  pareto.constraint = traded[0];
  if (three) pareto.third_constraint = traded[1];
  return pareto;
}

std::string DescribePareto(const Study& study) {
  std::string second;
  if (study.pareto.trades_objective) {
    const std::string& unit = study.second_objective.unit;
    second = absl::StrCat("a second objective", unit.empty() ? "" : absl::StrCat(" (", unit, ")"));
  } else {
    const Constraint& c = study.constraints[static_cast<size_t>(study.pareto.constraint)];
    second = absl::StrCat("the largest value of ", c.name, c.unit.empty() ? "" : absl::StrCat(" (", c.unit, ")"));
  }
  if (study.pareto.three_objectives()) {
    const Constraint& c = study.constraints[static_cast<size_t>(study.pareto.third_constraint)];
    return absl::StrCat("a Pareto front of three objectives: the objective, ", second, " and the largest value of ",
                        c.name, c.unit.empty() ? "" : absl::StrCat(" (", c.unit, ")"), "; ",
                        kParetoAnchorsOfThree, " anchors and a grid of ", study.pareto.points, " x ",
                        study.pareto.points, " levels (epsilon-constraint method)");
  }
  return absl::StrCat("a Pareto front of the objective against ", second, ", ", study.pareto.points,
                      " points",
                      study.pareto.refine == 0 ? ""
                                               : absl::StrCat(" and ", study.pareto.refine, " more where it bends"),
                      study.pareto.refine_again == 0
                          ? ""
                          : absl::StrCat(", then ", study.pareto.refine_again, " more where the refined front bends"),
                      " (epsilon-constraint method)");
}

}  // namespace mbopt::spec::io
