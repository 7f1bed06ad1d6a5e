// The scene's parameters (values and expressions) and the numbers, vectors,
// directions and sections every model kind reads through them.
#include "spec/io/scene_converter.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "spec/io/declared_name.h"

namespace mbopt::spec::io {

void SceneConverter::ConvertParameters() {
  std::set<std::string> seen;
  for (int i = 0; i < msg_.parameters_size(); ++i) {
    const v1::Parameter& p = msg_.parameters(i);
    const Where w = where_.Child("parameters", i);
    Parameter out;
    out.name = p.name();
    out.unit = p.unit();
    CheckDeclaredName(w, p.name(), seen.insert(p.name()).second,
                      {.missing = "a parameter needs a name", .duplicate = "parameter name"}, &errors_);
    absl::StatusOr<Unit> unit = FindUnit(p.unit());
    if (!unit.ok()) {
      errors_.Add(w, "unit", std::string(unit.status().message()));
    } else {
      out.si_per_unit = unit->si_per_unit;
    }
    if (!std::isfinite(p.value())) errors_.Add(w, "value", "must be a finite number");
    if (!p.expr().empty() && p.value() != 0.0) errors_.Add(w, "expr", "give value or expr, not both");
    out.value_si = p.value() * out.si_per_unit;
    units_.push_back(unit.ok() ? unit->dimension : Dimension::kAny);
    scene_.parameters.push_back(std::move(out));
  }
  // Expressions after every name is known, so one may read a parameter
  // written below it.
  resolve_state_.assign(scene_.parameters.size(), ResolveState::kUnresolved);
  scene_.parameter_expressions.assign(scene_.parameters.size(), nullptr);
  for (int i = 0; i < msg_.parameters_size(); ++i) {
    if (!msg_.parameters(i).expr().empty()) (void)ResolveParameter(i);
  }
  for (int i = 0; i < msg_.parameters_size(); ++i) {
    // Its value at the defaults of the parameters it reads.
    if (const auto expression = scene_.ParameterExpression(i)) {
      scene_.parameters[static_cast<size_t>(i)].value_si = expression->Evaluate(scene_.DefaultParameterValues());
    }
  }
  for (int i = 0; i < msg_.parameters_size(); ++i) {
    const Parameter& parameter = scene_.parameters[static_cast<size_t>(i)];
    if (scene_.ParameterExpression(i) != nullptr && !std::isfinite(parameter.value_si)) {
      errors_.Add(where_.Child("parameters", i), "expr",
                  absl::StrCat("\"", msg_.parameters(i).expr(), "\" is ", parameter.value_si,
                               " at the other parameters' values"));
    }
  }
}

// The names of a scene's expressions: its parameters, those written as
// `expr` standing for their expressions.
Expression::Names SceneConverter::ParameterNames() {
  Expression::Names names;
  names.find = [this](const std::string& name) -> std::optional<int> {
    const int index = scene_.FindParameter(name);
    return index >= 0 ? std::optional<int>(index) : std::nullopt;
  };
  for (const Parameter& parameter : scene_.parameters) names.all.push_back(parameter.name);
  names.expand = [this](const std::string& name) -> absl::StatusOr<std::shared_ptr<const Expression>> {
    const int index = scene_.FindParameter(name);
    if (index < 0 || index >= msg_.parameters_size() || msg_.parameters(index).expr().empty()) return nullptr;
    if (absl::Status s = ResolveParameter(index); !s.ok()) return s;
    return scene_.ParameterExpression(index);
  };
  return names;
}

// Parses parameter i's `expr` once, after those it reads. A parameter met
// again while its own expression is being read closes a cycle, refused
// with the cycle's names.
absl::Status SceneConverter::ResolveParameter(int i) {
  const size_t at = static_cast<size_t>(i);
  switch (resolve_state_[at]) {
    case ResolveState::kResolved:
      return absl::OkStatus();
    case ResolveState::kFailed:
      return absl::InvalidArgumentError(
          absl::StrCat("parameter \"", scene_.parameters[at].name, "\" has an expression that is refused"));
    case ResolveState::kResolving: {
      std::vector<std::string> cycle;
      const auto from = std::find(resolving_.begin(), resolving_.end(), i);
      for (auto it = from; it != resolving_.end(); ++it) cycle.push_back(scene_.parameters[static_cast<size_t>(*it)].name);
      cycle.push_back(scene_.parameters[at].name);
      const std::string text = absl::StrCat(
          "parameters read each other in a cycle: ", absl::StrJoin(cycle, " -> "),
          "; one of them must be a value (`value: ...`), not an expression");
      if (!cycle_reported_) errors_.Add(where_.Child("parameters", i), "expr", text);
      cycle_reported_ = true;
      return absl::InvalidArgumentError(text);
    }
    case ResolveState::kUnresolved:
      break;
  }
  resolve_state_[at] = ResolveState::kResolving;
  resolving_.push_back(i);
  absl::StatusOr<std::shared_ptr<const Expression>> parsed =
      Expression::Parse(msg_.parameters(i).expr(), ParameterNames());
  resolving_.pop_back();
  if (!parsed.ok()) {
    resolve_state_[at] = ResolveState::kFailed;
    // A cycle is reported once, where it closed; the parameters on it fail too.
    if (!cycle_reported_ || parsed.status().message().find("in a cycle") == std::string_view::npos) {
      errors_.Add(where_.Child("parameters", i), "expr", std::string(parsed.status().message()));
    }
    return parsed.status();
  }
  scene_.parameter_expressions[at] = *std::move(parsed);
  resolve_state_[at] = ResolveState::kResolved;
  return absl::OkStatus();
}

// A Number field `field` of the message at `w`; `present` says whether the
// field was given. Absent: `fallback` if it is set, else an error.
Number SceneConverter::Num(const Where& w, const std::string& field, bool present, const v1::Number& n,
           Dimension dimension, std::optional<double> fallback) {
  Number out;
  if (!present) {
    if (fallback) {
      out.value = *fallback;
    } else {
      errors_.Add(w, field,
                  absl::StrFormat("missing: expected a number in SI (%s), "
                                  "`{ value: ... }` or `{ param: \"name\" }`",
                                  DimensionName(dimension)));
    }
    return out;
  }
  switch (n.source_case()) {
    case v1::Number::kValue:
      if (!std::isfinite(n.value())) errors_.Add(w, field, "must be a finite number");
      out.value = n.value();
      break;
    case v1::Number::kParam: {
      out.param = scene_.FindParameter(n.param());
      if (out.param < 0) {
        errors_.Add(w, field, absl::StrCat("unknown parameter \"", n.param(), "\""));
      } else {
        const Dimension unit_dimension = units_[static_cast<size_t>(out.param)];
        if (unit_dimension != Dimension::kAny && dimension != Dimension::kAny &&
            unit_dimension != dimension) {
          errors_.Add(w, field,
                      absl::StrFormat("parameter \"%s\" has unit \"%s\" (%s) but this field "
                                      "is a %s",
                                      n.param(), scene_.parameters[out.param].unit,
                                      DimensionName(unit_dimension), DimensionName(dimension)));
        }
        // A parameter written as `expr`: the field follows its expression.
        if (const auto expression = scene_.ParameterExpression(out.param)) {
          out.expression = expression;
          out.param = -1;
        }
      }
      break;
    }
    case v1::Number::kExpr: {
      absl::StatusOr<std::shared_ptr<const Expression>> parsed = Expression::Parse(n.expr(), ParameterNames());
      if (!parsed.ok()) {
        errors_.Add(w, field, std::string(parsed.status().message()));
        break;
      }
      out.expression = *std::move(parsed);
      // Caught here, not in every analysis: an expression that cannot be
      // evaluated at the parameters' defaults (a division by zero, the
      // root of a negative number).
      const double at_defaults = out.expression->Evaluate(scene_.DefaultParameterValues());
      if (!std::isfinite(at_defaults)) {
        errors_.Add(w, field,
                    absl::StrCat("\"", n.expr(), "\" is ", at_defaults, " at the parameters' default values"));
      }
      break;
    }
    case v1::Number::SOURCE_NOT_SET:
      errors_.Add(w, field, "empty number: expected `value: ...`, `param: \"name\"` or `expr: \"...\"`");
      break;
  }
  return out;
}

void SceneConverter::RequirePositive(const Where& w, const std::string& field, const Number& n) {
  const double v = Default(n);
  if (!(v > 0.0)) {
    errors_.Add(w, field, absl::StrFormat("must be positive, got %g (SI)", v));
  }
}

void SceneConverter::RequireNotNegative(const Where& w, const std::string& field, const Number& n) {
  const double v = Default(n);
  if (!(v >= 0.0)) {
    errors_.Add(w, field, absl::StrFormat("must not be negative, got %g (SI)", v));
  }
}

Vec2 SceneConverter::Vec(const Where& w, const std::string& field, bool present, const v1::Vector2& v,
         Dimension dimension) {
  Vec2 out;
  if (!present) return out;  // (0, 0)
  const Where c = w.Child(field);
  out.x = Num(c, "x", v.has_x(), v.x(), dimension, 0.0);
  out.y = Num(c, "y", v.has_y(), v.y(), dimension, 0.0);
  return out;
}

// A fixed unit direction: literal numbers, not zero; normalized here.
void SceneConverter::Direction(const Where& w, const std::string& field, bool present, const v1::Vector2& v,
               double* dx, double* dy) {
  if (!present) {
    errors_.Add(w, field,
                "missing: expected a direction vector `{ x { value: 0 } y { value: 1 } }`");
    return;
  }
  const Where c = w.Child(field);
  if ((v.has_x() && v.x().has_param()) || (v.has_y() && v.y().has_param())) {
    errors_.Add(w, field, "a direction must be literal values, not parameters");
    return;
  }
  const double x = v.has_x() ? v.x().value() : 0.0;
  const double y = v.has_y() ? v.y().value() : 0.0;
  const double norm = std::hypot(x, y);
  if (!(norm > 0.0) || !std::isfinite(norm)) {
    errors_.Add(w, field,
                absl::StrFormat("zero direction vector (%g, %g): expected a "
                                "non-zero vector",
                                x, y));
    return;
  }
  *dx = x / norm;
  *dy = y / norm;
}

Section SceneConverter::ConvertSection(const Where& sw, const v1::Section& s) {
  Section section;
  section.area_m2 = Num(sw, "area_m2", s.has_area_m2(), s.area_m2(), Dimension::kArea);
  RequirePositive(sw, "area_m2", section.area_m2);
  section.youngs_modulus_pa = Num(sw, "youngs_modulus_pa", s.has_youngs_modulus_pa(),
                                  s.youngs_modulus_pa(), Dimension::kPressure);
  RequirePositive(sw, "youngs_modulus_pa", section.youngs_modulus_pa);
  section.density_kg_per_m3 = Num(sw, "density_kg_per_m3", s.has_density_kg_per_m3(),
                                  s.density_kg_per_m3(), Dimension::kDensity);
  RequirePositive(sw, "density_kg_per_m3", section.density_kg_per_m3);
  return section;
}

}  // namespace mbopt::spec::io
