// The lumped (small-motion, linear) model of a scene at one set of parameter
// values: rigid bodies with free coordinates X, Y and ROTATION about their
// centre of mass, joined by linear spring-dampers along fixed directions and
// excited by prescribed ground inputs. Its equations of motion are
//
//     M q'' + C q' + K q = f(t),
//
// with M diagonal (mass for X and Y, rotary inertia for ROTATION), K and C
// sums of k g g^T and c g g^T over the elements, where g is the gradient of
// the element's deflection s = g . q + h(t) and h(t) gathers the ground
// inputs it is attached to. f(t) = -sum g (k h(t) + c h'(t)).
//
// Small motion: a point at offset o from a body's centre of mass moves by
// u = (ux - oy rot, uy + ox rot). Everything is SI (m, kg, N, s, rad). The
// model is immutable once assembled; it owns no integration state.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/scene.h"

namespace mbopt::lumped {

// One-period cosine bump, resolved to SI numbers.
struct CosineBumpInput {
  double height_m = 0;
  double length_m = 1;
  double speed_m_per_s = 1;
  double start_s = 0;  // t0 of the profile plus the input's delay
  double direction_x = 0, direction_y = 1;

  double end_s() const { return start_s + length_m / speed_m_per_s; }
  double Displacement(double t_s) const;  // m, along the direction
  double Velocity(double t_s) const;      // m/s, analytic derivative
};

struct LumpedElement {
  std::string name;
  Eigen::VectorXd gradient;  // ds/dq, one entry per coordinate
  // s also contains sum over (input, factor) of factor * u_input(t).
  std::vector<std::pair<int, double>> input_terms;
  double stiffness_n_per_m = 0;
  double damping_n_s_per_m = 0;
};

class LumpedModel {
 public:
  // Resolves parameters and assembles M, K, C. InvalidArgument naming the
  // body or element if a resolved value is unusable at this design (mass or
  // inertia not positive, negative stiffness or damping, bump length or
  // speed not positive, a body with no free coordinate is fine but a model
  // with none is not).
  static absl::StatusOr<LumpedModel> Assemble(const spec::LumpedModel& model,
                                              const std::vector<double>& parameter_values_si);

  int num_coordinates() const { return static_cast<int>(mass_diagonal_.size()); }
  // Coordinate index of `dof` of body `body`, -1 if that motion is fixed.
  int CoordinateOf(int body, spec::Dof dof) const;

  const Eigen::VectorXd& mass_diagonal() const { return mass_diagonal_; }
  const Eigen::MatrixXd& stiffness() const { return stiffness_; }
  const Eigen::MatrixXd& damping() const { return damping_; }
  const std::vector<LumpedElement>& elements() const { return elements_; }
  const std::vector<CosineBumpInput>& inputs() const { return inputs_; }

  // f(t), N (or N m for rotations).
  void Forcing(double t_s, Eigen::VectorXd* force) const;
  // Element deflection s and its rate at state (q, q') and time t.
  double Deflection(int element, const Eigen::VectorXd& q, double t_s) const;
  double DeflectionRate(int element, const Eigen::VectorXd& qdot, double t_s) const;
  // Acceleration q'' from the equations of motion.
  void Acceleration(double t_s, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot,
                    Eigen::VectorXd* qddot) const;
  // A body point's motion along an axis: its displacement from q, velocity
  // from q', acceleration from q'' (small rotations: the same linear map).
  double PointMotion(int body, double offset_x_m, double offset_y_m, spec::Axis axis,
                     const Eigen::Ref<const Eigen::VectorXd>& coordinates) const;
  // Instants in (t_begin, t_end) where f(t) has a kink (a bump starts or
  // ends), ascending and without duplicates.
  std::vector<double> KinkTimes(double t_begin_s, double t_end_s) const;

 private:
  double InputSum(const LumpedElement& e, double t_s, bool rate) const;

  std::vector<std::vector<int>> coordinate_of_;  // [body][Dof]
  Eigen::VectorXd mass_diagonal_;
  Eigen::MatrixXd stiffness_;
  Eigen::MatrixXd damping_;
  std::vector<LumpedElement> elements_;
  std::vector<CosineBumpInput> inputs_;
  // f(t) = sum_j (force_per_displacement_[j] u_j(t) + force_per_velocity_[j] u_j'(t))
  std::vector<Eigen::VectorXd> force_per_displacement_;
  std::vector<Eigen::VectorXd> force_per_velocity_;
};

}  // namespace mbopt::lumped
