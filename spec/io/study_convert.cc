#include "spec/io/study_convert.h"

#include <cctype>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spec/io/declared_name.h"
#include "spec/io/design_set_convert.h"
#include "spec/io/pareto_convert.h"
#include "spec/layout.h"
#include "spec/limits.h"
#include "spec/units.h"
#include "spec/expression.h"

namespace mbopt::spec::io {
namespace {

// The unit `name` for values of `dimension`; records an error otherwise.
double UnitFactor(const Where& w, const std::string& field, const std::string& name,
                  Dimension dimension, Errors* errors) {
  absl::StatusOr<Unit> unit = FindUnit(name);
  if (!unit.ok()) {
    errors->Add(w, field, std::string(unit.status().message()));
    return 1.0;
  }
  if (!UnitFits(*unit, dimension)) {
    errors->Add(w, field,
                absl::StrFormat("unit \"%s\" is a %s but the output is a %s", name,
                                DimensionName(unit->dimension), DimensionName(dimension)));
  }
  return unit->si_per_unit;
}

// A signal (a scene output, per load case, or a response) by name, or -1
// with an error listing what there is.
int FindOutput(const Study& study, const Where& w, const std::string& field, const std::string& name,
               Errors* errors) {
  const int index = study.FindSignal(name);
  if (index < 0) {
    // Named in full up to a point: a message is read, not scrolled.
    constexpr int kListed = 20;
    auto list = [&](int first, int end) {
      std::string text;
      for (int s = first; s < end && s < first + kListed; ++s) {
        absl::StrAppend(&text, text.empty() ? "" : ", ", "\"", study.SignalName(s), "\"");
      }
      if (end - first > kListed) absl::StrAppend(&text, " and ", end - first - kListed, " more");
      return text;
    };
    const std::string known = list(0, study.num_case_signals());
    const std::string responses_known = list(study.num_case_signals(), study.num_signals());
    errors->Add(w, field,
                absl::StrCat("unknown output \"", name, "\"; the scene's outputs",
                             study.cases.empty() ? "" : " in each load case", ": ", known.empty() ? "(none)" : known,
                             responses_known.empty() ? "" : absl::StrCat("; the study's responses: ", responses_known)));
  }
  return index;
}

// A name usable in expressions: a letter or '_', then letters, digits, '_'.
bool IsIdentifier(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  }
  return true;
}

// The study's load cases. Each sets scene parameters that no design
// variable sets, in the parameter's own unit unless it names another.
std::vector<LoadCase> ConvertCases(const v1::Study& m, const Study& study, const Where& where, Errors* errors) {
  std::vector<LoadCase> cases;
  if (m.cases_size() > kMaxLoadCases) {
    errors->Add(where, "cases", absl::StrFormat("%d load cases, more than the limit of %d", m.cases_size(),
                                                kMaxLoadCases));
    return cases;
  }
  std::set<int> set_by_variables;
  for (const DesignVariable& v : study.variables) {
    set_by_variables.insert(v.parameter);
    set_by_variables.insert(v.also_sets.begin(), v.also_sets.end());
  }
  std::set<std::string> names;
  for (int k = 0; k < m.cases_size(); ++k) {
    const v1::LoadCase& c = m.cases(k);
    const Where w = where.Child("cases", k);
    LoadCase out;
    out.name = c.name();
    if (!IsIdentifier(c.name())) {
      errors->Add(w, "name", absl::StrCat("\"", c.name(), "\" is not a name: letters, digits and '_', not starting "
                                          "with a digit (outputs are named \"<case>.<output>\")"));
    } else if (!names.insert(c.name()).second) {
      errors->Add(w, "name", absl::StrCat("duplicate load case \"", c.name(), "\""));
    }
    std::set<int> set_here;
    for (int p = 0; p < c.set_size(); ++p) {
      const v1::ParameterValue& value = c.set(p);
      const Where pw = w.Child("set", p);
      const int parameter = study.scene.FindParameter(value.parameter());
      if (parameter < 0) {
        errors->Add(pw, "parameter", absl::StrCat("unknown scene parameter \"", value.parameter(), "\""));
        continue;
      }
      if (study.scene.ParameterExpression(parameter) != nullptr) {
        errors->Add(pw, "parameter",
                    absl::StrCat("parameter \"", value.parameter(),
                                 "\" is an expression of other parameters (`expr` in the scene): set those it reads"));
        continue;
      }
      if (set_by_variables.count(parameter) > 0) {
        errors->Add(pw, "parameter", absl::StrCat("parameter \"", value.parameter(),
                                                  "\" is set by a design variable; a load case sets the others"));
        continue;
      }
      if (!set_here.insert(parameter).second) {
        errors->Add(pw, "parameter", absl::StrCat("parameter \"", value.parameter(), "\" is set twice in this case"));
        continue;
      }
      if (!std::isfinite(value.value())) errors->Add(pw, "value", "must be a finite number");
      const Parameter& target = study.scene.parameters[static_cast<size_t>(parameter)];
      double si_per_unit = target.si_per_unit;
      if (!value.unit().empty()) {
        absl::StatusOr<Unit> unit = FindUnit(value.unit());
        absl::StatusOr<Unit> own = FindUnit(target.unit);
        if (!unit.ok()) {
          errors->Add(pw, "unit", std::string(unit.status().message()));
        } else if (own.ok() && !UnitFits(*unit, own->dimension)) {
          errors->Add(pw, "unit", absl::StrFormat("unit \"%s\" is a %s but parameter \"%s\" is a %s", value.unit(),
                                                  DimensionName(unit->dimension), target.name,
                                                  DimensionName(own->dimension)));
        } else {
          si_per_unit = unit->si_per_unit;
        }
      }
      out.parameter_values_si.emplace_back(parameter, value.value() * si_per_unit);
    }
    cases.push_back(std::move(out));
  }
  return cases;
}

// The study's responses, in order. A response may read the signals (the
// scene's outputs per load case, the responses before it), the scene's
// parameters and t.
std::vector<Response> ConvertResponses(const v1::Study& m, const Study& study, const Where& where, Errors* errors) {
  const Scene& scene = study.scene;
  std::vector<Response> responses;
  if (m.responses_size() > kMaxResponses) {
    errors->Add(where, "responses",
                absl::StrFormat("%d responses, more than the limit of %d", m.responses_size(), kMaxResponses));
    return responses;
  }
  const int num_case_signals = study.num_case_signals();
  const int num_signals = num_case_signals + m.responses_size();
  const int time_index = num_signals + static_cast<int>(scene.parameters.size());
  for (int k = 0; k < m.responses_size(); ++k) {
    const v1::Response& r = m.responses(k);
    const Where w = where.Child("responses", k);
    Response out;
    out.name = r.name();
    int clash = -1;
    for (int s = 0; s < num_case_signals && clash < 0; ++s) {
      if (study.SignalName(s) == r.name()) clash = s;
    }
    if (r.name().empty()) {
      errors->Add(w, "name", "a response needs a name");
    } else if (clash >= 0) {
      errors->Add(w, "name", absl::StrCat("\"", r.name(), "\" is already an output of the scene"));
    } else if (scene.FindParameter(r.name()) >= 0) {
      errors->Add(w, "name", absl::StrCat("\"", r.name(), "\" is already a parameter of the scene"));
    } else if (r.name() == "t" || r.name() == "pi") {
      errors->Add(w, "name", absl::StrCat("\"", r.name(), "\" is reserved in expressions"));
    } else {
      for (const Response& earlier : responses) {
        if (earlier.name == r.name()) errors->Add(w, "name", absl::StrCat("duplicate response \"", r.name(), "\""));
      }
    }
    Expression::Names names;
    names.kind = "output, response or parameter";
    names.find = [&](const std::string& name) -> std::optional<int> {
      for (int s = 0; s < num_case_signals; ++s) {
        if (study.SignalName(s) == name) return s;
      }
      for (size_t e = 0; e < responses.size(); ++e) {
        if (responses[e].name == name) return num_case_signals + static_cast<int>(e);
      }
      if (const int p = scene.FindParameter(name); p >= 0) return num_signals + p;
      if (name == "t") return time_index;
      return std::nullopt;
    };
    for (int s = 0; s < num_case_signals; ++s) names.all.push_back(study.SignalName(s));
    for (const Response& e : responses) names.all.push_back(e.name);
    for (const Parameter& p : scene.parameters) names.all.push_back(p.name);
    names.all.push_back("t");
    // A parameter written as `expr` reads as its expression, like in the scene.
    names.expand_index_offset = num_signals;
    names.expand = [&](const std::string& name) -> absl::StatusOr<std::shared_ptr<const Expression>> {
      for (int s = 0; s < num_case_signals; ++s) {
        if (study.SignalName(s) == name) return nullptr;
      }
      for (const Response& e : responses) {
        if (e.name == name) return nullptr;
      }
      const int p = scene.FindParameter(name);
      return scene.ParameterExpression(p);
    };
    if (r.expr().empty()) {
      errors->Add(w, "expr", "a response needs an expression, e.g. \"seat_position - body_position\"");
    } else if (absl::StatusOr<std::shared_ptr<const Expression>> parsed = Expression::Parse(r.expr(), names);
               !parsed.ok()) {
      std::string message(parsed.status().message());
      // A later response is a name the parser did not know yet.
      for (int later = k + 1; later < m.responses_size(); ++later) {
        if (message.find(absl::StrCat("\"", m.responses(later).name(), "\"")) != std::string::npos) {
          message += absl::StrCat(" (response \"", m.responses(later).name(),
                                  "\" is defined later: a response reads only those before it)");
          break;
        }
      }
      errors->Add(w, "expr", message);
    } else {
      out.expression = *std::move(parsed);
    }
    out.unit = r.unit();
    if (!r.unit().empty()) {
      if (absl::StatusOr<Unit> unit = FindUnit(r.unit()); unit.ok()) {
        out.dimension = unit->dimension;
      } else {
        errors->Add(w, "unit", std::string(unit.status().message()));
      }
    }
    responses.push_back(std::move(out));
  }
  return responses;
}

std::optional<Reduction> ToReduction(v1::Reduction r) {
  switch (r) {
    case v1::REDUCTION_MAX:
      return Reduction::kMax;
    case v1::REDUCTION_MAX_ABS:
      return Reduction::kMaxAbs;
    case v1::REDUCTION_MIN:
      return Reduction::kMin;
    case v1::REDUCTION_FINAL:
      return Reduction::kFinal;
    case v1::REDUCTION_RMS:
      return Reduction::kRms;
    case v1::REDUCTION_INTEGRAL:
      return Reduction::kIntegral;
    case v1::REDUCTION_RANGE:
      return Reduction::kRange;
    case v1::REDUCTION_MEAN:
      return Reduction::kMean;
    default:
      return std::nullopt;
  }
}

// The parameters a design variable or a load case sets: what changes from
// one analysis of the study to another.
std::set<int> VariedParameters(const Study& study) {
  std::set<int> varied;
  for (const DesignVariable& v : study.variables) {
    if (v.parameter >= 0) varied.insert(v.parameter);
    varied.insert(v.also_sets.begin(), v.also_sets.end());
  }
  for (const LoadCase& c : study.cases) {
    for (const auto& [parameter, value] : c.parameter_values_si) varied.insert(parameter);
  }
  return varied;
}

// Refuses, at `field`, reading parameters that the study varies: `what` is
// computed once for the whole study.
void CheckReadsNoVariedParameter(const Where& w, const std::string& field, const std::string& what,
                                 const std::vector<int>& parameters_read, const Study& study, Errors* errors) {
  const std::set<int> varied = VariedParameters(study);
  for (int p : parameters_read) {
    if (varied.count(p) == 0) continue;
    errors->Add(w, field,
                absl::StrCat(what, " is the same at every design point, but it reads parameter \"",
                             study.scene.parameters[static_cast<size_t>(p)].name,
                             "\", which a design variable or load case sets"));
    return;
  }
}

// The value of an expression of the scene's parameters that the study holds
// fixed (a window's end, an `equals` value), SI, at the scene file's values.
std::optional<double> FixedExpression(const Where& w, const std::string& field, const std::string& text,
                                      const Study& study, const std::string& what, Errors* errors) {
  const Scene& scene = study.scene;
  Expression::Names names;
  names.find = [&](const std::string& name) -> std::optional<int> {
    const int index = scene.FindParameter(name);
    return index >= 0 ? std::optional<int>(index) : std::nullopt;
  };
  for (const Parameter& parameter : scene.parameters) names.all.push_back(parameter.name);
  names.expand = [&](const std::string& name) -> absl::StatusOr<std::shared_ptr<const Expression>> {
    const int index = scene.FindParameter(name);
    return scene.ParameterExpression(index);
  };
  absl::StatusOr<std::shared_ptr<const Expression>> parsed = Expression::Parse(text, names);
  if (!parsed.ok()) {
    errors->Add(w, field, std::string(parsed.status().message()));
    return std::nullopt;
  }
  CheckReadsNoVariedParameter(w, field, what, (*parsed)->parameters(), study, errors);
  const double value = (*parsed)->Evaluate(scene.DefaultParameterValues());
  if (!std::isfinite(value)) {
    errors->Add(w, field, absl::StrCat("\"", text, "\" is ", value, " at the scene's parameter values"));
    return std::nullopt;
  }
  return value;
}

TimeWindow ConvertWindow(const Where& w, const v1::TimeWindow& m, const Study& study, Errors* errors) {
  TimeWindow window;
  if (m.has_from_s()) {
    if (!std::isfinite(m.from_s())) errors->Add(w, "from_s", "must be a finite number");
    window.from_s = m.from_s();
  }
  if (m.has_to_s()) {
    if (!std::isfinite(m.to_s())) errors->Add(w, "to_s", "must be a finite number");
    window.to_s = m.to_s();
  }
  if (!m.from_expr().empty()) {
    if (m.has_from_s()) errors->Add(w, "from_expr", "give from_s or from_expr, not both");
    window.from_s = FixedExpression(w, "from_expr", m.from_expr(), study, "a window", errors);
  }
  if (!m.to_expr().empty()) {
    if (m.has_to_s()) errors->Add(w, "to_expr", "give to_s or to_expr, not both");
    window.to_s = FixedExpression(w, "to_expr", m.to_expr(), study, "a window", errors);
  }
  if (window.from_s && window.to_s && !(*window.from_s <= *window.to_s)) {
    errors->Add(w, "to_s", absl::StrFormat("the window ends (%g s) before it starts (%g s)", *window.to_s,
                                           *window.from_s));
  }
  return window;
}

// Objective `o` (the study's, or a Pareto front's second) at `ow`. A form
// not set is kFeasible, without an error: each caller says what it means.
Objective ConvertObjective(const v1::Objective& o, const Study& study, const Where& ow, Errors* errors) {
  Objective obj;
  obj.unit = o.unit();
  switch (o.form_case()) {
    case v1::Objective::kMinimizeMaxOf: {
      obj.form = Objective::Form::kMinimizeMaxOf;
      obj.output = FindOutput(study, ow, "minimize_max_of", o.minimize_max_of(), errors);
      if (o.reduction() == v1::REDUCTION_MAX) {
        obj.reduction = Reduction::kMax;
      } else if (o.reduction() == v1::REDUCTION_MAX_ABS) {
        obj.reduction = Reduction::kMaxAbs;
      } else {
        errors->Add(ow, "reduction", "minimize_max_of needs REDUCTION_MAX or REDUCTION_MAX_ABS");
      }
      break;
    }
    case v1::Objective::kMinimize:
    case v1::Objective::kMaximize: {
      obj.form = Objective::Form::kMinimize;
      obj.maximize = o.form_case() == v1::Objective::kMaximize;
      obj.output = obj.maximize ? FindOutput(study, ow, "maximize", o.maximize(), errors)
                                : FindOutput(study, ow, "minimize", o.minimize(), errors);
      const std::optional<Reduction> r =
          o.reduction() == v1::REDUCTION_UNSPECIFIED ? Reduction::kFinal : ToReduction(o.reduction());
      if (!r.has_value() || !IsWholeSeriesReduction(*r)) {
        errors->Add(ow, "reduction",
                    absl::StrCat(obj.maximize ? "maximize" : "minimize",
                                 " takes one value per run: REDUCTION_FINAL (the default), REDUCTION_RMS, "
                                 "REDUCTION_INTEGRAL, REDUCTION_RANGE or REDUCTION_MEAN (for a maximum over time "
                                 "use minimize_max_of)"));
      }
      obj.reduction = r.value_or(Reduction::kFinal);
      break;
    }
    case v1::Objective::kTargetDistance: {
      obj.form = Objective::Form::kTargetDistance;
      const Where tw = ow.Child("target_distance");
      if (o.target_distance().terms_size() == 0) {
        errors->Add(tw, "terms", "target_distance needs at least one term");
      }
      for (int k = 0; k < o.target_distance().terms_size(); ++k) {
        const v1::TargetTerm& t = o.target_distance().terms(k);
        const Where kw = tw.Child("terms", k);
        TargetTerm term;
        term.output = FindOutput(study, kw, "output", t.output(), errors);
        term.target = t.target();
        term.weight = t.weight() == 0.0 ? 1.0 : t.weight();
        if (!(term.weight > 0.0) || !std::isfinite(term.weight)) {
          errors->Add(kw, "weight", absl::StrFormat("must be positive, got %g", t.weight()));
        }
        if (!std::isfinite(t.target())) errors->Add(kw, "target", "must be a finite number");
        term.unit = t.unit();
        term.si_per_unit = UnitFactor(
            kw, "unit", t.unit(),
            SignalDimension(study, term.output),
            errors);
        obj.terms.push_back(std::move(term));
      }
      break;
    }
    case v1::Objective::kMinimizeSum:
    case v1::Objective::kMinimizeMaxOver: {
      const bool sum = o.form_case() == v1::Objective::kMinimizeSum;
      obj.form = sum ? Objective::Form::kWeightedSum : Objective::Form::kMaxOver;
      const char* form = sum ? "minimize_sum" : "minimize_max_over";
      const Where sw = ow.Child(form);
      const auto& terms = sum ? o.minimize_sum().terms() : o.minimize_max_over().terms();
      if (terms.empty()) errors->Add(sw, "terms", absl::StrCat(form, " needs at least one term"));
      if (!o.unit().empty()) {
        errors->Add(ow, "unit", absl::StrCat(sum ? "a weighted sum" : "the largest of several terms",
                                             " has no unit of its own: each term's `unit` says how it is taken"));
      }
      for (int k = 0; k < terms.size(); ++k) {
        const v1::WeightedTerm& t = terms[k];
        const Where kw = sw.Child("terms", k);
        WeightedTerm term;
        term.output = FindOutput(study, kw, "output", t.output(), errors);
        const std::optional<Reduction> r =
            t.reduction() == v1::REDUCTION_UNSPECIFIED ? Reduction::kFinal : ToReduction(t.reduction());
        if (sum && !r.has_value()) {
          errors->Add(kw, "reduction",
                      "a term is one value: REDUCTION_FINAL (the default), REDUCTION_RMS, REDUCTION_INTEGRAL, "
                      "REDUCTION_RANGE or REDUCTION_MEAN, or a peak: REDUCTION_MAX, REDUCTION_MAX_ABS, or "
                      "REDUCTION_MIN with a negative weight");
        }
        if (!sum && (!r.has_value() || *r == Reduction::kMin)) {
          errors->Add(kw, "reduction",
                      "a term of minimize_max_over is REDUCTION_MAX or REDUCTION_MAX_ABS (a term per instant), or "
                      "one value: REDUCTION_FINAL (the default), REDUCTION_RMS, REDUCTION_INTEGRAL, REDUCTION_RANGE "
                      "or REDUCTION_MEAN");
        }
        term.reduction = r.value_or(Reduction::kFinal);
        if (t.has_window()) term.window = ConvertWindow(kw.Child("window"), t.window(), study, errors);
        term.weight = t.weight() == 0.0 ? 1.0 : t.weight();
        if (!std::isfinite(term.weight)) errors->Add(kw, "weight", "must be a finite number");
        if (!sum && !(term.weight > 0.0)) {
          errors->Add(kw, "weight", absl::StrFormat("a term of the largest must weigh more than 0, got %g",
                                                    term.weight));
        }
        // A peak enters a sum through a bound variable, which can only push a
        // largest value down: a peak with a negative weight (or a minimum
        // with a positive one) would be maximized, which no bound states.
        if (sum && r.has_value() && (*r == Reduction::kMax || *r == Reduction::kMaxAbs) && !(term.weight > 0.0)) {
          errors->Add(kw, "weight",
                      absl::StrFormat("a peak (%s) in a sum must weigh more than 0, got %g: a sum can push a peak "
                                      "down, not up (to raise the smallest value use REDUCTION_MIN with a negative "
                                      "weight)",
                                      *r == Reduction::kMax ? "REDUCTION_MAX" : "REDUCTION_MAX_ABS", term.weight));
        }
        if (sum && r.has_value() && *r == Reduction::kMin && !(term.weight < 0.0)) {
          errors->Add(kw, "weight",
                      absl::StrFormat("REDUCTION_MIN in a sum needs a negative weight (raising the smallest value), "
                                      "got %g: a sum cannot push a smallest value down",
                                      term.weight));
        }
        term.unit = t.unit();
        term.si_per_unit = UnitFactor(kw, "unit", t.unit(), SignalDimension(study, term.output),
                                      errors);
        obj.sum_terms.push_back(std::move(term));
      }
      break;
    }
    case v1::Objective::FORM_NOT_SET:
      obj.form = Objective::Form::kFeasible;  // the caller says what that means
      break;
  }
  const bool termwise = obj.form == Objective::Form::kWeightedSum || obj.form == Objective::Form::kMaxOver;
  if (o.has_window()) {
    if (obj.form == Objective::Form::kTargetDistance) {
      errors->Add(ow, "window", "target_distance takes final values; it has no window");
    }
    if (termwise) errors->Add(ow, "window", "each term has a window of its own (terms[k].window)");
    obj.window = ConvertWindow(ow.Child("window"), o.window(), study, errors);
  }
  if (obj.form != Objective::Form::kTargetDistance && obj.form != Objective::Form::kFeasible && !termwise) {
    obj.si_per_unit =
        UnitFactor(ow, "unit", o.unit(),
                   SignalDimension(study, obj.output),
                   errors);
  }

  return obj;
}

}  // namespace

