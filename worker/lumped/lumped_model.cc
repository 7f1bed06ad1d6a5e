#include "worker/lumped/lumped_model.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace mbopt::lumped {
namespace {

constexpr double kTwoPi = 6.283185307179586476925;

int DofSlot(spec::Dof dof) {
  switch (dof) {
    case spec::Dof::kX:
      return 0;
    case spec::Dof::kY:
      return 1;
    case spec::Dof::kRotation:
      return 2;
  }
  return 0;
}

}  // namespace

double CosineBumpInput::Displacement(double t_s) const {
  if (t_s <= start_s || t_s >= end_s()) return 0.0;
  return 0.5 * height_m * (1.0 - std::cos(kTwoPi * speed_m_per_s * (t_s - start_s) / length_m));
}

double CosineBumpInput::Velocity(double t_s) const {
  if (t_s <= start_s || t_s >= end_s()) return 0.0;
  const double omega = kTwoPi * speed_m_per_s / length_m;
  return 0.5 * height_m * omega * std::sin(omega * (t_s - start_s));
}

absl::StatusOr<LumpedModel> LumpedModel::Assemble(const spec::LumpedModel& spec_model,
                                                  const std::vector<double>& p) {
  LumpedModel m;
  // Coordinates in body order, X, Y, ROTATION within a body.
  std::vector<double> masses;
  m.coordinate_of_.assign(spec_model.bodies.size(), std::vector<int>(3, -1));
  for (size_t b = 0; b < spec_model.bodies.size(); ++b) {
    const spec::Body& body = spec_model.bodies[b];
    const double mass = body.mass_kg.Resolve(p);
    const double inertia = body.inertia_kg_m2.Resolve(p);
    for (spec::Dof dof : {spec::Dof::kX, spec::Dof::kY, spec::Dof::kRotation}) {
      if (std::find(body.dofs.begin(), body.dofs.end(), dof) == body.dofs.end()) continue;
      const double value = dof == spec::Dof::kRotation ? inertia : mass;
      if (!(value > 0.0) || !std::isfinite(value)) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "body \"%s\": %s must be positive and finite for its free %s coordinate, got %g",
            body.name, dof == spec::Dof::kRotation ? "inertia_kg_m2" : "mass_kg",
            dof == spec::Dof::kRotation ? "ROTATION" : (dof == spec::Dof::kX ? "X" : "Y"), value));
      }
      m.coordinate_of_[b][static_cast<size_t>(DofSlot(dof))] = static_cast<int>(masses.size());
      masses.push_back(value);
    }
  }
  const int n = static_cast<int>(masses.size());
  if (n == 0) {
    return absl::InvalidArgumentError("lumped model has no free coordinate (no body has dofs)");
  }
  m.mass_diagonal_ = Eigen::Map<const Eigen::VectorXd>(masses.data(), n);

  for (const spec::GroundInput& input : spec_model.inputs) {
    CosineBumpInput bump;
    bump.height_m = input.bump.height_m.Resolve(p);
    bump.length_m = input.bump.length_m.Resolve(p);
    bump.speed_m_per_s = input.bump.speed_m_per_s.Resolve(p);
    bump.start_s = input.bump.start_time_s.Resolve(p) + input.delay_s.Resolve(p);
    bump.direction_x = input.direction_x;
    bump.direction_y = input.direction_y;
    if (!(bump.length_m > 0.0) || !(bump.speed_m_per_s > 0.0) || !std::isfinite(bump.height_m) ||
        !std::isfinite(bump.start_s) || !std::isfinite(bump.length_m / bump.speed_m_per_s)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "input \"%s\": bump length (%g m) and speed (%g m/s) must be positive, height and "
          "start finite",
          input.name, bump.length_m, bump.speed_m_per_s));
    }
    m.inputs_.push_back(bump);
  }

  m.stiffness_ = Eigen::MatrixXd::Zero(n, n);
  m.damping_ = Eigen::MatrixXd::Zero(n, n);
  m.force_per_displacement_.assign(m.inputs_.size(), Eigen::VectorXd::Zero(n));
  m.force_per_velocity_.assign(m.inputs_.size(), Eigen::VectorXd::Zero(n));
  for (const spec::SpringDamper& e : spec_model.elements) {
    LumpedElement element;
    element.name = e.name;
    element.gradient = Eigen::VectorXd::Zero(n);
    element.stiffness_n_per_m = e.stiffness_n_per_m.Resolve(p);
    element.damping_n_s_per_m = e.damping_n_s_per_m.Resolve(p);
    if (!(element.stiffness_n_per_m >= 0.0) || !(element.damping_n_s_per_m >= 0.0) ||
        !std::isfinite(element.stiffness_n_per_m) || !std::isfinite(element.damping_n_s_per_m)) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "element \"%s\": stiffness (%g N/m) and damping (%g N s/m) must be finite and not "
          "negative",
          e.name, element.stiffness_n_per_m, element.damping_n_s_per_m));
    }
    const double dx = e.direction_x, dy = e.direction_y;
    for (const auto& [attachment, sign] :
         {std::pair<const spec::Attachment*, double>{&e.a, 1.0}, {&e.b, -1.0}}) {
      switch (attachment->kind) {
        case spec::Attachment::Kind::kGround:
          break;
        case spec::Attachment::Kind::kInput: {
          const CosineBumpInput& input = m.inputs_[static_cast<size_t>(attachment->index)];
          element.input_terms.emplace_back(
              attachment->index, sign * (dx * input.direction_x + dy * input.direction_y));
          break;
        }
        case spec::Attachment::Kind::kBody: {
          const auto& coords = m.coordinate_of_[static_cast<size_t>(attachment->index)];
          const double ox = attachment->offset_m.x.Resolve(p);
          const double oy = attachment->offset_m.y.Resolve(p);
          if (coords[0] >= 0) element.gradient[coords[0]] += sign * dx;
          if (coords[1] >= 0) element.gradient[coords[1]] += sign * dy;
          if (coords[2] >= 0) element.gradient[coords[2]] += sign * (-dx * oy + dy * ox);
          break;
        }
      }
    }
    const Eigen::VectorXd& g = element.gradient;
    m.stiffness_.noalias() += element.stiffness_n_per_m * g * g.transpose();
    m.damping_.noalias() += element.damping_n_s_per_m * g * g.transpose();
    for (const auto& [input, factor] : element.input_terms) {
      m.force_per_displacement_[static_cast<size_t>(input)] -=
          element.stiffness_n_per_m * factor * g;
      m.force_per_velocity_[static_cast<size_t>(input)] -= element.damping_n_s_per_m * factor * g;
    }
    m.elements_.push_back(std::move(element));
  }
  return m;
}

