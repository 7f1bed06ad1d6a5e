#include "worker/multibody/parameter_derivatives.h"

#include <optional>

namespace mbopt::multibody {
namespace {

// Whether two parts of models agree in everything the equations read
// besides the linear coefficients (ParameterDerivativeModel). Tabulated
// profiles and force curves are not compared: the scene gives them as plain
// numbers, which no parameter sets.
using Eigen::VectorXd;

// G(q, lambda) of the static equilibrium equations of `s` (see
// StaticParameterDerivative).
int StaticEquations(const ConstrainedSystem& s, double t, const VectorXd& q, const VectorXd& lambda, VectorXd* g) {
  const int n = s.num_coordinates(), m = s.num_constraints();
  VectorXd forces, phi;
  Eigen::MatrixXd phi_q;
  int flag = s.AppliedForces(t, q, VectorXd::Zero(n), &forces);
  if (flag == 0 && m > 0) flag = s.ConstraintJacobian(t, q, &phi_q);
  if (flag == 0 && m > 0) flag = s.Constraints(t, q, &phi);
  if (flag != 0) return flag;
  g->resize(n + m);
  g->head(n) = forces;
  if (m > 0) {
    g->head(n) -= phi_q.transpose() * lambda;
    g->tail(m) = phi;
  }
  return g->allFinite() ? 0 : 1;
}

bool Same(const Point& a, const Point& b) { return a.body == b.body && a.local_m == b.local_m && a.input == b.input; }

bool Same(const Profile& a, const Profile& b) {
  return a.kind == b.kind && a.start == b.start && a.rate == b.rate && a.coefficients == b.coefficients &&
         a.amplitude == b.amplitude && a.angular_frequency_rad_per_s == b.angular_frequency_rad_per_s &&
         a.phase_rad == b.phase_rad;
}

bool Same(const std::optional<Profile>& a, const std::optional<Profile>& b) {
  return a.has_value() == b.has_value() && (!a.has_value() || Same(*a, *b));
}

// The residual does not read a body's initial pose, but a joint's held
// relative angle comes from the initial angles (Mechanism).
bool SameGeometry(const Model& a, const Model& b) {
  if (a.bodies.size() != b.bodies.size() || a.joints.size() != b.joints.size() ||
      a.drivers.size() != b.drivers.size() || a.inputs.size() != b.inputs.size() ||
      a.springs.size() != b.springs.size() || a.rotational_springs.size() != b.rotational_springs.size() ||
      a.point_forces.size() != b.point_forces.size() || a.torques.size() != b.torques.size() ||
      a.beams.size() != b.beams.size() || a.gravity_m_per_s2 != b.gravity_m_per_s2) {
    return false;
  }
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    if (a.bodies[i].angle_rad != b.bodies[i].angle_rad) return false;
  }
  for (size_t i = 0; i < a.joints.size(); ++i) {
    const Joint &x = a.joints[i], &y = b.joints[i];
    if (x.kind != y.kind || !Same(x.a, y.a) || !Same(x.b, y.b) || x.axis_angle_rad != y.axis_angle_rad) return false;
  }
  for (size_t i = 0; i < a.drivers.size(); ++i) {
    if (a.drivers[i].joint != b.drivers[i].joint || !Same(a.drivers[i].profile, b.drivers[i].profile)) return false;
  }
  for (size_t i = 0; i < a.inputs.size(); ++i) {
    const InputPoint &x = a.inputs[i], &y = b.inputs[i];
    if (x.position_m != y.position_m || x.direction != y.direction || !Same(x.displacement, y.displacement)) {
      return false;
    }
  }
  for (size_t i = 0; i < a.springs.size(); ++i) {
    const SpringDamper &x = a.springs[i], &y = b.springs[i];
    if (!Same(x.a, y.a) || !Same(x.b, y.b) || x.free_length_m != y.free_length_m ||
        x.deflection_curve.empty() != y.deflection_curve.empty() ||
        x.velocity_curve.empty() != y.velocity_curve.empty()) {
      return false;
    }
  }
  for (size_t i = 0; i < a.rotational_springs.size(); ++i) {
    const RotationalSpringDamper &x = a.rotational_springs[i], &y = b.rotational_springs[i];
    if (x.joint != y.joint || x.free_angle_rad != y.free_angle_rad) return false;
  }
  for (size_t i = 0; i < a.point_forces.size(); ++i) {
    if (!Same(a.point_forces[i].at, b.point_forces[i].at) || !Same(a.point_forces[i].factor, b.point_forces[i].factor)) {
      return false;
    }
  }
  for (size_t i = 0; i < a.torques.size(); ++i) {
    if (a.torques[i].body != b.torques[i].body || !Same(a.torques[i].factor, b.torques[i].factor)) return false;
  }
  // A beam's forces are not linear in its section's numbers once its
  // structural damping follows them (beta from the first frequency).
  for (size_t i = 0; i < a.beams.size(); ++i) {
    const BeamElement &x = a.beams[i], &y = b.beams[i];
    if (x.a != y.a || x.b != y.b || x.length_m != y.length_m || x.axial_stiffness_n != y.axial_stiffness_n ||
        x.bending_stiffness_n_m2 != y.bending_stiffness_n_m2 || x.angle_a_rad != y.angle_a_rad ||
        x.angle_b_rad != y.angle_b_rad || x.damping_s != y.damping_s) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::unique_ptr<ParameterDerivativeModel> ParameterDerivativeModel::Of(const Model& nominal, const Model& plus,
                                                                        const Model& minus, double step) {
  if (!(step > 0.0) || !SameGeometry(nominal, plus) || !SameGeometry(nominal, minus)) return nullptr;
  const double scale = 1.0 / (2.0 * step);
  auto d = [scale](double up, double down) { return (up - down) * scale; };
  std::unique_ptr<ParameterDerivativeModel> out(new ParameterDerivativeModel());
  Model& m = out->model_;
  m.inputs = nominal.inputs;
  m.joints = nominal.joints;
  m.drivers = nominal.drivers;
  bool mass_changes = false;
  for (size_t i = 0; i < nominal.bodies.size(); ++i) {
    Body body = nominal.bodies[i];
    body.mass_kg = d(plus.bodies[i].mass_kg, minus.bodies[i].mass_kg);
    body.inertia_kg_m2 = d(plus.bodies[i].inertia_kg_m2, minus.bodies[i].inertia_kg_m2);
    mass_changes = mass_changes || body.mass_kg != 0.0;
    m.bodies.push_back(std::move(body));
  }
  // Gravity is m g: its derivative is dm g.
  if (mass_changes) m.gravity_m_per_s2 = nominal.gravity_m_per_s2;
  for (size_t i = 0; i < nominal.springs.size(); ++i) {
    const SpringDamper &s = nominal.springs[i], &up = plus.springs[i], &down = minus.springs[i];
    SpringDamper ds;
    ds.name = s.name;
    ds.a = s.a;
    ds.b = s.b;
    ds.free_length_m = s.free_length_m;
    // A force curve replaces the linear term: the coefficient then does
    // not act.
    if (s.deflection_curve.empty()) ds.stiffness_n_per_m = d(up.stiffness_n_per_m, down.stiffness_n_per_m);
    if (s.velocity_curve.empty()) ds.damping_n_s_per_m = d(up.damping_n_s_per_m, down.damping_n_s_per_m);
    ds.actuator_force_n = d(up.actuator_force_n, down.actuator_force_n);
    if (ds.stiffness_n_per_m != 0.0 || ds.damping_n_s_per_m != 0.0 || ds.actuator_force_n != 0.0) {
      m.springs.push_back(std::move(ds));
    }
  }
  for (size_t i = 0; i < nominal.rotational_springs.size(); ++i) {
    RotationalSpringDamper r = nominal.rotational_springs[i];
    r.stiffness_n_m_per_rad =
        d(plus.rotational_springs[i].stiffness_n_m_per_rad, minus.rotational_springs[i].stiffness_n_m_per_rad);
    r.damping_n_m_s_per_rad =
        d(plus.rotational_springs[i].damping_n_m_s_per_rad, minus.rotational_springs[i].damping_n_m_s_per_rad);
    if (r.stiffness_n_m_per_rad != 0.0 || r.damping_n_m_s_per_rad != 0.0) m.rotational_springs.push_back(std::move(r));
  }
  for (size_t i = 0; i < nominal.point_forces.size(); ++i) {
    PointForce f = nominal.point_forces[i];
    f.force_n = (plus.point_forces[i].force_n - minus.point_forces[i].force_n) * scale;
    if (!f.force_n.isZero(0.0)) m.point_forces.push_back(std::move(f));
  }
  for (size_t i = 0; i < nominal.torques.size(); ++i) {
    BodyTorque torque = nominal.torques[i];
    torque.torque_n_m = d(plus.torques[i].torque_n_m, minus.torques[i].torque_n_m);
    if (torque.torque_n_m != 0.0) m.torques.push_back(std::move(torque));
  }
  out->mechanism_ = std::make_unique<Mechanism>(out->model_);
  return out;
}

int GglParameterDerivative(const ParameterPerturbation& dp, double t, const Eigen::Ref<const VectorXd>& y,
                           const Eigen::Ref<const VectorXd>& y_dot, GglWorkspace* work, Eigen::Ref<VectorXd> out) {
  if (dp.derivative != nullptr) {
    const ConstrainedSystem& d = *dp.derivative;
    const int n = d.num_coordinates();
    const VectorXd q = y.head(n), v = y.segment(n, n);
    int flag = d.MassMatrix(q, &work->mass);
    if (flag == 0) flag = d.AppliedForces(t, q, v, &work->forces);
    if (flag != 0) return flag;
    out.setZero();
    out.segment(n, n) = work->mass * y_dot.segment(n, n) - work->forces;
    return out.allFinite() ? 0 : 1;
  }
  VectorXd plus(out.size()), minus(out.size());
  if (int flag = GglResidual(*dp.plus, t, y, y_dot, work, plus); flag != 0) return flag;
  if (int flag = GglResidual(*dp.minus, t, y, y_dot, work, minus); flag != 0) return flag;
  out = (plus - minus) / (2.0 * dp.step);
  return 0;
}

int StaticParameterDerivative(const ParameterPerturbation& dp, double t, const VectorXd& q, const VectorXd& lambda,
                              VectorXd* out) {
  if (dp.derivative != nullptr) {
    const ConstrainedSystem& d = *dp.derivative;
    const int n = d.num_coordinates(), m = d.num_constraints();
    VectorXd forces;
    if (int flag = d.AppliedForces(t, q, VectorXd::Zero(n), &forces); flag != 0) return flag;
    out->setZero(n + m);
    out->head(n) = forces;
    return out->allFinite() ? 0 : 1;
  }
  VectorXd plus, minus;
  if (int flag = StaticEquations(*dp.plus, t, q, lambda, &plus); flag != 0) return flag;
  if (int flag = StaticEquations(*dp.minus, t, q, lambda, &minus); flag != 0) return flag;
  *out = (plus - minus) / (2.0 * dp.step);
  return 0;
}

}  // namespace mbopt::multibody
