#include "worker/spatial/redundant_constraints.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "absl/strings/str_format.h"

namespace mbopt::spatial {

using Eigen::MatrixXd;
using Eigen::VectorXd;

IndependentConstraints IndependentCombination(const SpatialSystem& system, double t, const VectorXd& q) {
  IndependentConstraints out;
  MatrixXd phi_q;
  if (system.ConstraintJacobian(t, q, &phi_q) != 0) return out;
  const int bodies = static_cast<int>(system.model().bodies.size());
  const int m = system.num_constraints(), joint_rows = m - bodies;
  MatrixXd rest = phi_q.bottomRows(joint_rows);
  for (int b = 0; b < bodies; ++b) {
    const int at = SpatialSystem::kCoordinatesPerBody * b + 3;
    const Eigen::Vector4d p = q.segment<4>(at);
    if (!(p.squaredNorm() > 0.0)) return out;
    const Eigen::Vector4d unit = p.normalized();
    auto block = rest.middleCols<4>(at);
    block -= (block * unit) * unit.transpose();
  }
  int rank = 0;
  MatrixXd basis(joint_rows, 0);
  if (joint_rows > 0) {
    Eigen::ColPivHouseholderQR<MatrixXd> qr(rest);
    qr.setThreshold(kRelativeRankTolerance);
    rank = static_cast<int>(qr.rank());
    basis = qr.householderQ() * MatrixXd::Identity(joint_rows, rank);
  }
  out.ok = true;
  out.rank = bodies + rank;
  out.combination = MatrixXd::Zero(out.rank, m);
  out.combination.topLeftCorner(bodies, bodies).setIdentity();
  out.combination.bottomRightCorner(rank, joint_rows) = basis.transpose();
  return out;
}

CombinedConstraintSystem::CombinedConstraintSystem(const multibody::ConstrainedSystem& full, MatrixXd combination)
    : full_(full), combination_(std::move(combination)) {}

int CombinedConstraintSystem::MassMatrix(const VectorXd& q, MatrixXd* mass) const {
  return full_.MassMatrix(q, mass);
}

int CombinedConstraintSystem::AppliedForces(double t, const VectorXd& q, const VectorXd& v, VectorXd* forces) const {
  return full_.AppliedForces(t, q, v, forces);
}

int CombinedConstraintSystem::Constraints(double t, const VectorXd& q, VectorXd* phi) const {
  VectorXd all;
  const int status = full_.Constraints(t, q, &all);
  if (status == 0) *phi = combination_ * all;
  return status;
}

int CombinedConstraintSystem::ConstraintJacobian(double t, const VectorXd& q, MatrixXd* phi_q) const {
  MatrixXd all;
  const int status = full_.ConstraintJacobian(t, q, &all);
  if (status == 0) *phi_q = combination_ * all;
  return status;
}

int CombinedConstraintSystem::ConstraintTimeDerivative(double t, const VectorXd& q, VectorXd* phi_t) const {
  VectorXd all;
  const int status = full_.ConstraintTimeDerivative(t, q, &all);
  if (status == 0) *phi_t = combination_ * all;
  return status;
}

int CombinedConstraintSystem::AccelerationRightSide(double t, const VectorXd& q, const VectorXd& v,
                                                    VectorXd* gamma) const {
  VectorXd all;
  const int status = full_.AccelerationRightSide(t, q, v, &all);
  if (status == 0) *gamma = combination_ * all;
  return status;
}

// T Phi's derivatives from Phi's: the curvature with the multipliers
// T^T w, the velocity Jacobian and the pattern's rows through T.
int CombinedConstraintSystem::ConstraintCurvature(double t, const VectorXd& q, const VectorXd& w,
                                                  MatrixXd* curvature) const {
  return full_.ConstraintCurvature(t, q, combination_.transpose() * w, curvature);
}

int CombinedConstraintSystem::VelocityConstraintJacobian(double t, const VectorXd& q, const VectorXd& v,
                                                         MatrixXd* jacobian) const {
  MatrixXd all;
  const int status = full_.VelocityConstraintJacobian(t, q, v, &all);
  if (status == 0) *jacobian = combination_ * all;
  return status;
}

int CombinedConstraintSystem::ForceJacobians(double t, const VectorXd& q, const VectorXd& v, MatrixXd* q_q,
                                             MatrixXd* q_v) const {
  return full_.ForceJacobians(t, q, v, q_q, q_v);
}

void CombinedConstraintSystem::DerivativePattern(Pattern* coupling, Pattern* rows) const {
  Pattern all;
  full_.DerivativePattern(coupling, &all);
  const Pattern used = combination_.array() != 0.0;
  rows->setConstant(combination_.rows(), all.cols(), false);
  for (int r = 0; r < combination_.rows(); ++r) {
    for (int k = 0; k < combination_.cols(); ++k) {
      if (used(r, k)) rows->row(r) = rows->row(r) || all.row(k);
    }
  }
}

CombinedPerturbations::CombinedPerturbations(const std::vector<multibody::ParameterPerturbation>& full,
                                             const MatrixXd& combination) {
  for (const multibody::ParameterPerturbation& dp : full) {
    systems_.push_back(std::make_unique<CombinedConstraintSystem>(*dp.plus, combination));
    const CombinedConstraintSystem* plus = systems_.back().get();
    systems_.push_back(std::make_unique<CombinedConstraintSystem>(*dp.minus, combination));
    const CombinedConstraintSystem* minus = systems_.back().get();
    // A derivative model holds dM/dp and dQ/dp only (no constraint
    // depends on its parameter), which the combination does not touch.
    parameters_.push_back(multibody::ParameterPerturbation{plus, minus, dp.step, dp.magnitude, dp.derivative});
  }
}

namespace {

// The cosine of the largest principal angle between the ranges spanned by
// the joint rows of two combinations (orthonormal rows each).
double RangeCosine(const MatrixXd& a, const MatrixXd& b, int bodies) {
  const int ra = static_cast<int>(a.rows()) - bodies, rb = static_cast<int>(b.rows()) - bodies;
  if (ra == 0 || rb == 0) return 1.0;
  const MatrixXd overlap = a.bottomRightCorner(ra, a.cols() - bodies) * b.bottomRightCorner(rb, b.cols() - bodies).transpose();
  return Eigen::JacobiSVD<MatrixXd>(overlap).singularValues().minCoeff();
}

}  // namespace

spec::AnalysisFailure IntegrateWithRedundantRows(const SpatialSystem& system, const MatrixXd& combination, double t0,
                                                 const VectorXd& q0, const VectorXd& v0,
                                                 const std::vector<double>& times,
                                                 const multibody::ForwardDynamicsOptions& options,
                                                 const multibody::MotionCallback& at_instant,
                                                 multibody::ForwardDynamicsCounters* counters,
                                                 RedundantIntegrationCounters* redundant,
                                                 const multibody::ForwardSensitivityInput* sensitivities) {
  const int bodies = static_cast<int>(system.model().bodies.size());
  const int rank = static_cast<int>(combination.rows());
  // The requested instants and the checks between them, each marked.
  std::vector<std::pair<double, bool>> checks;
  if (!times.empty()) {
    const double spacing = (times.back() - t0) / kChecksPerSpan;
    double previous = t0;
    for (double t : times) {
      const int between = spacing > 0.0 ? static_cast<int>(std::ceil((t - previous) / spacing)) - 1 : 0;
      for (int k = 1; k <= between; ++k) checks.push_back({previous + (t - previous) * k / (between + 1), false});
      checks.push_back({t, true});
      previous = t;
    }
  }
  MatrixXd current = combination;
  double start_t = t0;
  VectorXd start_q = q0, start_v = v0;
  const bool with_sensitivities = sensitivities != nullptr && !sensitivities->parameters.empty();
  // The state's sensitivities at the start of each integration.
  std::vector<VectorXd> start_dq, start_dv;
  if (with_sensitivities) {
    start_dq = sensitivities->q0;
    start_dv = sensitivities->v0;
  }
  size_t next = 0;  // the first check not yet seen
  while (true) {
    std::vector<double> segment;
    std::vector<bool> requested;
    for (size_t k = next; k < checks.size(); ++k) {
      segment.push_back(checks[k].first);
      requested.push_back(checks[k].second);
    }
    if (segment.empty()) return spec::AnalysisFailure::Ok();
    const bool restart = start_t != t0;
    if (restart) {  // the integrator begins at start_t: its sample there was seen already
      segment.insert(segment.begin(), start_t);
      requested.insert(requested.begin(), false);
    }
    bool turned = false;
    size_t index = 0;
    const CombinedConstraintSystem combined(system, current);
    MatrixXd fresh;
    const multibody::MotionCallback check = [&](const multibody::MotionSample& s) {
      const size_t k = index++;
      if (restart && k == 0) return spec::AnalysisFailure::Ok();
      ++next;
      if (requested[k]) {
        if (spec::AnalysisFailure f = at_instant(s); !f.ok()) return f;
      }
      VectorXd phi;
      if (system.Constraints(s.t_s, s.q, &phi) != 0) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kNonFiniteValue,
            absl::StrFormat("the constraint equations are not finite at t = %.6g s", s.t_s));
      }
      phi.head(bodies) /= SpatialSystem::kNormRowScale;
      int row = 0;
      const double largest = phi.size() == 0 ? 0.0 : phi.cwiseAbs().maxCoeff(&row);
      redundant->largest_row = std::max(redundant->largest_row, largest);
      if (!(largest <= kRowBound)) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kAssembly,
            absl::StrFormat("%s is off by %.3g at t = %.6g s although the redundant joints' equations were combined "
                            "to hold it: the mechanism passed a pose where its mobility changes",
                            system.RowOwner(row), phi[row], s.t_s));
      }
      const IndependentConstraints now = IndependentCombination(system, s.t_s, s.q);
      if (!now.ok || now.rank != rank) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kAssembly,
            absl::StrFormat("the joints' equations have rank %d at t = %.6g s, %d at the start: the mechanism passed "
                            "a pose where its mobility changes",
                            now.rank, s.t_s, rank));
      }
      if (next < checks.size() && RangeCosine(current, now.combination, bodies) < kRestartCosine) {
        turned = true;
        fresh = now.combination;
        start_t = s.t_s;
        start_q = s.q;
        start_v = s.v;
        if (with_sensitivities) {
          for (size_t k = 0; k < s.sensitivities.size(); ++k) {
            start_dq[k] = s.sensitivities[k].q;
            start_dv[k] = s.sensitivities[k].v;
          }
        }
        // Stops this integration; the loop below restarts from here.
        return spec::AnalysisFailure::Of(spec::FailureKind::kCancelled, "new combination");
      }
      return spec::AnalysisFailure::Ok();
    };
    // The integrator reports its own totals: one integration's, summed here.
    multibody::ForwardDynamicsCounters part;
    std::unique_ptr<CombinedPerturbations> varied;
    multibody::ForwardSensitivityInput input;
    if (with_sensitivities) {
      varied = std::make_unique<CombinedPerturbations>(sensitivities->parameters, current);
      input.parameters = varied->parameters();
      input.q0 = start_dq;
      input.v0 = start_dv;
    }
    const spec::AnalysisFailure f = multibody::IntegrateForward(combined, start_t, start_q, start_v, segment, options,
                                                                check, &part, with_sensitivities ? &input : nullptr);
    counters->steps += part.steps;
    counters->residual_evaluations += part.residual_evaluations;
    counters->jacobian_evaluations += part.jacobian_evaluations;
    counters->jacobian_residual_evaluations += part.jacobian_residual_evaluations;
    counters->nonlinear_iterations += part.nonlinear_iterations;
    counters->error_test_failures += part.error_test_failures;
    counters->convergence_failures += part.convergence_failures;
    counters->sparse_linear_solver = part.sparse_linear_solver;
    counters->max_position_drift = std::max(counters->max_position_drift, part.max_position_drift);
    counters->max_velocity_drift = std::max(counters->max_velocity_drift, part.max_velocity_drift);
    if (!turned) return f;
    current = fresh;
    ++redundant->restarts;
  }
}

}  // namespace mbopt::spatial
