#include "spec/io/design_set_convert.h"

#include <cmath>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spec/io/pareto_convert.h"
#include "spec/limits.h"

namespace mbopt::spec::io {
namespace {

// The values of a design set (designs x variables), all held by the
// server: 80 MB. Here rather than in spec/limits.h because only this check
// reads it.
constexpr std::int64_t kMaxDesignSetValues = 10'000'000;

int FindVariable(const Study& study, const std::string& name) {
  for (size_t i = 0; i < study.variables.size(); ++i) {
    if (study.variables[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::string VariableNames(const Study& study) {
  std::string names;
  for (const DesignVariable& v : study.variables) absl::StrAppend(&names, names.empty() ? "" : ", ", "\"", v.name, "\"");
  return names.empty() ? "(none)" : names;
}

// One axis; false when it is unusable (an error was added).
bool ConvertAxis(const v1::SweepAxis& a, const Study& study, const Where& w, std::set<int>* swept, SweepAxis* out,
                 Errors* errors) {
  bool ok = true;
  out->variable = FindVariable(study, a.variable());
  if (out->variable < 0) {
    errors->Add(w, "variable",
                absl::StrCat("unknown design variable \"", a.variable(), "\"; the study's variables: ",
                             VariableNames(study)));
    ok = false;
  } else if (!swept->insert(out->variable).second) {
    errors->Add(w, "variable", absl::StrCat("design variable \"", a.variable(), "\" is swept twice"));
    ok = false;
  }
  out->points = a.points();
  if (a.points() < 1 || a.points() > kMaxDesignSetPoints) {
    errors->Add(w, "points", absl::StrFormat("must be between 1 and %d, got %d", kMaxDesignSetPoints, a.points()));
    ok = false;
  }
  const bool relative = a.relative_percent() != 0.0;
  if (relative && (a.has_from() || a.has_to())) {
    errors->Add(w, "relative_percent", "give from and to, or relative_percent, not both");
    return false;
  }
  if (!relative && !(a.has_from() && a.has_to())) {
    errors->Add(w, a.has_from() ? "to" : "from",
                "an axis needs from and to (scaled, like the variable's bounds), or relative_percent");
    return false;
  }
  if (!ok) return false;
  const DesignVariable& v = study.variables[static_cast<size_t>(out->variable)];
  const char* range_field = relative ? "relative_percent" : "from";
  if (relative) {
    if (!(a.relative_percent() > 0.0) || !std::isfinite(a.relative_percent())) {
      errors->Add(w, "relative_percent", absl::StrFormat("must be positive, got %g", a.relative_percent()));
      return false;
    }
    out->from = v.initial * (1.0 - a.relative_percent() / 100.0);
    out->to = v.initial * (1.0 + a.relative_percent() / 100.0);
    if (v.initial == 0.0 && a.points() > 1) {
      errors->Add(w, "relative_percent",
                  absl::StrCat("\"", v.name, "\" starts at 0, so a share of it is no range: give from and to"));
      return false;
    }
  } else {
    out->from = a.from();
    out->to = a.to();
    if (!std::isfinite(a.from()) || !std::isfinite(a.to())) {
      errors->Add(w, "from", "from and to must be finite numbers");
      return false;
    }
    if (a.points() > 1 && a.from() == a.to()) {
      errors->Add(w, "to", absl::StrFormat("from and to are both %g: %d points need a range (or points: 1)", a.from(),
                                           a.points()));
      return false;
    }
  }
  const double low = std::min(out->from, out->to);
  const double high = std::max(out->from, out->to);
  if (low < v.lower || high > v.upper) {
    errors->Add(w, range_field,
                absl::StrFormat("the axis runs from %g to %g (scaled), outside the bounds [%g, %g] of \"%s\"",
                                out->from, out->to, v.lower, v.upper, v.name));
    return false;
  }
  return true;
}

DesignSet ConvertSweep(const v1::Sweep& m, const Study& study, const Where& w, Errors* errors) {
  DesignSet set;
  set.form = DesignSet::Form::kSweep;
  if (m.axis_size() < 1 || m.axis_size() > 2) {
    errors->Add(w, "axis",
                absl::StrFormat("a sweep has one axis (a line) or two (a grid), got %d", m.axis_size()));
    return set;
  }
  std::set<int> swept;
  for (int k = 0; k < m.axis_size(); ++k) {
    SweepAxis axis;
    if (ConvertAxis(m.axis(k), study, w.Child("axis", k), &swept, &axis, errors)) set.axes.push_back(axis);
  }
  if (set.axes.size() == static_cast<size_t>(m.axis_size()) && set.size() > kMaxDesignSetPoints) {
    errors->Add(w, "axis", absl::StrFormat("the grid has %d designs, more than the limit of %d", set.size(),
                                           kMaxDesignSetPoints));
  }
  return set;
}

DesignSet ConvertSample(const v1::Sample& m, const Where& w, Errors* errors) {
  DesignSet set;
  if (!m.has_latin_hypercube()) {
    errors->Add(w, "latin_hypercube", "a sample names its form: latin_hypercube { count: N seed: S }");
    return set;
  }
  set.form = DesignSet::Form::kLatinHypercube;
  const v1::LatinHypercube& lhs = m.latin_hypercube();
  const Where lw = w.Child("latin_hypercube");
  if (lhs.count() < 1 || lhs.count() > kMaxDesignSetPoints) {
    errors->Add(lw, "count", absl::StrFormat("must be between 1 and %d, got %d", kMaxDesignSetPoints, lhs.count()));
  }
  set.latin_hypercube = LatinHypercubeSample{.count = lhs.count(), .seed = lhs.seed()};
  return set;
}

}  // namespace

DesignSet ConvertDesignSet(const v1::Study& m, const Study& study, const Where& where, Errors* errors) {
  if (m.has_sweep() && m.has_sample()) {
    errors->Add(where, "sample", "a study has a sweep or a sample, not both");
    return DesignSet{};
  }
  DesignSet set;
  if (m.has_sweep()) set = ConvertSweep(m.sweep(), study, where.Child("sweep"), errors);
  if (m.has_sample()) set = ConvertSample(m.sample(), where.Child("sample"), errors);
  const std::int64_t values = set.size() * static_cast<std::int64_t>(study.variables.size());
  if (set.size() <= kMaxDesignSetPoints && values > kMaxDesignSetValues) {
    errors->Add(where, m.has_sweep() ? "sweep" : "sample",
                absl::StrFormat("%d designs of %d variables are %d values, more than the limit of %d", set.size(),
                                study.variables.size(), values, kMaxDesignSetValues));
  }
  return set;
}

std::string DescribeStudyForm(const Study& study) {
  const DesignSet& set = study.design_set;
  auto axis = [&](const SweepAxis& a) {
    return absl::StrFormat("%s (%d point%s from %g to %g, scaled)", study.variables[static_cast<size_t>(a.variable)].name,
                           a.points, a.points == 1 ? "" : "s", a.from, a.to);
  };
  switch (set.form) {
    case DesignSet::Form::kNone:
      return study.pareto.enabled() ? DescribePareto(study) : "an optimization";
    case DesignSet::Form::kSweep:
      if (set.axes.size() == 1) return absl::StrCat("a sweep of ", axis(set.axes[0]));
      return absl::StrCat("a grid of ", axis(set.axes[0]), " by ", axis(set.axes[1]), ", ", set.size(), " designs");
    case DesignSet::Form::kLatinHypercube:
      return absl::StrCat("a Latin hypercube sample of ", set.latin_hypercube.count, " designs (seed ",
                          set.latin_hypercube.seed, ")");
  }
  return "";
}

}  // namespace mbopt::spec::io
