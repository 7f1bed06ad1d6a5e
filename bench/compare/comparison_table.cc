#include "bench/compare/comparison_table.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace mbopt::compare {

StudyComparison Compare(std::string study, std::string reference_note, std::vector<MethodRun> runs,
                        const TargetRule& rule) {
  StudyComparison c;
  c.study = std::move(study);
  c.reference_note = std::move(reference_note);
  c.runs = std::move(runs);
  c.best_objective = std::numeric_limits<double>::quiet_NaN();
  for (const MethodRun& r : c.runs) {
    if (!r.candidates.empty()) c.initial_objective = r.candidates.front().objective;
    for (const Candidate& cand : r.candidates) {
      if (cand.max_violation <= rule.violation &&
          (std::isnan(c.best_objective) || cand.objective < c.best_objective)) {
        c.best_objective = cand.objective;
      }
    }
  }
  const double magnitude = std::max(std::abs(c.best_objective),
                                    rule.floor_fraction_of_initial * std::abs(c.initial_objective));
  c.target_objective = c.best_objective + rule.objective_fraction * magnitude;
  return c;
}

std::optional<std::int64_t> AnalysesToTarget(const MethodRun& run, const StudyComparison& c,
                                             const TargetRule& rule) {
  if (std::isnan(c.best_objective)) return std::nullopt;
  for (const Candidate& cand : run.candidates) {
    if (cand.max_violation <= rule.violation && cand.objective <= c.target_objective) {
      return cand.analyses;
    }
  }
  return std::nullopt;
}

std::string ComparisonMarkdown(const StudyComparison& c, const TargetRule& rule) {
  std::string out = absl::StrCat("### ", c.study, "\n\n");
  absl::StrAppendFormat(&out,
                        "F(x0) = %.6g; best known here F* = %.6g (lowest F any method analysed "
                        "with max violation <= %.2g); target F <= %.6g.",
                        c.initial_objective, c.best_objective, rule.violation, c.target_objective);
  if (!c.reference_note.empty()) absl::StrAppend(&out, " ", c.reference_note);
  absl::StrAppend(&out, "\n\n| method | analyses to target | final F | final max violation | "
                        "total analyses | failed analyses | wall [s] | end |\n"
                        "|---|---:|---:|---:|---:|---:|---:|---|\n");
  for (const MethodRun& r : c.runs) {
    const std::optional<std::int64_t> reach = AnalysesToTarget(r, c, rule);
    absl::StrAppendFormat(&out, "| %s | %s | %.6g | %.3g | %d | %d | %.2f | %s |\n", r.method,
                          reach.has_value() ? absl::StrCat(*reach) : "not reached",
                          r.final_objective, r.final_max_violation, r.analyses,
                          r.failed_analyses, r.wall_seconds, r.end);
  }
  return out;
}

std::string Verdict(const StudyComparison& c, const TargetRule& rule) {
  const MethodRun* fastest = nullptr;
  std::int64_t fastest_n = 0;
  const MethodRun* lowest = nullptr;
  for (const MethodRun& r : c.runs) {
    const std::optional<std::int64_t> reach = AnalysesToTarget(r, c, rule);
    if (reach.has_value() && (fastest == nullptr || *reach < fastest_n)) {
      fastest = &r;
      fastest_n = *reach;
    }
    if (r.final_max_violation <= rule.violation &&
        (lowest == nullptr || r.final_objective < lowest->final_objective)) {
      lowest = &r;
    }
  }
  std::string out;
  const MethodRun* slp = nullptr;
  for (const MethodRun& r : c.runs) {
    if (r.evaluations == 0) slp = &r;  // the SLP is the method without NLopt evaluations
  }
  if (fastest == nullptr) {
    absl::StrAppend(&out, "No method reached the target.");
  } else {
    absl::StrAppend(&out, "Fewest analyses to the target: ", fastest->method, " (", fastest_n, ").");
  }
  if (lowest != nullptr) {
    absl::StrAppendFormat(&out, " Lowest final F among feasible final designs: %s (%.6g).",
                          lowest->method, lowest->final_objective);
  } else {
    absl::StrAppend(&out, " No method ended at a design feasible within the tolerance.");
  }
  if (slp != nullptr) {
    const std::optional<std::int64_t> slp_reach = AnalysesToTarget(*slp, c, rule);
    absl::StrAppendFormat(&out, " The SLP ran %d cycles (%d trial points rejected).", slp->cycles,
                          slp->rejected_trials);
    if (!slp_reach.has_value() && slp->final_max_violation <= rule.violation &&
        slp->end.rfind("converged", 0) == 0) {
      absl::StrAppendFormat(&out,
                            " It stopped at F = %.6g, above the target %.6g: its convergence test (F "
                            "changes by less than 0.5 %% in a cycle, METHOD.md section 3) ended the run "
                            "while slow progress was still being made; a smaller "
                            "convergence_objective_tolerance in the study continues it.",
                            slp->final_objective, c.target_objective);
    }
    for (const MethodRun& r : c.runs) {
      if (&r == slp) continue;
      const std::optional<std::int64_t> reach = AnalysesToTarget(r, c, rule);
      if (reach.has_value() && (!slp_reach.has_value() || *reach < *slp_reach)) {
        absl::StrAppendFormat(&out, " %s wins on analyses to the target (%d against %s).", r.method, *reach,
                              slp_reach.has_value() ? absl::StrCat(*slp_reach) : "not reached");
      }
      absl::StrAppendFormat(&out, " %s made %d evaluations (%d analyses each with the gradient).", r.method,
                            r.evaluations, 1 + r.num_variables);
    }
  }
  return out;
}

}  // namespace mbopt::compare