Study ConvertStudy(const v1::Study& m, Scene scene_in, const Where& where, Errors* errors) {
  Study study;
  study.name = m.name();
  study.source_file = where.file();
  study.scene = std::move(scene_in);
  Scene& scene = study.scene;

  // Overrides first: the layout (grid size) depends on them.
  if (m.has_analysis()) {
    const Where w = where.Child("analysis");
    const v1::AnalysisOverrides& a = m.analysis();
    if (a.time_grid_points() < 0) errors->Add(w, "time_grid_points", "must not be negative");
    if (a.time_grid_points() > kMaxTimeGridPoints) {
      errors->Add(w, "time_grid_points",
                  absl::StrFormat("%d is more than the limit of %d instants", a.time_grid_points(), kMaxTimeGridPoints));
    }
    if (a.relative_tolerance() < 0) errors->Add(w, "relative_tolerance", "must not be negative");
    if (a.absolute_tolerance() < 0) errors->Add(w, "absolute_tolerance", "must not be negative");
    if (a.elements_per_flexible_link() < 0) {
      errors->Add(w, "elements_per_flexible_link", "must not be negative");
    }
    if (a.elements_per_flexible_link() > kMaxLinkageFlexibleElements) {
      errors->Add(w, "elements_per_flexible_link",
                  absl::StrFormat("%d is more than the limit of %d elements per link", a.elements_per_flexible_link(),
                                  kMaxLinkageFlexibleElements));
    }
    study.analysis.time_grid_points = a.time_grid_points();
    study.analysis.relative_tolerance = a.relative_tolerance();
    study.analysis.absolute_tolerance = a.absolute_tolerance();
    study.analysis.elements_per_flexible_link = a.elements_per_flexible_link();
    study.analysis.rigid_links = a.rigid_links();
    if (a.time_grid_points() > 0) scene.time_grid.points = a.time_grid_points();
    if (a.relative_tolerance() > 0) scene.integrator.relative_tolerance = a.relative_tolerance();
    if (a.absolute_tolerance() > 0) scene.integrator.absolute_tolerance = a.absolute_tolerance();
    if (auto* linkage = std::get_if<LinkageModel>(&scene.model)) {
      for (Link& link : linkage->links) {
        if (a.elements_per_flexible_link() > 0 && link.flexible_elements > 0) {
          link.flexible_elements = a.elements_per_flexible_link();
        }
        if (a.rigid_links()) link.flexible_elements = 0;
      }
    }
  }

  std::set<std::string> names;
  std::set<int> bound;
  if (m.variables_size() > kMaxDesignVariables) {
    errors->Add(where, "variables",
                absl::StrFormat("%d design variables, more than the limit of %d", m.variables_size(), kMaxDesignVariables));
  }
  for (int i = 0; i < m.variables_size(); ++i) {
    const v1::DesignVariable& v = m.variables(i);
    const Where w = where.Child("variables", i);
    DesignVariable out;
    out.name = v.name();
    CheckDeclaredName(w, v.name(), names.insert(v.name()).second,
                      {.missing = "a design variable needs a name", .duplicate = "design variable"}, errors);
    out.parameter = scene.FindParameter(v.parameter());
    if (out.parameter < 0) {
      errors->Add(w, "parameter", absl::StrCat("unknown scene parameter \"", v.parameter(), "\""));
    } else if (scene.ParameterExpression(out.parameter) != nullptr) {
      errors->Add(w, "parameter",
                  absl::StrCat("parameter \"", v.parameter(),
                               "\" is an expression of other parameters (`expr` in the scene); a design variable "
                               "sets a parameter with a value, e.g. one the expression reads"));
    } else if (!bound.insert(out.parameter).second) {
      errors->Add(
          w, "parameter",
          absl::StrCat("parameter \"", v.parameter(), "\" is already bound to another variable"));
    }
    for (int a = 0; a < v.also_sets_size(); ++a) {
      const int also = scene.FindParameter(v.also_sets(a));
      if (also < 0) {
        errors->Add(w, "also_sets", a, absl::StrCat("unknown scene parameter \"", v.also_sets(a), "\""));
      } else if (scene.ParameterExpression(also) != nullptr) {
        errors->Add(w, "also_sets", a,
                    absl::StrCat("parameter \"", v.also_sets(a),
                                 "\" is an expression of other parameters (`expr` in the scene): it follows them"));
      } else if (!bound.insert(also).second) {
        errors->Add(w, "also_sets", a,
                    absl::StrCat("parameter \"", v.also_sets(a), "\" is already set by a variable"));
      } else {
        out.also_sets.push_back(also);
      }
    }
    out.scale = v.scale() == 0.0 ? 1.0 : v.scale();
    if (!(out.scale > 0.0) || !std::isfinite(out.scale)) {
      errors->Add(w, "scale", absl::StrFormat("must be positive, got %g", v.scale()));
      out.scale = 1.0;
    }
    out.lower = v.lower();
    out.upper = v.upper();
    if (!std::isfinite(v.lower()) || !std::isfinite(v.upper())) {
      errors->Add(w, "lower", "bounds must be finite numbers");
    } else if (!(v.lower() < v.upper())) {
      errors->Add(w, "upper",
                  absl::StrFormat("bounds reversed or empty: lower (%g) must be "
                                  "below upper (%g)",
                                  v.lower(), v.upper()));
    }
    if (v.has_initial()) {
      out.initial = v.initial();
    } else if (out.parameter >= 0) {
      const Parameter& p = scene.parameters[static_cast<size_t>(out.parameter)];
      out.initial = p.value_si / p.si_per_unit / out.scale;
    }
    const bool bounds_ok =
        std::isfinite(v.lower()) && std::isfinite(v.upper()) && v.lower() < v.upper();
    if (bounds_ok && !(out.initial >= out.lower && out.initial <= out.upper)) {
      errors->Add(
          w, v.has_initial() ? "initial" : "parameter",
          absl::StrFormat("initial value %g (scaled%s) is outside the bounds [%g, %g]", out.initial,
                          v.has_initial() ? "" : ", from the parameter", out.lower, out.upper));
    }
    study.variables.push_back(std::move(out));
  }
  if (m.variables_size() == 0)
    errors->Add(where, "variables", "a study needs at least one design variable");

  study.cases = ConvertCases(m, study, where, errors);
  CheckReadsNoVariedParameter(where, m.has_scene() ? "scene.time_grid" : "scene_file", "the scene's time grid",
                              study.scene.time_grid_parameters_read, study, errors);
  study.responses = ConvertResponses(m, study, where, errors);

  // Objective.
  study.objective = ConvertObjective(m.objective(), study, where.Child("objective"), errors);
  if (m.objective().form_case() == v1::Objective::FORM_NOT_SET) {
    if (!m.has_objective()) {
      // No objective at all: find a design that meets the constraints.
      if (m.constraints_size() == 0) {
        errors->Add(where, "objective",
                    "missing, and the study has no constraints either: a study without an objective finds a "
                    "design that meets its constraints; add constraints, or an objective (`minimize_max_of`, "
                    "`minimize`, `maximize`, `minimize_sum`, `minimize_max_over` or `target_distance`)");
      }
    } else {
      errors->Add(where, "objective",
                  "empty: expected `minimize_max_of`, `minimize`, `maximize`, `minimize_sum`, "
                  "`minimize_max_over` or `target_distance` (or no `objective` at all, to find a design that "
                  "meets the constraints)");
    }
  }

  // Constraints.
  std::set<std::string> constraint_names;
  for (int i = 0; i < m.constraints_size(); ++i) {
    const v1::Constraint& c = m.constraints(i);
    const Where w = where.Child("constraints", i);
    Constraint out;
    out.name = c.name();
    CheckDeclaredName(w, c.name(), constraint_names.insert(c.name()).second,
                      {.missing = "a constraint needs a name", .duplicate = "constraint name"}, errors);
    out.output = FindOutput(study, w, "output", c.output(), errors);
    if (std::optional<Reduction> r = ToReduction(c.reduction())) {
      out.reduction = *r;
    } else {
      errors->Add(w, "reduction",
                  "missing: expected REDUCTION_MAX, REDUCTION_MAX_ABS, REDUCTION_MIN, REDUCTION_FINAL, "
                  "REDUCTION_RMS, REDUCTION_INTEGRAL, REDUCTION_RANGE or REDUCTION_MEAN");
    }
    if (c.has_window()) out.window = ConvertWindow(w.Child("window"), c.window(), study, errors);
    for (const auto& [field, present, value] :
         {std::tuple{"limit", true, c.limit()}, std::tuple{"lower", c.has_lower(), c.lower()},
          std::tuple{"upper", c.has_upper(), c.upper()}, std::tuple{"equals", c.has_equals(), c.equals()},
          std::tuple{"tolerance", true, c.tolerance()}}) {
      if (present && !std::isfinite(value)) errors->Add(w, field, "must be a finite number");
    }
    const bool bounds = c.has_lower() || c.has_upper();
    const bool limit_given = c.limit() != 0.0;
    // `equals_expr` is SI: in the constraint's unit from here on, as `equals`.
    std::optional<double> equals = c.has_equals() ? std::optional<double>(c.equals()) : std::nullopt;
    if (!c.equals_expr().empty()) {
      if (c.has_equals()) errors->Add(w, "equals_expr", "give equals or equals_expr, not both");
      const std::optional<double> si = FixedExpression(w, "equals_expr", c.equals_expr(), study, "an `equals` value", errors);
      absl::StatusOr<Unit> unit = FindUnit(c.unit());
      equals = si.has_value() && unit.ok() ? *si / unit->si_per_unit : 0.0;
    }
    if (IsWholeSeriesReduction(out.reduction)) {
      // One value per series: limit (<=), lower/upper, or equals +- tolerance.
      if (equals.has_value()) {
        if (bounds || limit_given) {
          errors->Add(w, "equals", "give equals (with tolerance) or limit or lower/upper, not several");
        }
        if (c.tolerance() < 0.0) {
          errors->Add(w, "tolerance",
                      absl::StrFormat("the half-width of the band the value may lie in: > 0, or 0 (absent) for "
                                      "%g of the value, got %g",
                                      kDefaultEqualityRelativeTolerance, c.tolerance()));
        }
        // Absent: a small share of the value (of one unit for a value of 0),
        // the band a user means by "equal".
        const double tolerance = c.tolerance() > 0.0 ? c.tolerance()
                                                     : kDefaultEqualityRelativeTolerance *
                                                           std::max(std::abs(*equals), 1.0);
        out.equals = *equals;
        out.lower = *equals - tolerance;
        out.upper = *equals + tolerance;
      } else if (bounds) {
        if (limit_given) errors->Add(w, "limit", "give limit or lower/upper, not both");
        if (c.has_lower()) out.lower = c.lower();
        if (c.has_upper()) out.upper = c.upper();
        if (out.lower && out.upper && !(*out.lower <= *out.upper)) {
          errors->Add(w, "upper", absl::StrFormat("upper (%g) is below lower (%g)", *out.upper, *out.lower));
        }
      } else {
        out.upper = c.limit();
      }
    } else {
      // One row per instant: the limit's side is the reduction's.
      if (equals.has_value() || c.tolerance() != 0.0) {
        errors->Add(w, "equals", "equals and tolerance need a reduction with one value per series (FINAL, RMS, "
                                 "INTEGRAL, RANGE, MEAN)");
      }
      const bool upper_side = out.reduction != Reduction::kMin;
      if (c.has_lower() && upper_side) {
        errors->Add(w, "lower", "REDUCTION_MAX and REDUCTION_MAX_ABS bound from above: use limit or upper");
      }
      if (c.has_upper() && !upper_side) errors->Add(w, "upper", "REDUCTION_MIN bounds from below: use limit or lower");
      if ((c.has_upper() || c.has_lower()) && limit_given) errors->Add(w, "limit", "give limit or the bound, not both");
      out.limit = c.has_upper() ? c.upper() : c.has_lower() ? c.lower() : c.limit();
      if (out.reduction == Reduction::kMaxAbs && !(out.limit > 0.0)) {
        errors->Add(w, "limit",
                    absl::StrFormat("REDUCTION_MAX_ABS needs a positive limit, got %g", out.limit));
      }
    }
    out.unit = c.unit();
    out.si_per_unit =
        UnitFactor(w, "unit", c.unit(),
                   SignalDimension(study, out.output),
                   errors);
    study.constraints.push_back(std::move(out));
  }

  // Plots for the report: names and units checked like a constraint's.
  if (m.plots_size() > kMaxXyPlots) {
    errors->Add(where, "plots", absl::StrFormat("%d plots, more than the limit of %d", m.plots_size(), kMaxXyPlots));
  }
  for (int i = 0; i < m.plots_size() && i < kMaxXyPlots; ++i) {
    const v1::XyPlot& p = m.plots(i);
    const Where w = where.Child("plots", i);
    XyPlot plot;
    plot.x = FindOutput(study, w, "x", p.x(), errors);
    plot.y = FindOutput(study, w, "y", p.y(), errors);
    plot.x_unit = p.x_unit();
    plot.y_unit = p.y_unit();
    if (plot.x >= 0) plot.x_si_per_unit = UnitFactor(w, "x_unit", p.x_unit(), SignalDimension(study, plot.x), errors);
    if (plot.y >= 0) plot.y_si_per_unit = UnitFactor(w, "y_unit", p.y_unit(), SignalDimension(study, plot.y), errors);
    study.plots.push_back(std::move(plot));
  }

  // Optimizer settings: 0 / unset keeps the default.
  if (m.has_optimizer()) {
    const Where w = where.Child("optimizer");
    const v1::OptimizerOptions& p = m.optimizer();
    OptimizerSettings& s = study.optimizer;
    auto positive = [&](const char* field, double value, std::optional<double>* target) {
      if (value < 0.0 || !std::isfinite(value)) {
        errors->Add(w, field,
                    absl::StrFormat("must be positive (0 for the default), got %g", value));
      } else if (value > 0.0) {
        *target = value;
      }
    };
    positive("initial_move_limit", p.initial_move_limit(), &s.initial_move_limit);
    positive("convergence_objective_tolerance", p.convergence_objective_tolerance(),
             &s.convergence_objective_tolerance);
    positive("convergence_violation_tolerance", p.convergence_violation_tolerance(),
             &s.convergence_violation_tolerance);
    positive("convergence_optimality_tolerance", p.convergence_optimality_tolerance(),
             &s.convergence_optimality_tolerance);
    positive("finite_difference_relative_step", p.finite_difference_relative_step(),
             &s.finite_difference_relative_step);
    // The ranges of slp::SlpOptions::Validate, checked here so that a client
    // refuses what the server would.
    if (p.initial_move_limit() > 1.0) {
      errors->Add(w, "initial_move_limit",
                  absl::StrFormat("must be at most 1 (a relative move limit; 0 for the default 0.2), got %g",
                                  p.initial_move_limit()));
    }
    if (p.finite_difference_relative_step() > 0.1) {
      errors->Add(w, "finite_difference_relative_step",
                  absl::StrFormat("must be at most 0.1 (a larger step is no derivative), got %g",
                                  p.finite_difference_relative_step()));
    }
    if (!std::isfinite(p.screening_threshold()) || p.screening_threshold() > 0.0 ||
        p.screening_threshold() < -1e6) {
      errors->Add(w, "screening_threshold",
                  absl::StrFormat("must be finite, <= 0 (a positive threshold drops violated constraints) and "
                                  ">= -1e6, got %g",
                                  p.screening_threshold()));
    }
    if (p.max_cycles() > kMaxOptimizerCycles) {
      errors->Add(w, "max_cycles", absl::StrFormat("%d is more than the limit of %d", p.max_cycles(), kMaxOptimizerCycles));
    }
    if (p.max_cycles() < 0) {
      errors->Add(w, "max_cycles", "must be positive (0 for the default)");
    } else if (p.max_cycles() > 0) {
      s.max_cycles = p.max_cycles();
    }
    if (p.screening_threshold() != 0.0) s.screening_threshold = p.screening_threshold();
    if (p.has_objective_target()) {
      if (study.objective.form == Objective::Form::kFeasible) {
        errors->Add(w, "objective_target",
                    "the study has no objective: it stops at the first design that meets its constraints; leave "
                    "objective_target out");
      } else if (!std::isfinite(p.objective_target())) {
        errors->Add(w, "objective_target", "must be a finite number");
      } else {
        s.objective_target = p.objective_target();
      }
    }
    s.central_differences = p.finite_difference() == v1::FINITE_DIFFERENCE_CENTRAL;
    s.simulator_sensitivities = p.sensitivity() == v1::SENSITIVITY_METHOD_SIMULATOR;
    if (s.simulator_sensitivities && std::holds_alternative<LinkageModel>(scene.model)) {
      errors->Add(w, "sensitivity",
                  "SENSITIVITY_METHOD_SIMULATOR is not available for this formulation: linkage scenes have no "
                  "simulator sensitivities (write the mechanism as a multibody scene, or use finite differences)");
    }
    // The explicit path carries no sensitivity equations; the derivatives
    // would have to come from IDAS, another integrator than the values'.
    if (s.simulator_sensitivities && scene.integrator.method == IntegratorMethod::kExplicitRungeKutta) {
      errors->Add(w, "sensitivity",
                  "SENSITIVITY_METHOD_SIMULATOR is not available with the scene's integrator { method: "
                  "EXPLICIT_RUNGE_KUTTA }: use integrator method IDAS (the default), or finite differences");
    }
  }

  study.design_set = ConvertDesignSet(m, study, where, errors);
  if (m.pareto().has_objective()) {
    study.second_objective =
        ConvertObjective(m.pareto().objective(), study, where.Child("pareto").Child("objective"), errors);
  }
  study.pareto = ConvertPareto(m, study, where, errors);

  if (errors->empty()) {
    // Catch what only the layout sees (e.g. minimize on a multi-series output).
    absl::StatusOr<StudyLayout> layout = MakeStudyLayout(study);
    if (!layout.ok()) errors->AddRaw(std::string(layout.status().message()));
  }
  return study;
}

}  // namespace mbopt::spec::io
