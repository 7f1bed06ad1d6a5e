#include "spec/io/scene_convert.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "spec/layout.h"
#include "spec/limits.h"
#include "spec/units.h"

namespace mbopt::spec::io {
namespace {

class SceneConverter {
 public:
  SceneConverter(const v1::Scene& message, const Where& where, Errors* errors)
      : msg_(message), where_(where), errors_(*errors) {}

  Scene Run() {
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
      case v1::Scene::MODEL_NOT_SET:
        errors_.Add(where_, "",
                    "the scene has no model: expected `linkage { ... }`, `lumped { ... }`, "
                    "`multibody { ... }`, `external { ... }` or `fmu { ... }`");
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

 private:
  void ConvertParameters() {
    std::set<std::string> seen;
    for (int i = 0; i < msg_.parameters_size(); ++i) {
      const v1::Parameter& p = msg_.parameters(i);
      const Where w = where_.Child("parameters", i);
      Parameter out;
      out.name = p.name();
      out.unit = p.unit();
      if (p.name().empty()) errors_.Add(w, "name", "a parameter needs a name");
      if (!seen.insert(p.name()).second) {
        errors_.Add(w, "name", absl::StrCat("duplicate parameter name \"", p.name(), "\""));
      }
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
  Expression::Names ParameterNames() {
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
  absl::Status ResolveParameter(int i) {
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
  Number Num(const Where& w, const std::string& field, bool present, const v1::Number& n,
             Dimension dimension, std::optional<double> fallback = std::nullopt) {
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

  double Default(const Number& n) const { return n.Resolve(scene_.DefaultParameterValues()); }

  void RequirePositive(const Where& w, const std::string& field, const Number& n) {
    const double v = Default(n);
    if (!(v > 0.0)) {
      errors_.Add(w, field, absl::StrFormat("must be positive, got %g (SI)", v));
    }
  }
  void RequireNotNegative(const Where& w, const std::string& field, const Number& n) {
    const double v = Default(n);
    if (!(v >= 0.0)) {
      errors_.Add(w, field, absl::StrFormat("must not be negative, got %g (SI)", v));
    }
  }

  Vec2 Vec(const Where& w, const std::string& field, bool present, const v1::Vector2& v,
           Dimension dimension) {
    Vec2 out;
    if (!present) return out;  // (0, 0)
    const Where c = w.Child(field);
    out.x = Num(c, "x", v.has_x(), v.x(), dimension, 0.0);
    out.y = Num(c, "y", v.has_y(), v.y(), dimension, 0.0);
    return out;
  }

  // A fixed unit direction: literal numbers, not zero; normalized here.
  void Direction(const Where& w, const std::string& field, bool present, const v1::Vector2& v,
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

  void ConvertEffects() {
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

  // ------------------------------------------------------------- lumped --
  LumpedModel ConvertLumped(const v1::LumpedModel& m, const Where& w) {
    LumpedModel out;
    std::map<std::string, int> bodies, inputs;
    for (int i = 0; i < m.bodies_size(); ++i) {
      const v1::Body& b = m.bodies(i);
      const Where bw = w.Child("bodies", i);
      Body body;
      body.name = b.name();
      if (b.name().empty()) errors_.Add(bw, "name", "a body needs a name");
      if (!bodies.emplace(b.name(), i).second) {
        errors_.Add(bw, "name", absl::StrCat("duplicate body name \"", b.name(), "\""));
      }
      std::set<int> dofs;
      for (int d = 0; d < b.dofs_size(); ++d) {
        if (!dofs.insert(b.dofs(d)).second) {
          errors_.Add(bw, "dofs", d, "duplicate degree of freedom");
          continue;
        }
        switch (b.dofs(d)) {
          case v1::DOF_X:
            body.dofs.push_back(Dof::kX);
            break;
          case v1::DOF_Y:
            body.dofs.push_back(Dof::kY);
            break;
          case v1::DOF_ROTATION:
            body.dofs.push_back(Dof::kRotation);
            break;
          default:
            errors_.Add(bw, "dofs", d, "expected DOF_X, DOF_Y or DOF_ROTATION");
        }
      }
      const bool translates = dofs.count(v1::DOF_X) > 0 || dofs.count(v1::DOF_Y) > 0;
      const bool rotates = dofs.count(v1::DOF_ROTATION) > 0;
      body.mass_kg = Num(bw, "mass_kg", b.has_mass_kg(), b.mass_kg(), Dimension::kMass,
                         translates ? std::nullopt : std::optional<double>(0.0));
      if (translates) RequirePositive(bw, "mass_kg", body.mass_kg);
      body.inertia_kg_m2 =
          Num(bw, "inertia_kg_m2", b.has_inertia_kg_m2(), b.inertia_kg_m2(), Dimension::kInertia,
              rotates ? std::nullopt : std::optional<double>(0.0));
      if (rotates) RequirePositive(bw, "inertia_kg_m2", body.inertia_kg_m2);
      body.position_m =
          Vec(bw, "position_m", b.has_position_m(), b.position_m(), Dimension::kLength);
      out.bodies.push_back(std::move(body));
    }
    if (m.bodies_size() == 0) errors_.Add(w, "bodies", "a lumped model needs at least one body");
    for (int i = 0; i < m.inputs_size(); ++i) {
      const v1::GroundInput& g = m.inputs(i);
      const Where iw = w.Child("inputs", i);
      GroundInput input;
      input.name = g.name();
      if (g.name().empty()) errors_.Add(iw, "name", "an input needs a name");
      if (!inputs.emplace(g.name(), i).second) {
        errors_.Add(iw, "name", absl::StrCat("duplicate input name \"", g.name(), "\""));
      }
      if (g.profile_case() != v1::GroundInput::kCosineBump) {
        errors_.Add(iw, "", "missing profile: expected `cosine_bump { ... }`");
      } else {
        const Where cw = iw.Child("cosine_bump");
        const v1::CosineBump& c = g.cosine_bump();
        input.bump.height_m =
            Num(cw, "height_m", c.has_height_m(), c.height_m(), Dimension::kLength);
        input.bump.length_m =
            Num(cw, "length_m", c.has_length_m(), c.length_m(), Dimension::kLength);
        RequirePositive(cw, "length_m", input.bump.length_m);
        input.bump.speed_m_per_s = Num(cw, "speed_m_per_s", c.has_speed_m_per_s(),
                                       c.speed_m_per_s(), Dimension::kVelocity);
        RequirePositive(cw, "speed_m_per_s", input.bump.speed_m_per_s);
        input.bump.start_time_s =
            Num(cw, "start_time_s", c.has_start_time_s(), c.start_time_s(), Dimension::kTime, 0.0);
      }
      input.delay_s = Num(iw, "delay_s", g.has_delay_s(), g.delay_s(), Dimension::kTime, 0.0);
      Direction(iw, "direction", g.has_direction(), g.direction(), &input.direction_x,
                &input.direction_y);
      out.inputs.push_back(std::move(input));
    }
    std::set<std::string> element_names;
    for (int i = 0; i < m.elements_size(); ++i) {
      const v1::SpringDamper& e = m.elements(i);
      const Where ew = w.Child("elements", i);
      SpringDamper element;
      element.name = e.name();
      if (e.name().empty()) errors_.Add(ew, "name", "an element needs a name");
      if (!element_names.insert(e.name()).second) {
        errors_.Add(ew, "name", absl::StrCat("duplicate element name \"", e.name(), "\""));
      }
      element.a = Attach(ew, "a", e.has_a(), e.a(), bodies, inputs);
      element.b = Attach(ew, "b", e.has_b(), e.b(), bodies, inputs);
      Direction(ew, "direction", e.has_direction(), e.direction(), &element.direction_x,
                &element.direction_y);
      element.stiffness_n_per_m = Num(ew, "stiffness_n_per_m", e.has_stiffness_n_per_m(),
                                      e.stiffness_n_per_m(), Dimension::kStiffness, 0.0);
      RequireNotNegative(ew, "stiffness_n_per_m", element.stiffness_n_per_m);
      element.damping_n_s_per_m = Num(ew, "damping_n_s_per_m", e.has_damping_n_s_per_m(),
                                      e.damping_n_s_per_m(), Dimension::kDamping, 0.0);
      RequireNotNegative(ew, "damping_n_s_per_m", element.damping_n_s_per_m);
      out.elements.push_back(std::move(element));
    }
    lumped_bodies_ = bodies;
    lumped_elements_.clear();
    for (size_t i = 0; i < out.elements.size(); ++i) {
      lumped_elements_.emplace(out.elements[i].name, static_cast<int>(i));
    }
    return out;
  }

  Attachment Attach(const Where& w, const std::string& field, bool present, const v1::Attachment& a,
                    const std::map<std::string, int>& bodies,
                    const std::map<std::string, int>& inputs) {
    Attachment out;
    if (!present) {
      errors_.Add(w, field,
                  "missing: expected `{ body: \"name\" }`, `{ input: \"name\" }` or "
                  "`{ ground: true }`");
      return out;
    }
    const Where aw = w.Child(field);
    switch (a.target_case()) {
      case v1::Attachment::kBody: {
        out.kind = Attachment::Kind::kBody;
        auto it = bodies.find(a.body());
        if (it == bodies.end()) {
          errors_.Add(aw, "body", absl::StrCat("unknown body \"", a.body(), "\""));
        } else {
          out.index = it->second;
        }
        out.offset_m = Vec(aw, "offset_m", a.has_offset_m(), a.offset_m(), Dimension::kLength);
        break;
      }
      case v1::Attachment::kInput: {
        out.kind = Attachment::Kind::kInput;
        auto it = inputs.find(a.input());
        if (it == inputs.end()) {
          errors_.Add(aw, "input", absl::StrCat("unknown input \"", a.input(), "\""));
        } else {
          out.index = it->second;
        }
        break;
      }
      case v1::Attachment::kGround:
        out.kind = Attachment::Kind::kGround;
        break;
      case v1::Attachment::TARGET_NOT_SET:
        errors_.Add(w, field, "expected `body: \"name\"`, `input: \"name\"` or `ground: true`");
        break;
    }
    if (a.has_offset_m() && out.kind != Attachment::Kind::kBody) {
      errors_.Add(aw, "offset_m", "an offset is only meaningful on a body attachment");
    }
    return out;
  }

  // ------------------------------------------------------------ linkage --
  LinkageModel ConvertLinkage(const v1::LinkageModel& m, const Where& w) {
    LinkageModel out;
    std::map<std::string, int> joints;
    for (int i = 0; i < m.joints_size(); ++i) {
      const v1::Joint& j = m.joints(i);
      const Where jw = w.Child("joints", i);
      Joint joint;
      joint.name = j.name();
      joint.ground = j.ground();
      if (j.name().empty()) errors_.Add(jw, "name", "a joint needs a name");
      if (!joints.emplace(j.name(), i).second) {
        errors_.Add(jw, "name", absl::StrCat("duplicate joint name \"", j.name(), "\""));
      }
      if (!j.has_position_m())
        errors_.Add(jw, "position_m", "missing: expected the joint's position");
      joint.position_m =
          Vec(jw, "position_m", j.has_position_m(), j.position_m(), Dimension::kLength);
      out.joints.push_back(std::move(joint));
    }
    auto joint_index = [&](const Where& at, const std::string& field, const std::string& name) {
      auto it = joints.find(name);
      if (it == joints.end()) {
        errors_.Add(at, field, absl::StrCat("unknown joint \"", name, "\""));
        return -1;
      }
      return it->second;
    };
    std::map<std::string, int> links;
    for (int i = 0; i < m.links_size(); ++i) {
      const v1::Link& l = m.links(i);
      const Where lw = w.Child("links", i);
      Link link;
      link.name = l.name();
      if (l.name().empty()) errors_.Add(lw, "name", "a link needs a name");
      if (!links.emplace(l.name(), i).second) {
        errors_.Add(lw, "name", absl::StrCat("duplicate link name \"", l.name(), "\""));
      }
      link.joint_a = joint_index(lw, "joint_a", l.joint_a());
      link.joint_b = joint_index(lw, "joint_b", l.joint_b());
      if (link.joint_a >= 0 && link.joint_a == link.joint_b) {
        errors_.Add(lw, "joint_b", "a link needs two different joints");
      }
      if (l.has_length_m()) {
        link.length_m = Num(lw, "length_m", true, l.length_m(), Dimension::kLength);
        RequirePositive(lw, "length_m", *link.length_m);
      }
      if (l.has_section()) link.section = ConvertSection(lw.Child("section"), l.section());
      if (l.has_flexible()) {
        if (l.flexible().elements() < 1 || l.flexible().elements() > kMaxLinkageFlexibleElements) {
          errors_.Add(lw.Child("flexible"), "elements",
                      absl::StrCat("a flexible link needs 1 to ", kMaxLinkageFlexibleElements, " elements, got ",
                                   l.flexible().elements()));
        }
        if (!l.has_section()) {
          errors_.Add(lw, "section", "a flexible link needs a section");
        }
        link.flexible_elements = std::max(1, l.flexible().elements());
        link.rotary_inertia = l.flexible().rotary_inertia();
      }
      std::set<std::string> points;
      for (int p = 0; p < l.points_size(); ++p) {
        const Where pw = lw.Child("points", p);
        LinkPoint point;
        point.name = l.points(p).name();
        if (point.name.empty()) errors_.Add(pw, "name", "a point needs a name");
        if (!points.insert(point.name).second) {
          errors_.Add(pw, "name", absl::StrCat("duplicate point name \"", point.name, "\""));
        }
        point.position_m = Vec(pw, "position_m", l.points(p).has_position_m(),
                               l.points(p).position_m(), Dimension::kLength);
        link.points.push_back(std::move(point));
      }
      out.links.push_back(std::move(link));
    }
    if (m.links_size() == 0) errors_.Add(w, "links", "a linkage needs at least one link");
    if (!m.has_driver()) {
      errors_.Add(w, "driver",
                  "missing: a linkage is driven at a prescribed speed, so it needs its driven link and pivot; to "
                  "let the mechanism move freely (under its loads, gravity or springs, with no driver) write it as "
                  "a `multibody` scene, whose drivers are optional (docs/scene.md)");
    } else {
      const Where dw = w.Child("driver");
      const v1::Driver& d = m.driver();
      auto it = links.find(d.link());
      if (it == links.end()) {
        errors_.Add(dw, "link", absl::StrCat("unknown link \"", d.link(), "\""));
      } else {
        out.driver.link = it->second;
      }
      out.driver.pivot_joint = joint_index(dw, "pivot_joint", d.pivot_joint());
      if (out.driver.link >= 0 && out.driver.pivot_joint >= 0) {
        const Link& link = out.links[static_cast<size_t>(out.driver.link)];
        if (link.joint_a != out.driver.pivot_joint && link.joint_b != out.driver.pivot_joint) {
          errors_.Add(dw, "pivot_joint",
                      absl::StrCat("joint \"", d.pivot_joint(), "\" is not an end of link \"",
                                   d.link(), "\""));
        } else if (!out.joints[static_cast<size_t>(out.driver.pivot_joint)].ground) {
          errors_.Add(
              dw, "pivot_joint",
              absl::StrCat("the driver's pivot \"", d.pivot_joint(), "\" must be a ground joint"));
        }
      }
      if (d.has_start_angle_rad()) {
        out.driver.start_angle_rad =
            Num(dw, "start_angle_rad", true, d.start_angle_rad(), Dimension::kAngle);
      }
      out.driver.angular_velocity_rad_per_s =
          Num(dw, "angular_velocity_rad_per_s", d.has_angular_velocity_rad_per_s(),
              d.angular_velocity_rad_per_s(), Dimension::kAngularVelocity);
    }
    switch (m.flexible_formulation()) {
      case v1::FLEXIBLE_FORMULATION_UNSPECIFIED:
      case v1::FLEXIBLE_FORMULATION_FLOATING_FRAME:
        out.flexible_formulation = FlexibleFormulation::kFloatingFrame;
        break;
      case v1::FLEXIBLE_FORMULATION_COROTATIONAL:
        out.flexible_formulation = FlexibleFormulation::kCorotational;
        break;
      default:
        errors_.Add(w, "flexible_formulation", "expected FLEXIBLE_FORMULATION_FLOATING_FRAME or "
                                               "FLEXIBLE_FORMULATION_COROTATIONAL");
    }
    if (m.flexible_formulation() != v1::FLEXIBLE_FORMULATION_UNSPECIFIED &&
        std::none_of(out.links.begin(), out.links.end(), [](const Link& l) { return l.flexible_elements > 0; })) {
      errors_.Add(w, "flexible_formulation",
                  "chooses how flexible links are analysed, but no link is flexible: give the links a `flexible` "
                  "block or remove the field");
    }
    linkage_links_ = links;
    linkage_joints_ = joints;
    return out;
  }

  Section ConvertSection(const Where& sw, const v1::Section& s) {
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

  // ---------------------------------------------------------- multibody --
  // "body.marker" or "ground.marker" to a marker reference.
  MarkerRef Marker(const Where& w, const std::string& field, const std::string& ref) {
    MarkerRef out;
    const size_t dot = ref.find('.');
    if (dot == std::string::npos) {
      errors_.Add(w, field, absl::StrCat("\"", ref, "\": expected \"body.marker\" or \"ground.marker\""));
      return out;
    }
    const std::string body = ref.substr(0, dot), marker = ref.substr(dot + 1);
    if (body == "input") {
      auto it = multibody_inputs_.find(marker);
      if (it == multibody_inputs_.end()) {
        errors_.Add(w, field, absl::StrCat("unknown input point \"", marker, "\" (inputs: ",
                                           multibody_inputs_.empty() ? "none" : absl::StrJoin(Names(multibody_inputs_), ", "),
                                           ")"));
      } else {
        out.input = it->second;
        out.marker = 0;  // resolved
      }
      return out;
    }
    if (auto link = multibody_links_.find(body); link != multibody_links_.end()) {
      out.link = link->second;
      if (marker == "a" || marker == "b") {
        out.marker = marker == "a" ? 0 : 1;
      } else {
        errors_.Add(w, field, absl::StrCat("flexible link \"", body, "\" has ends \"a\" and \"b\", not \"", marker,
                                           "\""));
      }
      return out;
    }
    const std::vector<LinkPoint>* markers = &multibody_.ground_markers;
    if (body != "ground") {
      auto it = multibody_bodies_.find(body);
      if (it == multibody_bodies_.end()) {
        errors_.Add(w, field, absl::StrCat("unknown body \"", body, "\" in \"", ref, "\" (bodies: ",
                                           absl::StrJoin(Names(multibody_bodies_), ", "), ")"));
        return out;
      }
      out.body = it->second;
      markers = &multibody_.bodies[static_cast<size_t>(out.body)].markers;
    }
    for (size_t k = 0; k < markers->size(); ++k) {
      if ((*markers)[k].name == marker) out.marker = static_cast<int>(k);
    }
    if (out.marker < 0) {
      std::vector<std::string> names;
      for (const LinkPoint& p : *markers) names.push_back(p.name);
      errors_.Add(w, field, absl::StrCat("\"", body, "\" has no marker \"", marker, "\" (markers: ",
                                         names.empty() ? "none" : absl::StrJoin(names, ", "), ")"));
    }
    return out;
  }

  static std::vector<std::string> Names(const std::map<std::string, int>& table) {
    std::vector<std::pair<int, std::string>> ordered;
    for (const auto& [name, index] : table) ordered.emplace_back(index, name);
    std::sort(ordered.begin(), ordered.end());
    std::vector<std::string> names;
    for (const auto& [index, name] : ordered) names.push_back(name);
    return names;
  }

  std::vector<LinkPoint> Markers(const Where& w, const std::string& field,
                                 const google::protobuf::RepeatedPtrField<v1::Marker>& markers) {
    std::vector<LinkPoint> out;
    std::set<std::string> names;
    for (int k = 0; k < markers.size(); ++k) {
      const Where mw = w.Child(field, k);
      LinkPoint p;
      p.name = markers[k].name();
      if (p.name.empty()) errors_.Add(mw, "name", "a marker needs a name");
      if (!names.insert(p.name).second) errors_.Add(mw, "name", absl::StrCat("duplicate marker \"", p.name, "\""));
      p.position_m = Vec(mw, "position_m", markers[k].has_position_m(), markers[k].position_m(), Dimension::kLength);
      out.push_back(std::move(p));
    }
    return out;
  }

  int MultibodyJointIndex(const Where& w, const std::string& field, const std::string& name) {
    auto it = multibody_joints_.find(name);
    if (it == multibody_joints_.end()) {
      errors_.Add(w, field, absl::StrCat("unknown joint \"", name, "\" (joints: ",
                                         absl::StrJoin(Names(multibody_joints_), ", "), ")"));
      return -1;
    }
    return it->second;
  }

  MultibodyModel ConvertMultibody(const v1::MultibodyModel& m, const Where& w) {
    multibody_ = MultibodyModel{};
    switch (m.analysis()) {
      case v1::MULTIBODY_ANALYSIS_FROM_DEGREES_OF_FREEDOM: break;
      case v1::MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM:
        multibody_.analysis = MultibodyModel::Analysis::kStaticEquilibrium;
        break;
      default:
        errors_.Add(w, "analysis",
                    "expected MULTIBODY_ANALYSIS_FROM_DEGREES_OF_FREEDOM or MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM");
        break;
    }
    multibody_.ground_markers = Markers(w, "ground_markers", m.ground_markers());
    for (int i = 0; i < m.inputs_size(); ++i) {
      const v1::InputPoint& in = m.inputs(i);
      const Where iw = w.Child("inputs", i);
      MultibodyInput input;
      input.name = in.name();
      if (in.name().empty()) errors_.Add(iw, "name", "an input point needs a name");
      if (!multibody_inputs_.emplace(in.name(), i).second) {
        errors_.Add(iw, "name", absl::StrCat("duplicate input name \"", in.name(), "\""));
      }
      input.position_m = Vec(iw, "position_m", in.has_position_m(), in.position_m(), Dimension::kLength);
      Direction(iw, "direction", in.has_direction(), in.direction(), &input.direction_x, &input.direction_y);
      if (in.has_harmonic()) {
        Harmonic(iw.Child("harmonic"), in.harmonic(), &input.displacement);
      } else if (in.has_tabulated()) {
        Tabulated(iw.Child("tabulated"), in.tabulated(), &input.displacement);
      } else {
        errors_.Add(iw, "", "an input point needs a displacement: `harmonic { ... }` or `tabulated { ... }`");
      }
      multibody_.inputs.push_back(std::move(input));
    }
    for (int i = 0; i < m.bodies_size(); ++i) {
      const v1::RigidBody& b = m.bodies(i);
      const Where bw = w.Child("bodies", i);
      RigidBody body;
      body.name = b.name();
      if (b.name().empty() || b.name() == "ground") {
        errors_.Add(bw, "name", "a body needs a name other than \"ground\"");
      }
      if (!multibody_bodies_.emplace(b.name(), i).second) {
        errors_.Add(bw, "name", absl::StrCat("duplicate body name \"", b.name(), "\""));
      }
      body.mass_kg = Num(bw, "mass_kg", b.has_mass_kg(), b.mass_kg(), Dimension::kMass);
      RequirePositive(bw, "mass_kg", body.mass_kg);
      body.inertia_kg_m2 = Num(bw, "inertia_kg_m2", b.has_inertia_kg_m2(), b.inertia_kg_m2(), Dimension::kInertia);
      RequirePositive(bw, "inertia_kg_m2", body.inertia_kg_m2);
      body.position_m = Vec(bw, "position_m", b.has_position_m(), b.position_m(), Dimension::kLength);
      body.angle_rad = Num(bw, "angle_rad", b.has_angle_rad(), b.angle_rad(), Dimension::kAngle, 0.0);
      body.markers = Markers(bw, "markers", b.markers());
      multibody_.bodies.push_back(std::move(body));
    }
    for (int i = 0; i < m.flexible_links_size(); ++i) {
      const v1::FlexibleBeamLink& l = m.flexible_links(i);
      const Where lw = w.Child("flexible_links", i);
      MultibodyFlexibleLink link;
      link.name = l.name();
      if (l.name().empty() || l.name() == "ground" || l.name() == "input") {
        errors_.Add(lw, "name", "a flexible link needs a name other than \"ground\" and \"input\"");
      }
      if (multibody_bodies_.count(l.name()) > 0 || !multibody_links_.emplace(l.name(), i).second) {
        errors_.Add(lw, "name", absl::StrCat("duplicate body or link name \"", l.name(), "\""));
      }
      link.start_m = Vec(lw, "start_m", l.has_start_m(), l.start_m(), Dimension::kLength);
      link.angle_rad = Num(lw, "angle_rad", l.has_angle_rad(), l.angle_rad(), Dimension::kAngle, 0.0);
      link.length_m = Num(lw, "length_m", l.has_length_m(), l.length_m(), Dimension::kLength);
      RequirePositive(lw, "length_m", link.length_m);
      if (!l.has_section()) errors_.Add(lw, "section", "a flexible link needs a section (area, modulus, density)");
      link.section = ConvertSection(lw.Child("section"), l.section());
      link.elements = l.elements() == 0 ? 4 : l.elements();
      link.rotary_inertia = l.rotary_inertia();
      if (link.elements < 1 || link.elements > kMaxFlexibleLinkElements) {
        errors_.Add(lw, "elements", absl::StrFormat("expected 1 to %d elements (0 for the default 4), got %d",
                                                    kMaxFlexibleLinkElements, l.elements()));
      }
      multibody_.flexible_links.push_back(std::move(link));
    }
    if (m.bodies_size() == 0 && m.flexible_links_size() == 0) {
      errors_.Add(w, "bodies", "a multibody model needs at least one body or flexible link");
    }
    for (int i = 0; i < m.joints_size(); ++i) {
      const v1::MultibodyJoint& j = m.joints(i);
      const Where jw = w.Child("joints", i);
      MultibodyJoint joint;
      joint.name = j.name();
      if (j.name().empty()) errors_.Add(jw, "name", "a joint needs a name");
      if (!multibody_joints_.emplace(j.name(), i).second) {
        errors_.Add(jw, "name", absl::StrCat("duplicate joint name \"", j.name(), "\""));
      }
      switch (j.kind()) {
        case v1::JOINT_REVOLUTE: joint.kind = JointKind::kRevolute; break;
        case v1::JOINT_PRISMATIC: joint.kind = JointKind::kPrismatic; break;
        case v1::JOINT_FIXED: joint.kind = JointKind::kFixed; break;
        case v1::JOINT_POINT_ON_LINE: joint.kind = JointKind::kPointOnLine; break;
        default:
          errors_.Add(jw, "kind", "expected JOINT_REVOLUTE, JOINT_PRISMATIC, JOINT_FIXED or JOINT_POINT_ON_LINE");
      }
      joint.a = Marker(jw, "a", j.a());
      joint.b = Marker(jw, "b", j.b());
      if (joint.a.input >= 0 || joint.b.input >= 0) {
        errors_.Add(jw, joint.a.input >= 0 ? "a" : "b",
                    "an input point takes springs and forces, not joints (it is not a body)");
      }
      const bool same_body = joint.a.link >= 0 || joint.b.link >= 0
                                 ? joint.a.link == joint.b.link && joint.a.marker == joint.b.marker
                                 : joint.a.body == joint.b.body;
      if (joint.a.marker >= 0 && joint.b.marker >= 0 && same_body) {
        errors_.Add(jw, "b", "a joint joins two different bodies (or a body and ground)");
      }
      joint.axis_angle_rad = Num(jw, "axis_angle_rad", j.has_axis_angle_rad(), j.axis_angle_rad(), Dimension::kAngle, 0.0);
      const Dimension coordinate = joint.linear() ? Dimension::kLength : Dimension::kAngle;
      if (j.has_initial_value()) joint.initial_value = Num(jw, "initial_value", true, j.initial_value(), coordinate);
      if (j.has_initial_rate()) joint.initial_rate = Num(jw, "initial_rate", true, j.initial_rate(), Dimension::kAny);
      multibody_.joints.push_back(std::move(joint));
    }
    std::set<int> driven;
    for (int i = 0; i < m.drivers_size(); ++i) {
      const v1::MultibodyDriver& d = m.drivers(i);
      const Where dw = w.Child("drivers", i);
      MultibodyDriver driver;
      driver.joint = MultibodyJointIndex(dw, "joint", d.joint());
      if (driver.joint >= 0) {
        if (multibody_.joints[static_cast<size_t>(driver.joint)].kind == JointKind::kFixed) {
          errors_.Add(dw, "joint", "a fixed joint cannot be driven");
        }
        if (!driven.insert(driver.joint).second) errors_.Add(dw, "joint", "this joint already has a driver");
      }
      switch (d.profile_case()) {
        case v1::MultibodyDriver::kConstantRate: {
          const Where pw = dw.Child("constant_rate");
          driver.profile = MultibodyDriver::Profile::kConstantRate;
          driver.start = Num(pw, "start", d.constant_rate().has_start(), d.constant_rate().start(), Dimension::kAny, 0.0);
          driver.rate = Num(pw, "rate", d.constant_rate().has_rate(), d.constant_rate().rate(), Dimension::kAny);
          break;
        }
        case v1::MultibodyDriver::kPolynomial: {
          const Where pw = dw.Child("polynomial");
          driver.profile = MultibodyDriver::Profile::kPolynomial;
          for (int k = 0; k < d.polynomial().coefficients_size(); ++k) {
            driver.coefficients.push_back(Num(pw, absl::StrCat("coefficients[", k, "]"), true, d.polynomial().coefficients(k), Dimension::kAny));
          }
          if (driver.coefficients.empty()) errors_.Add(pw, "coefficients", "a polynomial needs at least one coefficient");
          break;
        }
        case v1::MultibodyDriver::kHarmonic:
          Harmonic(dw.Child("harmonic"), d.harmonic(), &driver);
          break;
        case v1::MultibodyDriver::kTabulated:
          Tabulated(dw.Child("tabulated"), d.tabulated(), &driver);
          break;
        case v1::MultibodyDriver::PROFILE_NOT_SET:
          errors_.Add(dw, "", "a driver needs a profile: `constant_rate`, `polynomial` or `harmonic`");
          break;
      }
      multibody_.drivers.push_back(std::move(driver));
    }
    for (int i = 0; i < m.springs_size(); ++i) {
      const v1::MultibodySpring& sp = m.springs(i);
      const Where sw = w.Child("springs", i);
      MultibodySpring spring;
      spring.name = sp.name();
      if (sp.name().empty()) errors_.Add(sw, "name", "a spring needs a name");
      if (!multibody_springs_.emplace(sp.name(), i).second) {
        errors_.Add(sw, "name", absl::StrCat("duplicate spring name \"", sp.name(), "\""));
      }
      spring.a = Marker(sw, "a", sp.a());
      spring.b = Marker(sw, "b", sp.b());
      spring.free_length_m = Num(sw, "free_length_m", sp.has_free_length_m(), sp.free_length_m(), Dimension::kLength, 0.0);
      RequireNotNegative(sw, "free_length_m", spring.free_length_m);
      spring.stiffness_n_per_m = Num(sw, "stiffness_n_per_m", sp.has_stiffness_n_per_m(), sp.stiffness_n_per_m(), Dimension::kStiffness, 0.0);
      spring.damping_n_s_per_m = Num(sw, "damping_n_s_per_m", sp.has_damping_n_s_per_m(), sp.damping_n_s_per_m(), Dimension::kDamping, 0.0);
      spring.actuator_force_n = Num(sw, "actuator_force_n", sp.has_actuator_force_n(), sp.actuator_force_n(), Dimension::kForce, 0.0);
      if (sp.has_deflection_curve()) {
        spring.deflection_m.assign(sp.deflection_curve().x().begin(), sp.deflection_curve().x().end());
        spring.deflection_force_n.assign(sp.deflection_curve().force_n().begin(), sp.deflection_curve().force_n().end());
        CheckTable(sw.Child("deflection_curve"), "x", "force_n", spring.deflection_m, spring.deflection_force_n);
      }
      if (sp.has_velocity_curve()) {
        spring.velocity_m_per_s.assign(sp.velocity_curve().x().begin(), sp.velocity_curve().x().end());
        spring.velocity_force_n.assign(sp.velocity_curve().force_n().begin(), sp.velocity_curve().force_n().end());
        CheckTable(sw.Child("velocity_curve"), "x", "force_n", spring.velocity_m_per_s, spring.velocity_force_n);
      }
      multibody_.springs.push_back(std::move(spring));
    }
    for (int i = 0; i < m.rotational_springs_size(); ++i) {
      const v1::RotationalSpring& r = m.rotational_springs(i);
      const Where rw = w.Child("rotational_springs", i);
      RotationalSpring spring;
      spring.name = r.name();
      spring.joint = MultibodyJointIndex(rw, "joint", r.joint());
      if (spring.joint >= 0 && multibody_.joints[static_cast<size_t>(spring.joint)].kind != JointKind::kRevolute) {
        errors_.Add(rw, "joint", "a rotational spring acts at a revolute joint");
      }
      spring.stiffness_n_m_per_rad = Num(rw, "stiffness_n_m_per_rad", r.has_stiffness_n_m_per_rad(), r.stiffness_n_m_per_rad(), Dimension::kRotationalStiffness, 0.0);
      spring.damping_n_m_s_per_rad = Num(rw, "damping_n_m_s_per_rad", r.has_damping_n_m_s_per_rad(), r.damping_n_m_s_per_rad(), Dimension::kRotationalDamping, 0.0);
      spring.free_angle_rad = Num(rw, "free_angle_rad", r.has_free_angle_rad(), r.free_angle_rad(), Dimension::kAngle, 0.0);
      multibody_.rotational_springs.push_back(std::move(spring));
    }
    for (int i = 0; i < m.point_forces_size(); ++i) {
      const Where fw = w.Child("point_forces", i);
      MultibodyPointForce force;
      force.at = Marker(fw, "at", m.point_forces(i).at());
      force.force_n = Vec(fw, "force_n", m.point_forces(i).has_force_n(), m.point_forces(i).force_n(), Dimension::kForce);
      force.factor = Factor(fw, m.point_forces(i));
      multibody_.point_forces.push_back(std::move(force));
    }
    for (int i = 0; i < m.torques_size(); ++i) {
      const Where tw = w.Child("torques", i);
      MultibodyTorque torque;
      auto it = multibody_bodies_.find(m.torques(i).body());
      if (it == multibody_bodies_.end()) {
        errors_.Add(tw, "body", absl::StrCat("unknown body \"", m.torques(i).body(), "\""));
      } else {
        torque.body = it->second;
      }
      torque.torque_n_m = Num(tw, "torque_n_m", m.torques(i).has_torque_n_m(), m.torques(i).torque_n_m(), Dimension::kTorque);
      torque.factor = Factor(tw, m.torques(i));
      multibody_.torques.push_back(std::move(torque));
    }
    return multibody_;
  }

  void Harmonic(const Where& pw, const v1::HarmonicProfile& h, MultibodyDriver* out) {
    out->profile = MultibodyDriver::Profile::kHarmonic;
    out->start = Num(pw, "mean", h.has_mean(), h.mean(), Dimension::kAny, 0.0);
    out->amplitude = Num(pw, "amplitude", h.has_amplitude(), h.amplitude(), Dimension::kAny);
    out->angular_frequency_rad_per_s = Num(pw, "angular_frequency_rad_per_s", h.has_angular_frequency_rad_per_s(),
                                           h.angular_frequency_rad_per_s(), Dimension::kAngularVelocity);
    out->phase_rad = Num(pw, "phase_rad", h.has_phase_rad(), h.phase_rad(), Dimension::kAngle, 0.0);
  }

  // A table that must cover the motion, from 0 to the time grid's end.
  void Tabulated(const Where& pw, const v1::TabulatedProfile& t, MultibodyDriver* out) {
    out->profile = MultibodyDriver::Profile::kTabulated;
    out->times_s.assign(t.times_s().begin(), t.times_s().end());
    out->values.assign(t.values().begin(), t.values().end());
    if (CheckTable(pw, "times_s", "values", out->times_s, out->values) && msg_.has_time_grid() &&
        (out->times_s.front() > 0.0 || out->times_s.back() < msg_.time_grid().end_s())) {
      errors_.Add(pw, "times_s",
                  absl::StrFormat("the table covers %g..%g s; it must cover the motion from 0 to the time "
                                  "grid's end, %g s",
                                  out->times_s.front(), out->times_s.back(), msg_.time_grid().end_s()));
    }
  }

  // The optional time factor of a point force or a torque.
  template <class Message>
  std::optional<TimeFactor> Factor(const Where& w, const Message& m) {
    TimeFactor factor;
    if (m.has_harmonic()) {
      Harmonic(w.Child("harmonic"), m.harmonic(), &factor);
      return factor;
    }
    if (m.has_tabulated()) {
      Tabulated(w.Child("tabulated"), m.tabulated(), &factor);
      return factor;
    }
    return std::nullopt;
  }

  // A table of at least two finite points, abscissae strictly increasing.
  bool CheckTable(const Where& w, const std::string& x_field, const std::string& y_field, const std::vector<double>& x,
                  const std::vector<double>& y) {
    if (x.size() < 2 || x.size() != y.size()) {
      errors_.Add(w, x_field, absl::StrFormat("a table needs at least 2 points and as many %s as %s (got %d and %d)",
                                              x_field, y_field, x.size(), y.size()));
      return false;
    }
    for (size_t k = 0; k < x.size(); ++k) {
      if (!std::isfinite(x[k]) || !std::isfinite(y[k])) {
        errors_.Add(w, x_field, absl::StrFormat("point %d is not finite", k));
        return false;
      }
      if (k > 0 && !(x[k] > x[k - 1])) {
        errors_.Add(w, x_field, absl::StrFormat("must increase strictly: %g after %g (point %d)", x[k], x[k - 1], k));
        return false;
      }
    }
    return true;
  }

  MultibodyOutput MultibodyOutputOf(const v1::Output& o, const Where& ow) {
    using Q = MultibodyOutput::Quantity;
    MultibodyOutput out;
    auto marker = [&](const char* field, const v1::MarkerOutput& m, Q quantity) {
      const Where kw = ow.Child(field);
      out.quantity = quantity;
      out.marker = Marker(kw, "marker", m.marker());
      out.axis = m.axis() == v1::AXIS_Y ? Axis::kY : Axis::kX;
      if (m.axis() != v1::AXIS_X && m.axis() != v1::AXIS_Y) errors_.Add(kw, "axis", "expected AXIS_X or AXIS_Y");
    };
    auto joint = [&](const char* field, const v1::JointOutput& j, Q quantity, bool needs_axis) {
      const Where kw = ow.Child(field);
      out.quantity = quantity;
      out.joint = MultibodyJointIndex(kw, "joint", j.joint());
      if (out.joint >= 0) out.linear = multibody_.joints[static_cast<size_t>(out.joint)].linear();
      if (needs_axis) {
        out.axis = j.axis() == v1::AXIS_Y ? Axis::kY : Axis::kX;
        if (j.axis() != v1::AXIS_X && j.axis() != v1::AXIS_Y) errors_.Add(kw, "axis", "expected AXIS_X or AXIS_Y");
      }
      if (quantity == Q::kDriverEffort && out.joint >= 0) {
        bool driven = false;
        for (const MultibodyDriver& d : multibody_.drivers) driven = driven || d.joint == out.joint;
        if (!driven) errors_.Add(kw, "joint", absl::StrCat("joint \"", j.joint(), "\" has no driver"));
      }
    };
    auto spring = [&](const char* field, const v1::SpringOutput& sp, Q quantity) {
      const Where kw = ow.Child(field);
      out.quantity = quantity;
      auto it = multibody_springs_.find(sp.spring());
      if (it == multibody_springs_.end()) {
        errors_.Add(kw, "spring", absl::StrCat("unknown spring \"", sp.spring(), "\""));
      } else {
        out.spring = it->second;
      }
    };
    switch (o.kind_case()) {
      case v1::Output::kMarkerPosition: marker("marker_position", o.marker_position(), Q::kMarkerPosition); break;
      case v1::Output::kMarkerVelocity: marker("marker_velocity", o.marker_velocity(), Q::kMarkerVelocity); break;
      case v1::Output::kMarkerAcceleration: marker("marker_acceleration", o.marker_acceleration(), Q::kMarkerAcceleration); break;
      case v1::Output::kJointCoordinate: joint("joint_coordinate", o.joint_coordinate(), Q::kJointCoordinate, false); break;
      case v1::Output::kJointRate: joint("joint_rate", o.joint_rate(), Q::kJointRate, false); break;
      case v1::Output::kJointReaction: joint("joint_reaction", o.joint_reaction(), Q::kJointReaction, true); break;
      case v1::Output::kDriverEffort: joint("driver_effort", o.driver_effort(), Q::kDriverEffort, false); break;
      case v1::Output::kSpringLength: spring("spring_length", o.spring_length(), Q::kSpringLength); break;
      case v1::Output::kSpringForce: spring("spring_force", o.spring_force(), Q::kSpringForce); break;
      case v1::Output::kKineticEnergy: out.quantity = Q::kKineticEnergy; break;
      case v1::Output::kPotentialEnergy: out.quantity = Q::kPotentialEnergy; break;
      default: break;
    }
    const bool motion = out.quantity == Q::kMarkerVelocity || out.quantity == Q::kMarkerAcceleration ||
                        out.quantity == Q::kJointRate || out.quantity == Q::kKineticEnergy;
    if (motion && multibody_.analysis == MultibodyModel::Analysis::kStaticEquilibrium) {
      errors_.Add(ow, "",
                  absl::StrCat("output \"", o.name(),
                               "\" is a rate, an acceleration or kinetic energy: a static-equilibrium analysis has "
                               "no motion (ask for positions, joint coordinates, reactions, driver efforts, spring "
                               "lengths and forces, potential energy)"));
    }
    return out;
  }

  // ----------------------------------------------------------- external --
  ExternalModel ConvertExternal(const v1::ExternalModel& m, const Where& w) {
    ExternalModel out;
    out.driver = m.driver();
    // The driver itself is the worker's to check (its declared parameters
    // are known only there); the name must at least be one a worker could
    // declare.
    if (m.driver().empty()) {
      errors_.Add(w, "driver", "missing: expected the name of an analysis driver a worker declares");
    } else if (!IsDriverName(m.driver())) {
      errors_.Add(w, "driver",
                  absl::StrCat("\"", m.driver(), "\" is not a driver name: expected letters, digits, '_', '-' "
                               "and '.', not starting with '.', at most 100 characters"));
    }
    std::set<std::string> names;
    for (int i = 0; i < m.inputs_size(); ++i) {
      const v1::ExternalInput& in = m.inputs(i);
      const Where iw = w.Child("inputs", i);
      if (in.name().empty()) errors_.Add(iw, "name", "an input needs the name of one of the driver's parameters");
      if (!names.insert(in.name()).second) {
        errors_.Add(iw, "name", absl::StrCat("duplicate input \"", in.name(), "\""));
      }
      out.inputs.push_back({in.name(), Num(iw, "value", in.has_value(), in.value(), Dimension::kAny)});
    }
    return out;
  }

  static bool IsDriverName(const std::string& name) {
    if (name.empty() || name.size() > 100 || name[0] == '.') return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-' ||
             c == '.';
    });
  }

  // ------------------------------------------------------------ outputs --
  FmuModel ConvertFmu(const v1::FmuModel& m, const Where& w) {
    FmuModel out;
    out.path = m.path();
    if (out.path.empty()) errors_.Add(w, "path", "missing: expected the .fmu file, e.g. `path: \"model.fmu\"`");
    switch (m.interface()) {
      case v1::FMU_INTERFACE_UNSPECIFIED:
      case v1::FMU_MODEL_EXCHANGE:
        out.co_simulation = false;
        break;
      case v1::FMU_CO_SIMULATION:
        out.co_simulation = true;
        break;
      default:
        errors_.Add(w, "interface", "expected FMU_MODEL_EXCHANGE or FMU_CO_SIMULATION");
    }
    if (m.communication_step_s() < 0.0 || !std::isfinite(m.communication_step_s())) {
      errors_.Add(w, "communication_step_s",
                  absl::StrFormat("must be > 0 s (0 for the FMU's default step), got %g", m.communication_step_s()));
    } else if (m.communication_step_s() > 0.0 && !out.co_simulation) {
      errors_.Add(w, "communication_step_s", "applies to `interface: FMU_CO_SIMULATION` only");
    }
    out.communication_step_s = m.communication_step_s();
    std::set<std::string> seen;
    for (int i = 0; i < m.parameters_size(); ++i) {
      const v1::FmuParameter& p = m.parameters(i);
      const Where pw = w.Child("parameters", i);
      if (p.variable().empty()) errors_.Add(pw, "variable", "missing: expected the FMU parameter's name");
      if (!seen.insert(p.variable()).second) {
        errors_.Add(pw, "variable", absl::StrCat("FMU parameter \"", p.variable(), "\" is set twice"));
      }
      out.parameters.push_back({p.variable(), Num(pw, "value", p.has_value(), p.value(), Dimension::kAny)});
    }
    return out;
  }

  void ConvertOutputs() {
    std::set<std::string> names;
    const bool lumped = std::holds_alternative<LumpedModel>(scene_.model);
    const bool linkage = std::holds_alternative<LinkageModel>(scene_.model);
    const bool multibody = std::holds_alternative<MultibodyModel>(scene_.model);
    const bool external = std::holds_alternative<ExternalModel>(scene_.model);
    auto lookup = [&](const std::map<std::string, int>& table, const Where& w,
                      const std::string& field, const std::string& name, const char* what) {
      auto it = table.find(name);
      if (it == table.end()) {
        errors_.Add(w, field, absl::StrCat("unknown ", what, " \"", name, "\""));
        return -1;
      }
      return it->second;
    };
    auto axis = [&](const Where& w, v1::Axis a) {
      if (a == v1::AXIS_X) return Axis::kX;
      if (a != v1::AXIS_Y) errors_.Add(w, "axis", "expected AXIS_X or AXIS_Y");
      return Axis::kY;
    };
    for (int i = 0; i < msg_.outputs_size(); ++i) {
      const v1::Output& o = msg_.outputs(i);
      const Where ow = where_.Child("outputs", i);
      Output out;
      out.name = o.name();
      if (o.name().empty()) errors_.Add(ow, "name", "an output needs a name");
      if (!names.insert(o.name()).second) {
        errors_.Add(ow, "name", absl::StrCat("duplicate output name \"", o.name(), "\""));
      }
      const char* needs = nullptr;  // the model kind this output needs
      switch (o.kind_case()) {
        case v1::Output::kElementDeflection: {
          needs = "lumped";
          ElementDeflectionOutput k;
          if (lumped) {
            k.element = lookup(lumped_elements_, ow.Child("element_deflection"), "element",
                               o.element_deflection().element(), "element");
          }
          out.kind = k;
          break;
        }
        case v1::Output::kBodyAcceleration:
        case v1::Output::kBodyDisplacement:
        case v1::Output::kBodyVelocity: {
          needs = "lumped";
          using Q = BodyAccelerationOutput::Quantity;
          const bool displacement = o.kind_case() == v1::Output::kBodyDisplacement;
          const bool velocity = o.kind_case() == v1::Output::kBodyVelocity;
          const Where kw =
              ow.Child(displacement ? "body_displacement" : velocity ? "body_velocity" : "body_acceleration");
          const v1::BodyAccelerationOutput& a =
              displacement ? o.body_displacement() : velocity ? o.body_velocity() : o.body_acceleration();
          BodyAccelerationOutput k;
          k.quantity = displacement ? Q::kDisplacement : velocity ? Q::kVelocity : Q::kAcceleration;
          if (lumped) k.body = lookup(lumped_bodies_, kw, "body", a.body(), "body");
          k.offset_m = Vec(kw, "offset_m", a.has_offset_m(), a.offset_m(), Dimension::kLength);
          k.axis = axis(kw, a.axis());
          out.kind = k;
          break;
        }
        case v1::Output::kPointPosition: {
          needs = "linkage";
          const Where kw = ow.Child("point_position");
          PointPositionOutput k;
          k.axis = axis(kw, o.point_position().axis());
          if (linkage) ResolvePoint(kw, o.point_position().point(), &k);
          out.kind = k;
          break;
        }
        case v1::Output::kLinkRotation: {
          needs = "linkage";
          LinkRotationOutput k;
          if (linkage) {
            k.link = lookup(linkage_links_, ow.Child("link_rotation"), "link",
                            o.link_rotation().link(), "link");
          }
          out.kind = k;
          break;
        }
        case v1::Output::kBendingStress: {
          needs = multibody ? "multibody" : "linkage";
          BendingStressOutput k;
          const Where kw = ow.Child("bending_stress");
          if (multibody) {
            k.link = lookup(multibody_links_, kw, "link", o.bending_stress().link(), "flexible link");
          }
          if (linkage) {
            k.link = lookup(linkage_links_, kw, "link", o.bending_stress().link(), "link");
            const auto& linkage = std::get<LinkageModel>(scene_.model);
            if (k.link >= 0 && !linkage.links[static_cast<size_t>(k.link)].section) {
              errors_.Add(kw, "link",
                          absl::StrCat("link \"", o.bending_stress().link(),
                                       "\" has no section: bending stress needs one"));
            }
          }
          out.kind = k;
          break;
        }
        case v1::Output::kDriveTorque:
          needs = "linkage";
          out.kind = DriveTorqueOutput{};
          break;
        case v1::Output::kMass:
          needs = "linkage";
          out.kind = MassOutput{};
          break;
        case v1::Output::kMarkerPosition:
        case v1::Output::kMarkerVelocity:
        case v1::Output::kMarkerAcceleration:
        case v1::Output::kJointCoordinate:
        case v1::Output::kJointRate:
        case v1::Output::kJointReaction:
        case v1::Output::kDriverEffort:
        case v1::Output::kSpringLength:
        case v1::Output::kSpringForce:
        case v1::Output::kKineticEnergy:
        case v1::Output::kPotentialEnergy:
          needs = "multibody";
          out.kind = multibody ? MultibodyOutputOf(o, ow) : MultibodyOutput{};
          break;
        case v1::Output::kExternalValue:
        case v1::Output::kExternalSeries: {
          needs = "external";
          const bool series = o.kind_case() == v1::Output::kExternalSeries;
          const v1::ExternalResultOutput& r = series ? o.external_series() : o.external_value();
          if (r.name().empty()) {
            errors_.Add(ow.Child(series ? "external_series" : "external_value"), "name",
                        "missing: expected the name the driver writes in its results file");
          }
          out.kind = ExternalResultOutput{r.name(), series};
          break;
        }
        case v1::Output::kFmuVariable:
          needs = "fmu";
          if (o.fmu_variable().variable().empty()) {
            errors_.Add(ow.Child("fmu_variable"), "variable", "missing: expected the FMU variable's name");
          }
          out.kind = FmuVariableOutput{o.fmu_variable().variable()};
          break;
        case v1::Output::KIND_NOT_SET:
          errors_.Add(ow, "", "the output has no kind (e.g. `element_deflection { ... }`)");
          break;
      }
      const char* model_kind = lumped      ? "lumped"
                               : linkage   ? "linkage"
                               : multibody ? "multibody"
                               : external  ? "external"
                                           : "fmu";
      if (needs != nullptr && std::string(needs) != model_kind) {
        errors_.Add(ow, "",
                    absl::StrCat("output \"", o.name(), "\" needs ", needs[0] == 'e' ? "an " : "a ", needs,
                                 " model; this scene's model is ",
                                 model_kind));
      }
      scene_.outputs.push_back(std::move(out));
    }
  }

  void ResolvePoint(const Where& w, const std::string& name, PointPositionOutput* k) {
    const auto& linkage = std::get<LinkageModel>(scene_.model);
    const size_t dot = name.find('.');
    if (dot == std::string::npos) {
      auto it = linkage_joints_.find(name);
      if (it == linkage_joints_.end()) {
        errors_.Add(
            w, "point",
            absl::StrCat("unknown joint \"", name, "\" (a link point is written \"link.point\")"));
      } else {
        k->joint = it->second;
      }
      return;
    }
    const std::string link_name = name.substr(0, dot), point_name = name.substr(dot + 1);
    auto it = linkage_links_.find(link_name);
    if (it == linkage_links_.end()) {
      errors_.Add(w, "point", absl::StrCat("unknown link \"", link_name, "\""));
      return;
    }
    k->link = it->second;
    const Link& link = linkage.links[static_cast<size_t>(k->link)];
    for (size_t p = 0; p < link.points.size(); ++p) {
      if (link.points[p].name == point_name) k->point = static_cast<int>(p);
    }
    if (k->point < 0) {
      errors_.Add(w, "point",
                  absl::StrCat("link \"", link_name, "\" has no point \"", point_name, "\""));
    }
  }

  void ConvertGrid() {
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

  void ConvertIntegrator() {
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

  const v1::Scene& msg_;
  const Where& where_;
  MultibodyModel multibody_;
  std::map<std::string, int> multibody_bodies_, multibody_joints_, multibody_springs_, multibody_inputs_,
      multibody_links_;
  Errors& errors_;
  Scene scene_;
  std::vector<Dimension> units_;  // per parameter
  enum class ResolveState { kUnresolved, kResolving, kResolved, kFailed };
  std::vector<ResolveState> resolve_state_;  // per parameter, for those written as `expr`
  std::vector<int> resolving_;               // the chain being resolved, for naming a cycle
  bool cycle_reported_ = false;
  std::map<std::string, int> lumped_bodies_, lumped_elements_;
  std::map<std::string, int> linkage_links_, linkage_joints_;
};

}  // namespace

Scene ConvertScene(const v1::Scene& message, const Where& where, Errors* errors) {
  return SceneConverter(message, where, errors).Run();
}

}  // namespace mbopt::spec::io