int LumpedModel::CoordinateOf(int body, spec::Dof dof) const {
  return coordinate_of_[static_cast<size_t>(body)][static_cast<size_t>(DofSlot(dof))];
}

void LumpedModel::Forcing(double t_s, Eigen::VectorXd* force) const {
  force->setZero(num_coordinates());
  for (size_t j = 0; j < inputs_.size(); ++j) {
    const double u = inputs_[j].Displacement(t_s);
    const double v = inputs_[j].Velocity(t_s);
    if (u != 0.0) *force += u * force_per_displacement_[j];
    if (v != 0.0) *force += v * force_per_velocity_[j];
  }
}

double LumpedModel::InputSum(const LumpedElement& e, double t_s, bool rate) const {
  double sum = 0.0;
  for (const auto& [input, factor] : e.input_terms) {
    const CosineBumpInput& in = inputs_[static_cast<size_t>(input)];
    sum += factor * (rate ? in.Velocity(t_s) : in.Displacement(t_s));
  }
  return sum;
}

double LumpedModel::Deflection(int element, const Eigen::VectorXd& q, double t_s) const {
  const LumpedElement& e = elements_[static_cast<size_t>(element)];
  return e.gradient.dot(q) + InputSum(e, t_s, false);
}

double LumpedModel::DeflectionRate(int element, const Eigen::VectorXd& qdot, double t_s) const {
  const LumpedElement& e = elements_[static_cast<size_t>(element)];
  return e.gradient.dot(qdot) + InputSum(e, t_s, true);
}

void LumpedModel::Acceleration(double t_s, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                               Eigen::VectorXd* qddot) const {
  Forcing(t_s, qddot);
  qddot->noalias() -= stiffness_ * q;
  qddot->noalias() -= damping_ * qdot;
  qddot->array() /= mass_diagonal_.array();
}

double LumpedModel::PointMotion(int body, double offset_x_m, double offset_y_m, spec::Axis axis,
                                const Eigen::Ref<const Eigen::VectorXd>& qddot) const {
  const int ix = CoordinateOf(body, spec::Dof::kX);
  const int iy = CoordinateOf(body, spec::Dof::kY);
  const int ir = CoordinateOf(body, spec::Dof::kRotation);
  const double rot = ir >= 0 ? qddot[ir] : 0.0;
  if (axis == spec::Axis::kX) return (ix >= 0 ? qddot[ix] : 0.0) - offset_y_m * rot;
  return (iy >= 0 ? qddot[iy] : 0.0) + offset_x_m * rot;
}

std::vector<double> LumpedModel::KinkTimes(double t_begin_s, double t_end_s) const {
  std::vector<double> kinks;
  for (const CosineBumpInput& in : inputs_) {
    for (double t : {in.start_s, in.end_s()}) {
      if (t > t_begin_s && t < t_end_s) kinks.push_back(t);
    }
  }
  std::sort(kinks.begin(), kinks.end());
  kinks.erase(std::unique(kinks.begin(), kinks.end()), kinks.end());
  return kinks;
}

}  // namespace mbopt::lumped
