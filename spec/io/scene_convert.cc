#include "spec/io/scene_convert.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "spec/io/scene_converter.h"
#include "spec/limits.h"

namespace mbopt::spec::io {

Scene SceneConverter::Run() {
  scene_.name = msg_.name();
  scene_.source_file = where_.file();
  ConvertParameters();
  ConvertEffects();
  switch (msg_.model_case()) {
    case v1::Scene::kLinkage:
      scene_.model = ConvertLinkage(msg_.linkage(), where_.Child("linkage"));
      break;
    case v1::Scene::kLumped:
      scene_.model = ConvertLumped(msg_.lumped(), where_.Child("lumped"));
      break;
    case v1::Scene::kMultibody:
      scene_.model = ConvertMultibody(msg_.multibody(), where_.Child("multibody"));
      break;
    case v1::Scene::kExternal:
      scene_.model = ConvertExternal(msg_.external(), where_.Child("external"));
      break;
    case v1::Scene::kFmu:
      scene_.model = ConvertFmu(msg_.fmu(), where_.Child("fmu"));
      break;
    case v1::Scene::kSpatial:
      scene_.model = ConvertSpatial(msg_.spatial(), where_.Child("spatial"));
      break;
    case v1::Scene::MODEL_NOT_SET:
      errors_.Add(where_, "",
                  "the scene has no model: expected `linkage { ... }`, `lumped { ... }`, "
                  "`multibody { ... }`, `spatial { ... }`, `external { ... }` or `fmu { ... }`");
      return scene_;
  }
  if (msg_.model_case() == v1::Scene::kLumped && msg_.has_effects()) {
    // Silently ignoring a declared effect would give wrong answers.
    if (msg_.effects().has_gravity()) {
      errors_.Add(where_.Child("effects"), "gravity",
                  "a lumped model moves by small amounts about its static equilibrium, where gravity is "
                  "balanced by the spring preloads, so it has no gravity to declare; for a mechanism that moves "
                  "under its own weight (large motions, gravity doing work) write it as a `multibody` scene, "
                  "which takes `effects { gravity { ... } }`");
    }
    if (msg_.effects().has_structural_damping()) {
      errors_.Add(where_.Child("effects"), "structural_damping",
                  "structural damping applies to flexible links; a lumped model takes its "
                  "damping from its elements");
    }
  }
  if (msg_.model_case() == v1::Scene::kExternal && msg_.has_effects()) {
    // The driver's simulator models what it models; an effect declared
    // here would be silently ignored.
    errors_.Add(where_, "effects",
                "an external scene's effects are its driver's: declare gravity or damping in the "
                "simulator's own input, through the driver's parameters");
  }
  if (msg_.model_case() == v1::Scene::kFmu && msg_.has_effects()) {
    errors_.Add(where_.Child("effects"), "",
                "an FMU scene's physics is the FMU's: it takes no effects (set them as FMU parameters)");
  }
  if (msg_.model_case() == v1::Scene::kSpatial && msg_.has_effects()) {
    // Effects' gravity is a planar vector: a spatial model declares its own.
    errors_.Add(where_, "effects",
                "a spatial scene takes no `effects`: declare gravity in the model, "
                "`spatial { gravity { acceleration_m_per_s2 { z { value: -9.81 } } } }`");
  }
  if (const auto* mb = std::get_if<MultibodyModel>(&scene_.model);
      mb != nullptr && mb->flexible_links.empty() && msg_.effects().has_structural_damping()) {
    errors_.Add(where_.Child("effects"), "structural_damping",
                "structural damping applies to flexible links; this multibody model has none");
  }
  ConvertOutputs();
  ConvertGrid();
  ConvertIntegrator();
  return scene_;
}

void SceneConverter::ConvertEffects() {
  if (!msg_.has_effects()) return;
  const Where w = where_.Child("effects");
  const v1::Effects& e = msg_.effects();
  if (e.has_gravity()) {
    const Where g = w.Child("gravity");
    scene_.effects.gravity_m_per_s2 =
        Vec(g, "acceleration_m_per_s2", e.gravity().has_acceleration_m_per_s2(),
            e.gravity().acceleration_m_per_s2(), Dimension::kAcceleration);
  }
  if (e.has_structural_damping()) {
    const double ratio = e.structural_damping().ratio_of_critical();
    if (!(ratio >= 0.0) || !std::isfinite(ratio)) {
      errors_.Add(w.Child("structural_damping"), "ratio_of_critical",
                  absl::StrFormat("must not be negative, got %g", ratio));
    }
    scene_.effects.structural_damping_ratio = ratio;
  }
}

void SceneConverter::ConvertGrid() {
  if (!msg_.has_time_grid()) {
    errors_.Add(where_, "time_grid",
                "missing: expected `time_grid { start_s: .. end_s: .. "
                "points: .. }`");
    return;
  }
  const Where w = where_.Child("time_grid");
  v1::TimeGrid g = msg_.time_grid();
  // An end written as an expression becomes its value here: the checks
  // below then see numbers, as if the file had written them.
  for (const auto& [field, expr, set] :
       {std::tuple{"start_expr", g.start_expr(), &v1::TimeGrid::set_start_s},
        std::tuple{"end_expr", g.end_expr(), &v1::TimeGrid::set_end_s}}) {
    if (expr.empty()) continue;
    const std::string number_field = std::string(field) == "start_expr" ? "start_s" : "end_s";
    if ((number_field == "start_s" ? g.start_s() : g.end_s()) != 0.0) {
      errors_.Add(w, field, absl::StrCat("give ", number_field, " or ", field, ", not both"));
    }
    absl::StatusOr<std::shared_ptr<const Expression>> parsed = Expression::Parse(expr, ParameterNames());
    if (!parsed.ok()) {
      errors_.Add(w, field, std::string(parsed.status().message()));
      continue;
    }
    (g.*set)((*parsed)->Evaluate(scene_.DefaultParameterValues()));
    for (int p : (*parsed)->parameters()) scene_.time_grid_parameters_read.push_back(p);
  }
  std::sort(scene_.time_grid_parameters_read.begin(), scene_.time_grid_parameters_read.end());
  scene_.time_grid_parameters_read.erase(
      std::unique(scene_.time_grid_parameters_read.begin(), scene_.time_grid_parameters_read.end()),
      scene_.time_grid_parameters_read.end());
  scene_.time_grid.start_s = g.start_s();
  scene_.time_grid.end_s = g.end_s();
  scene_.time_grid.points = g.points();
  if (g.points() > kMaxTimeGridPoints) {
    errors_.Add(w, "points", absl::StrCat(g.points(), " is more than the limit of ", kMaxTimeGridPoints, " instants"));
  }
  if (g.points() < 1) {
    errors_.Add(w, "points", absl::StrCat("must be at least 1, got ", g.points()));
  }
  if (!std::isfinite(g.start_s()) || g.start_s() < 0.0) {
    errors_.Add(w, "start_s",
                absl::StrFormat("must be >= 0 (the simulation starts at "
                                "t = 0), got %g",
                                g.start_s()));
  }
  if (!std::isfinite(g.end_s()) || g.end_s() < g.start_s()) {
    errors_.Add(w, "end_s",
                absl::StrFormat("must be >= start_s (%g), got %g", g.start_s(), g.end_s()));
  }
  if (g.points() > 1 && g.end_s() == g.start_s()) {
    errors_.Add(w, "end_s", "several points need end_s > start_s");
  }
}

void SceneConverter::ConvertIntegrator() {
  if (!msg_.has_integrator()) return;
  const Where w = where_.Child("integrator");
  const v1::IntegratorSettings& s = msg_.integrator();
  IntegratorSettings& out = scene_.integrator;
  if (s.relative_tolerance() < 0.0 || !std::isfinite(s.relative_tolerance())) {
    errors_.Add(w, "relative_tolerance", "must be positive (0 for the default 1e-6)");
  } else if (s.relative_tolerance() > 0.0) {
    out.relative_tolerance = s.relative_tolerance();
  }
  if (s.absolute_tolerance() < 0.0 || !std::isfinite(s.absolute_tolerance())) {
    errors_.Add(w, "absolute_tolerance", "must be positive (0 for the default 1e-9)");
  } else if (s.absolute_tolerance() > 0.0) {
    out.absolute_tolerance = s.absolute_tolerance();
  }
  if (s.max_steps() > kMaxIntegratorSteps) {
    errors_.Add(w, "max_steps", absl::StrCat(s.max_steps(), " is more than the limit of ", kMaxIntegratorSteps));
  } else if (s.max_steps() < 0) {
    errors_.Add(w, "max_steps", "must be positive (0 for the default 100000)");
  } else if (s.max_steps() > 0) {
    out.max_steps = static_cast<long>(s.max_steps());
  }
  switch (s.method()) {
    case v1::IDAS:
      out.method = IntegratorMethod::kIdas;
      break;
    case v1::EXPLICIT_RUNGE_KUTTA:
      // The rigid-body engines (planar and spatial) have the explicit path;
      // a lumped model's stiff network and a flexible link's stiff axial and
      // bending modes would hold its step to their stability limit.
      if (msg_.model_case() != v1::Scene::kMultibody && msg_.model_case() != v1::Scene::kSpatial) {
        errors_.Add(w, "method", "EXPLICIT_RUNGE_KUTTA applies to `multibody` and `spatial` scenes only");
      } else if (msg_.multibody().flexible_links_size() > 0) {
        errors_.Add(w, "method",
                    "EXPLICIT_RUNGE_KUTTA does not apply to a scene with flexible links: their axial and bending "
                    "vibrations are stiff; use IDAS (the default)");
      } else {
        out.method = IntegratorMethod::kExplicitRungeKutta;
      }
      break;
    default:
      errors_.Add(w, "method", absl::StrCat("unknown integrator method ", static_cast<int>(s.method())));
  }
  if (s.max_wall_seconds() < 0.0 || !std::isfinite(s.max_wall_seconds())) {
    errors_.Add(w, "max_wall_seconds",
                absl::StrCat("must be positive (0 for the default ", kDefaultAnalysisWallSeconds, " s)"));
  } else if (s.max_wall_seconds() > kMaxAnalysisWallSeconds) {
    errors_.Add(w, "max_wall_seconds",
                absl::StrCat(s.max_wall_seconds(), " is more than the limit of ", kMaxAnalysisWallSeconds,
                             " s (7 days)"));
  } else if (s.max_wall_seconds() > 0.0) {
    out.max_wall_seconds = s.max_wall_seconds();
  }
}

Scene ConvertScene(const v1::Scene& message, const Where& where, Errors* errors) {
  return SceneConverter(message, where, errors).Run();
}

}  // namespace mbopt::spec::io
