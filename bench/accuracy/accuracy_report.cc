#include "bench/accuracy/accuracy_report.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"

namespace mbopt::accuracy {
namespace {

double Scale(const ProblemSweep& s) {
  return std::max(std::abs(s.reference.objective), 0.01 * std::abs(s.initial_objective));
}

const SettingResult* DefaultRun(const ProblemSweep& s) {
  for (const SettingResult& r : s.results) {
    if (r.setting.kind == KnobKind::kDefault) return &r;
  }
  return nullptr;
}

// What a solver knob is judged against: the run that solves the same model
// best (the reference when it shares the default's model, else the default).
const SettingResult* SolverBaseline(const ProblemSweep& s) {
  return s.plan.reference_is_default_model ? &s.reference : DefaultRun(s);
}

// A solver knob replaces the study's own value only when it is faster than
// this fraction of the default's time: smaller differences are timing noise
// on a shared machine.
constexpr double kSignificantSpeedup = 0.8;

// A solver knob may not make the found design violate more than the
// tolerance beyond what the baseline does (a feasible design always passes).
double SolverViolationLimit(const SettingResult& baseline, const Acceptance& a) {
  return std::max(a.true_violation, baseline.true_max_violation + a.true_violation);
}

std::string Why(const ProblemSweep& s, const SettingResult& r, const Acceptance& a) {
  std::vector<std::string> why;
  if (!r.recheck_ok) why.push_back("re-check failed");
  const SettingResult* def = SolverBaseline(s);
  if (r.setting.kind == KnobKind::kSolver && def != nullptr) {
    const double change = std::abs(r.objective - def->objective) / Scale(s);
    if (change > a.objective_error) {
      why.push_back(absl::StrFormat("F off by %.2g %% from the %s run", 100 * change,
                                    s.plan.reference_is_default_model ? "reference" : "default"));
    }
    if (r.recheck_ok && r.true_max_violation > SolverViolationLimit(*def, a)) {
      why.push_back(absl::StrFormat("true violation %.2g %%", 100 * r.true_max_violation));
    }
  } else {
    const double error = ObjectiveError(s, r.objective);
    if (error > a.objective_error) why.push_back(absl::StrFormat("error %.2g %%", 100 * error));
    if (r.recheck_ok && r.true_max_violation > a.true_violation) {
      why.push_back(absl::StrFormat("true violation %.2g %%", 100 * r.true_max_violation));
    }
  }
  return absl::StrJoin(why, ", ");
}

std::string Label(const SettingResult& r) {
  return r.setting.kind == KnobKind::kDefault ? r.setting.knob
                                              : absl::StrCat(r.setting.knob, " ", r.setting.value);
}

std::string Row(const ProblemSweep& s, const SettingResult& r) {
  return absl::StrFormat("| %s | %s | %.6g | %.2e | %.2e | %s | %s | %d | %.2f | %s |\n", r.setting.knob,
                         r.setting.value, r.objective, ObjectiveError(s, r.objective),
                         ChangeVsDefault(s, r.objective),
                         r.recheck_ok ? absl::StrFormat("%.6g", r.true_objective) : "failed",
                         r.recheck_ok ? absl::StrFormat("%.2e", r.true_max_violation) : r.recheck_failure,
                         r.analyses, r.wall_seconds, r.end);
}

}  // namespace

double ObjectiveError(const ProblemSweep& sweep, double objective) {
  return std::abs(objective - sweep.reference.objective) / Scale(sweep);
}

double ChangeVsDefault(const ProblemSweep& sweep, double objective) {
  const SettingResult* def = DefaultRun(sweep);
  return def == nullptr ? NAN : std::abs(objective - def->objective) / Scale(sweep);
}

bool Acceptable(const ProblemSweep& s, const SettingResult& r, const Acceptance& a) {
  if (!r.recheck_ok) return false;
  const SettingResult* def = SolverBaseline(s);
  if (r.setting.kind == KnobKind::kSolver && def != nullptr) {
    return std::abs(r.objective - def->objective) / Scale(s) <= a.objective_error &&
           r.true_max_violation <= SolverViolationLimit(*def, a);
  }
  return WithinReferenceTolerances(s, r, a);
}

bool WithinReferenceTolerances(const ProblemSweep& s, const SettingResult& r, const Acceptance& a) {
  return r.recheck_ok && ObjectiveError(s, r.objective) <= a.objective_error &&
         r.true_max_violation <= a.true_violation;
}

Setting RecommendedSetting(const ProblemSweep& s, const Acceptance& full, std::vector<std::string>* why,
                           Setting* model_only) {
  // Each knob gets half the tolerances: the errors of the chosen values add
  // up in the combination, which is then checked against the full ones.
  const Acceptance a{full.objective_error / 2, full.true_violation / 2};
  Setting out{KnobKind::kDefault, "recommended", "", {}, {}};
  *model_only = Setting{KnobKind::kDefault, "recommended (model knobs only)", "", {}, {}};
  std::vector<std::string> model_values;
  const SettingResult* def = DefaultRun(s);
  std::vector<std::string> knobs;
  std::map<std::string, const SettingResult*> fastest;
  std::map<std::string, KnobKind> kind;
  for (const SettingResult& r : s.results) {
    if (r.setting.kind == KnobKind::kDefault) continue;
    if (kind.count(r.setting.knob) == 0) knobs.push_back(r.setting.knob);
    kind[r.setting.knob] = r.setting.kind;
    if (Acceptable(s, r, a) &&
        (fastest[r.setting.knob] == nullptr || r.wall_seconds < fastest[r.setting.knob]->wall_seconds)) {
      fastest[r.setting.knob] = &r;
    }
  }
  // A default run that is itself acceptable competes with the model knobs'
  // values: keeping the study's own value is then an option.
  const bool default_model_ok = def != nullptr && Acceptable(s, *def, a);
  std::vector<std::string> values;
  for (const std::string& k : knobs) {
    const SettingResult* f = fastest[k];
    if (kind[k] == KnobKind::kModel) {
      if (f != nullptr && !(default_model_ok && def->wall_seconds <= f->wall_seconds)) {
        out.analysis.MergeFrom(f->setting.analysis);
        model_only->analysis.MergeFrom(f->setting.analysis);
        values.push_back(absl::StrCat(k, " ", f->setting.value));
        model_values.push_back(values.back());
        why->push_back(absl::StrFormat("%s: %s, the fastest value within half the tolerances of the reference (%.2f s).",
                                       k, f->setting.value, f->wall_seconds));
      } else if (default_model_ok) {
        why->push_back(absl::StrCat(k, ": the study's own value (acceptable and at least as fast)."));
      } else if (k == "time grid points" || k == "elements per link") {
        // Nothing acceptable: fall back to the reference's value of this knob.
        v1::AnalysisOverrides r;
        if (k == "time grid points") r.set_time_grid_points(s.plan.reference.analysis.time_grid_points());
        if (k == "elements per link") r.set_elements_per_flexible_link(s.plan.reference.analysis.elements_per_flexible_link());
        out.analysis.MergeFrom(r);
        model_only->analysis.MergeFrom(r);
        values.push_back(absl::StrCat(k, " as the reference"));
        model_values.push_back(values.back());
        why->push_back(absl::StrCat(k, ": no measured value is within half the tolerances; the reference's value."));
      } else {
        why->push_back(absl::StrCat(k, ": no alternative value is within half the tolerances; the study's own."));
      }
    } else {
      // The default's own value stays unless a passing value is faster, or
      // the default itself fails against a same-model reference.
      const bool default_fails = s.plan.reference_is_default_model && def != nullptr && !Acceptable(s, *def, a);
      if (f != nullptr && def != nullptr &&
          (default_fails || f->wall_seconds < kSignificantSpeedup * def->wall_seconds)) {
        out.analysis.MergeFrom(f->setting.analysis);
        out.optimizer.MergeFrom(f->setting.optimizer);
        values.push_back(absl::StrCat(k, " ", f->setting.value));
        why->push_back(absl::StrFormat("%s: %s, the fastest value within half the tolerances (F within %.2g %%) of the %s run "
                                       "(%.2f s; the default %.2f s).",
                                       k, f->setting.value, 100 * a.objective_error,
                                       s.plan.reference_is_default_model ? "reference" : "default",
                                       f->wall_seconds, def->wall_seconds));
      } else {
        why->push_back(absl::StrCat(k, ": the study's own value (no acceptable value is more than 20 % faster)."));
      }
    }
  }
  out.value = values.empty() ? "study's own" : absl::StrJoin(values, ", ");
  model_only->value = model_values.empty() ? "study's own" : absl::StrJoin(model_values, ", ");
  return out;
}

std::vector<PlotPoint> PlotPoints(const ProblemSweep& sweep, const Acceptance& acceptance) {
  std::vector<PlotPoint> points;
  auto add = [&](const SettingResult& r) {
    PlotPoint p;
    p.label = r.setting.kind == KnobKind::kDefault ? r.setting.knob : r.setting.value;
    if (r.setting.knob == "finite-difference step") p.label = absl::StrCat("h ", r.setting.value);
    if (r.setting.knob == "relative tolerance") p.label = absl::StrCat("rtol ", r.setting.value);
    if (r.setting.knob == "time grid points") p.label = absl::StrCat(r.setting.value, " pts");
    if (r.setting.knob == "elements per link") p.label = absl::StrCat(r.setting.value, " elem");
    if (r.setting.knob == "link model") p.label = "rigid links";
    if (r.setting.knob == "sensitivity") p.label = "simulator sens.";
    p.wall_seconds = r.wall_seconds;
    p.error = ObjectiveError(sweep, r.objective);
    p.is_default = r.setting.knob == "default";
    p.violated = !r.recheck_ok || r.true_max_violation > acceptance.true_violation;
    points.push_back(p);
  };
  for (const SettingResult& r : sweep.results) add(r);
  if (sweep.recommended.has_value()) add(*sweep.recommended);
  if (sweep.fallback.has_value()) add(*sweep.fallback);
  return points;
}

std::string ProblemMarkdown(const ProblemSweep& s, const Acceptance& a, const std::string& svg_link,
                            const std::vector<std::string>& recommendation_why) {
  std::string out = absl::StrCat("## ", s.plan.problem, "\n\n");
  absl::StrAppendFormat(
      &out,
      "Study `%s`. Reference run (%s): F_ref = %.7g after %d analyses, %.2f s (%s); its design "
      "re-checked: F = %.7g, max violation %.3g. F(x0) = %.6g on the re-check model (%s).\n\n",
      s.plan.study_file, s.reference.setting.value, s.reference.objective, s.reference.analyses,
      s.reference.wall_seconds, s.reference.end, s.reference.true_objective,
      s.reference.true_max_violation, s.initial_objective,
      s.plan.recheck_note.empty() ? "the study's own model" : s.plan.recheck_note);
  if (!s.plan.initial_note.empty()) absl::StrAppend(&out, "Start: ", s.plan.initial_note, ".\n\n");
  absl::StrAppend(&out,
                  "| knob | value | F found | error vs F_ref | change vs default | F re-checked | "
                  "true max violation | analyses | wall [s] | end |\n"
                  "|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
  for (const SettingResult& r : s.results) absl::StrAppend(&out, Row(s, r));
  if (s.recommended.has_value()) absl::StrAppend(&out, Row(s, *s.recommended));
  if (s.fallback.has_value()) absl::StrAppend(&out, Row(s, *s.fallback));
  if (!s.plan.not_swept.empty()) {
    absl::StrAppend(&out, "\nNot swept here: ", absl::StrJoin(s.plan.not_swept, "; "), ".\n");
  }
  if (!svg_link.empty()) {
    absl::StrAppend(&out, "\n![wall time vs objective error, ", s.plan.problem, "](", svg_link, ")\n");
  }
  const std::vector<PlotPoint> points = PlotPoints(s, a);
  std::vector<std::string> front_labels;
  for (const int i : ParetoFront(points)) {
    const size_t k = static_cast<size_t>(i);
    front_labels.push_back(k < s.results.size()                                   ? Label(s.results[k])
                           : k == s.results.size() && s.recommended.has_value() ? std::string("recommended")
                                                                                  : std::string("model knobs only"));
  }
  absl::StrAppend(&out, "\nPareto front (fastest first): ", absl::StrJoin(front_labels, "; "), ".\n");

  // Per knob: which values pass.
  std::vector<std::string> knobs;
  std::map<std::string, std::vector<std::string>> ok, bad;
  for (const SettingResult& r : s.results) {
    if (r.setting.kind == KnobKind::kDefault) continue;
    if (ok.count(r.setting.knob) == 0 && bad.count(r.setting.knob) == 0) knobs.push_back(r.setting.knob);
    if (Acceptable(s, r, a)) {
      ok[r.setting.knob].push_back(r.setting.value);
    } else {
      bad[r.setting.knob].push_back(absl::StrCat(r.setting.value, " (", Why(s, r, a), ")"));
    }
  }
  const SettingResult* def = DefaultRun(s);
  absl::StrAppendFormat(&out,
                        "\n**Which values pass.** Tolerances: the SLP's own convergence tolerances, %.2g %% "
                        "on the objective and %.2g %% on the violation. Model knobs (grid, mesh, link "
                        "model) are judged against the reference; solver knobs (tolerance, finite "
                        "differences) against the best run on the same model (the default run, or the "
                        "reference when it shares the default's model).",
                        100 * a.objective_error, 100 * a.true_violation);
  if (def != nullptr) {
    absl::StrAppendFormat(&out, " The study's default (%.2f s) has error %.2g %% and true violation %.2g %%: %s.",
                          def->wall_seconds, 100 * ObjectiveError(s, def->objective),
                          100 * def->true_max_violation,
                          Acceptable(s, *def, a) ? "within the tolerances"
                                                 : absl::StrCat("outside them (", Why(s, *def, a), ")"));
  }
  absl::StrAppend(&out, "\n\n");
  for (const std::string& k : knobs) {
    absl::StrAppend(&out, "- ", k, ": pass ", ok[k].empty() ? "none" : absl::StrJoin(ok[k], ", "),
                    bad[k].empty() ? "" : absl::StrCat("; fail ", absl::StrJoin(bad[k], ", ")), ".\n");
  }
  absl::StrAppend(&out, "\n**Recommended default.** Per knob, the fastest value that passes with half the "
                        "tolerances (the chosen values' errors add up in the combination):\n\n");
  for (const std::string& w : recommendation_why) absl::StrAppend(&out, "- ", w, "\n");
  if (s.recommended.has_value()) {
    const SettingResult& r = *s.recommended;
    const bool pass = WithinReferenceTolerances(s, r, a);
    absl::StrAppendFormat(
        &out,
        "\nThe combination (%s) was run to check it (table row \"recommended\"): error %.2g %% against F_ref, "
        "true violation %.2g %%, %.2f s (the default: %.2f s). %s\n\n",
        r.setting.value, 100 * ObjectiveError(s, r.objective), 100 * r.true_max_violation, r.wall_seconds,
        def != nullptr ? def->wall_seconds : NAN,
        pass ? "It is within both tolerances of the reference: recommended as this problem's default."
             : "It is NOT within both tolerances of the reference: the knobs interact.");
  }
  if (s.fallback.has_value()) {
    const SettingResult& r = *s.fallback;
    const bool pass = WithinReferenceTolerances(s, r, a);
    absl::StrAppendFormat(
        &out,
        "The model knobs alone (%s; solver knobs at the study's own) were run as well: error %.2g %%, "
        "true violation %.2g %%, %.2f s. %s\n\n",
        r.setting.value, 100 * ObjectiveError(s, r.objective), 100 * r.true_max_violation, r.wall_seconds,
        pass ? "Within both tolerances: recommended as this problem's default instead."
             : "Not within both tolerances either: use the reference settings for final answers.");
  }
  return out;
}

}  // namespace mbopt::accuracy
