#include "worker/solve/lumped_sensitivity.h"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "worker/model/lumped_model.h"
#include "worker/solve/cvodes_integrator.h"
#include "worker/solve/integrate_across_kinks.h"
#include "worker/solve/lumped_newton_operator.h"

namespace mbopt::solve {
namespace {

bool Uses(const spec::Number& number, int parameter) { return number.param == parameter; }

// The model's derivatives with respect to one parameter.
struct ParameterDerivative {
  Eigen::VectorXd mass_diagonal;  // dM/dp
  Eigen::MatrixXd stiffness;      // dK/dp
  Eigen::MatrixXd damping;        // dC/dp
  std::vector<int> stiffness_elements;  // df/dp = -sum g h (these) - sum g h' (the next)
  std::vector<int> damping_elements;
};

// Everything the C callbacks see.
struct SensitivityProblem {
  const model::LumpedModel* model = nullptr;
  int n = 0;
  Eigen::VectorXd inverse_mass;
  Eigen::MatrixXd minv_k, minv_c;
  std::vector<ParameterDerivative> derivatives;
  Eigen::VectorXd force, rhs;  // scratch
  Eigen::VectorXd zero;        // q = 0, for the ground-input part of a deflection
  // Ground-input part of each element's deflection and its rate at
  // `inputs_time`: every parameter's df/dp is built from these, so one
  // sensitivity right-hand side evaluates the inputs once, not once per
  // parameter.
  std::vector<double> input_deflection, input_rate;
  double inputs_time = std::numeric_limits<double>::quiet_NaN();
  std::string sundials_message;
  // IntegratorSettings::max_wall_seconds (<= 0: none), checked in Rhs.
  double max_wall_seconds = 0;
  std::chrono::steady_clock::time_point start;
  bool wall_time_exceeded = false;

  void EvaluateInputs(double t) {
    if (t == inputs_time) return;
    for (size_t e = 0; e < model->elements().size(); ++e) {
      input_deflection[e] = model->Deflection(static_cast<int>(e), zero, t);
      input_rate[e] = model->DeflectionRate(static_cast<int>(e), zero, t);
    }
    inputs_time = t;
  }
  // d f / dp_k at the time of the last EvaluateInputs.
  void ForcingDerivative(int k, Eigen::VectorXd* out) const {
    out->setZero(n);
    const ParameterDerivative& d = derivatives[static_cast<size_t>(k)];
    for (int e : d.stiffness_elements) {
      *out -= model->elements()[static_cast<size_t>(e)].gradient *
              input_deflection[static_cast<size_t>(e)];
    }
    for (int e : d.damping_elements) {
      *out -= model->elements()[static_cast<size_t>(e)].gradient *
              input_rate[static_cast<size_t>(e)];
    }
  }
  // d q'' / dp_k from the differentiated equations of motion.
  template <typename Out>
  void AccelerationDerivative(int k, double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                              const Eigen::Ref<const Eigen::VectorXd>& v,
                              const Eigen::Ref<const Eigen::VectorXd>& qddot,
                              const Eigen::Ref<const Eigen::VectorXd>& s,
                              const Eigen::Ref<const Eigen::VectorXd>& sv, Out&& out) {
    const ParameterDerivative& d = derivatives[static_cast<size_t>(k)];
    EvaluateInputs(t);
    ForcingDerivative(k, &rhs);
    rhs -= d.mass_diagonal.cwiseProduct(qddot);
    rhs.noalias() -= d.damping * v;
    rhs.noalias() -= d.stiffness * q;
    out = inverse_mass.cwiseProduct(rhs);
    out.noalias() -= minv_k * s;
    out.noalias() -= minv_c * sv;
  }
};

int Rhs(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  if (p->max_wall_seconds > 0 &&
      std::chrono::duration<double>(std::chrono::steady_clock::now() - p->start).count() >
          p->max_wall_seconds) {
    p->wall_time_exceeded = true;
    return -1;
  }
  const int n = p->n;
  Eigen::Map<const Eigen::VectorXd> q(N_VGetArrayPointer(y), n), v(N_VGetArrayPointer(y) + n, n);
  Eigen::Map<Eigen::VectorXd> qdot(N_VGetArrayPointer(ydot), n),
      vdot(N_VGetArrayPointer(ydot) + n, n);
  qdot = v;
  p->model->Forcing(t, &p->force);
  vdot = p->inverse_mass.cwiseProduct(p->force);
  vdot.noalias() -= p->minv_k * q;
  vdot.noalias() -= p->minv_c * v;
  return vdot.allFinite() ? 0 : -1;
}

int SensitivityRhs(int num_sensitivities, realtype t, N_Vector y, N_Vector ydot, N_Vector* ys,
                   N_Vector* ysdot, void* user_data, N_Vector, N_Vector) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  const int n = p->n;
  const Eigen::Map<const Eigen::VectorXd> q(N_VGetArrayPointer(y), n),
      v(N_VGetArrayPointer(y) + n, n), qddot(N_VGetArrayPointer(ydot) + n, n);
  for (int k = 0; k < num_sensitivities; ++k) {
    const double* in = N_VGetArrayPointer(ys[k]);
    double* out = N_VGetArrayPointer(ysdot[k]);
    const Eigen::Map<const Eigen::VectorXd> s(in, n), sv(in + n, n);
    Eigen::Map<Eigen::VectorXd> a(out + n, n);
    p->AccelerationDerivative(k, t, q, v, qddot, s, sv, a);
    Eigen::Map<Eigen::VectorXd>(out, n) = sv;
    if (!a.allFinite()) return -1;
  }
  return 0;
}

// CV_STAGGERED1's form: one sensitivity per call.
int SensitivityRhs1(int, realtype t, N_Vector y, N_Vector ydot, int k, N_Vector ys,
                    N_Vector ysdot, void* user_data, N_Vector, N_Vector) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  const int n = p->n;
  const Eigen::Map<const Eigen::VectorXd> q(N_VGetArrayPointer(y), n),
      v(N_VGetArrayPointer(y) + n, n), qddot(N_VGetArrayPointer(ydot) + n, n);
  const double* in = N_VGetArrayPointer(ys);
  double* out = N_VGetArrayPointer(ysdot);
  const Eigen::Map<const Eigen::VectorXd> s(in, n), sv(in + n, n);
  Eigen::Map<Eigen::VectorXd> a(out + n, n);
  p->AccelerationDerivative(k, t, q, v, qddot, s, sv, a);
  Eigen::Map<Eigen::VectorXd>(out, n) = sv;
  return a.allFinite() ? 0 : -1;
}

int Jacobian(realtype, N_Vector, N_Vector, SUNMatrix jac, void* user_data, N_Vector, N_Vector,
             N_Vector) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  const int n = p->n;
  Eigen::Map<Eigen::MatrixXd> j(SUNDenseMatrix_Data(jac), 2 * n, 2 * n);
  j.setZero();
  j.topRightCorner(n, n).setIdentity();
  j.bottomLeftCorner(n, n) = -p->minv_k;
  j.bottomRightCorner(n, n) = -p->minv_c;
  return 0;
}

void CaptureMessage(int code, const char* module, const char* function, char* message,
                    void* user_data) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  p->sundials_message = absl::StrFormat("%s/%s (%d): %s", module != nullptr ? module : "",
                                        function != nullptr ? function : "", code,
                                        message != nullptr ? message : "");
}

// Owns every SUNDIALS object of one integration.
struct Sundials {
  SUNContext context = nullptr;
  void* cvode = nullptr;
  N_Vector y = nullptr;
  N_Vector abstol = nullptr;
  N_Vector* ys = nullptr;
  int num_sensitivities = 0;
  SUNMatrix matrix = nullptr;
  SUNLinearSolver linear_solver = nullptr;

  Sundials() = default;
  Sundials(const Sundials&) = delete;
  Sundials& operator=(const Sundials&) = delete;
  ~Sundials() {
    if (cvode != nullptr) CVodeFree(&cvode);
    if (linear_solver != nullptr) SUNLinSolFree(linear_solver);
    if (matrix != nullptr) SUNMatDestroy(matrix);
    if (ys != nullptr) N_VDestroyVectorArray(ys, num_sensitivities);
    if (abstol != nullptr) N_VDestroy(abstol);
    if (y != nullptr) N_VDestroy(y);
    if (context != nullptr) SUNContext_Free(&context);
  }
};

engine::AnalysisReport Failed(engine::AnalysisReport report, std::string reason) {
  report.status = engine::AnalysisStatus::kFailed;
  report.failure_reason = std::move(reason);
  report.outputs.clear();
  return report;
}

// The states and all sensitivities as one ODE of size 2n (1 + ns),
// Y = (y, s_1, ..., s_ns), integrated by CVODES without its sensitivity
// module. Its Newton matrix is block lower triangular,
//
//     [ I - gJ                 ]
//     [ -g B_k        I - gJ   ],   B_k = d(sensitivity RHS k)/dy,
//
// so one n x n factorization of M + gC + g^2 K (as IntegrateLumped) solves
// every block: x_0 from b_0, then x_k from b_k + g B_k x_0. The error test
// weighs every component with the tolerances CVodeSensEEtolerances would
// give the sensitivities (rtol, atol_i / pbar_k), i.e. the sensitivities are
// error-controlled as with CVodeSetSensErrCon(SUNTRUE). What this saves over
// the sensitivity module is per-vector overhead: CVODES does each of its
// vector operations once on a 2n (1 + ns) array instead of 1 + ns times on
// 2n-element vectors, which dominates for small n.
template <typename Record>
std::string IntegrateAugmented(SensitivityProblem* p, const spec::IntegratorSettings& settings,
                               const LumpedSensitivityOptions& options, double omega_max,
                               const std::vector<double>& pbar,
                               const std::vector<double>& instants, const Record& record,
                               engine::AnalysisCounters* counters,
                               LumpedSensitivityCounters* sensitivity_counters) {
  const model::LumpedModel& m = *p->model;
  const int n = p->n;
  const int ns = static_cast<int>(p->derivatives.size());
  const int block = 2 * n;
  const int size = block * (1 + ns);
  // B_k's only nonzero rows (the rate rows): M^-1 (dM M^-1 [K C] - [dK dC]).
  std::vector<Eigen::MatrixXd> coupling(static_cast<size_t>(ns));
  Eigen::MatrixXd minv_kc(n, 2 * n);
  minv_kc << p->minv_k, p->minv_c;
  for (int k = 0; k < ns; ++k) {
    const ParameterDerivative& d = p->derivatives[static_cast<size_t>(k)];
    Eigen::MatrixXd b = d.mass_diagonal.asDiagonal() * minv_kc;
    b.leftCols(n) -= d.stiffness;
    b.rightCols(n) -= d.damping;
    coupling[static_cast<size_t>(k)] = p->inverse_mass.asDiagonal() * b;
  }
  auto rhs = [p, n, ns, block](double t, const double* y, double* ydot) -> int {
    const Eigen::Map<const Eigen::VectorXd> q(y, n), v(y + n, n);
    Eigen::Map<Eigen::VectorXd> qdot(ydot, n), vdot(ydot + n, n);
    qdot = v;
    p->model->Forcing(t, &p->force);
    vdot = p->inverse_mass.cwiseProduct(p->force);
    vdot.noalias() -= p->minv_k * q;
    vdot.noalias() -= p->minv_c * v;
    if (!vdot.allFinite()) return -1;
    for (int k = 0; k < ns; ++k) {
      const double* in = y + block * (1 + k);
      double* out = ydot + block * (1 + k);
      const Eigen::Map<const Eigen::VectorXd> s(in, n), sv(in + n, n);
      Eigen::Map<Eigen::VectorXd> a(out + n, n);
      p->AccelerationDerivative(k, t, q, v, vdot, s, sv, a);
      Eigen::Map<Eigen::VectorXd>(out, n) = sv;
      if (!a.allFinite()) return -1;
    }
    return 0;
  };
  // Each block through the plain integration's operator; a sensitivity
  // block's right-hand side first takes the coupling to the state block
  // already solved (the Newton matrix is block lower triangular).
  LumpedNewtonOperator newton(m);
  Eigen::VectorXd state_x(block);
  auto newton_solve = [&](double, double gamma, double* bx, bool* refactored) -> int {
    if (newton.Prepare(gamma)) *refactored = true;
    for (int k = 0; k <= ns; ++k) {
      double* x = bx + block * k;
      Eigen::Map<Eigen::VectorXd> b(x, block), bv(x + n, n);
      if (k > 0) bv.noalias() += gamma * (coupling[static_cast<size_t>(k - 1)] * state_x);
      if (!newton.Solve(x)) return 1;
      if (k == 0) state_x = b;
    }
    return 0;
  };

  // CVODES' sensitivity module requires each of the 1 + ns blocks to pass
  // the error test on its own (the largest of the block norms); the
  // augmented system has one WRMS norm over all blocks, which averages a
  // large error in one block with small ones elsewhere. Dividing every
  // tolerance by sqrt(1 + ns) makes that norm the root-sum-square of the
  // block norms, never less than the largest: the test is at least as
  // strict as the module's.
  const double norm_bound = options.augmented_block_norm_bound ? std::sqrt(1.0 + ns) : 1.0;
  CvodesOptions cv;
  cv.relative_tolerance = settings.relative_tolerance / norm_bound;
  cv.max_steps = settings.max_steps;
  cv.max_wall_seconds = settings.max_wall_seconds;
  cv.absolute_tolerances.resize(size);
  for (int k = 0; k <= ns; ++k) {
    const double scale = (k == 0 ? 1.0 : 1.0 / pbar[static_cast<size_t>(k - 1)]) / norm_bound;
    cv.absolute_tolerances.segment(block * k, n).setConstant(settings.absolute_tolerance * scale);
    cv.absolute_tolerances.segment(block * k + n, n)
        .setConstant(settings.absolute_tolerance * std::max(1.0, omega_max) * scale);
  }
  Eigen::VectorXd y = Eigen::VectorXd::Zero(size);
  absl::StatusOr<std::unique_ptr<CvodesIntegrator>> created =
      CvodesIntegrator::CreateWithNewtonSolver(size, rhs, newton_solve,
                                               CvodesIntegrator::NewtonRefresh::kCvodesSetups, cv,
                                               0.0, y);
  if (!created.ok()) return absl::StrCat("integrator setup: ", created.status().message());
  CvodesIntegrator& integrator = **created;

  const double t_last = instants.empty() ? 0.0 : instants.back();
  const std::string failure = IntegrateAcrossKinks(
      integrator, m.KinkTimes(0.0, t_last), instants, &y, [&](double t, const Eigen::VectorXd& state) {
        record(t, state.head(block), [&](int k) { return state.data() + block * (1 + k); });
        return std::string();
      });
  const CvodesCounters c = integrator.counters();
  counters->time_steps = c.steps;
  counters->rhs_evaluations = c.rhs_evaluations;
  counters->jacobian_evaluations = c.jacobian_evaluations;
  counters->newton_iterations = c.nonlinear_iterations;
  // One right-hand side evaluates every sensitivity; one Newton iteration
  // corrects them all.
  sensitivity_counters->sensitivity_rhs_evaluations = c.rhs_evaluations;
  sensitivity_counters->sensitivity_newton_iterations = c.nonlinear_iterations;
  sensitivity_counters->linear_setups = c.jacobian_evaluations;
  sensitivity_counters->error_test_failures = c.error_test_failures;
  return failure;
}

}  // namespace

std::string LumpedSensitivityUnavailable(const spec::Scene& scene,
                                         const std::vector<int>& parameters) {
  const auto* m = std::get_if<spec::LumpedModel>(&scene.model);
  if (m == nullptr) return "simulator sensitivities are available only for lumped scenes";
  for (int p : parameters) {
    const std::string name = p >= 0 && p < static_cast<int>(scene.parameters.size())
                                 ? scene.parameters[static_cast<size_t>(p)].name
                                 : absl::StrCat("#", p);
    auto where = [&](const std::string& what) {
      return absl::StrCat("parameter \"", name, "\" sets ", what,
                          ", which has no simulator sensitivity (only masses, inertias, "
                          "stiffnesses and dampings have)");
    };
    for (const spec::SpringDamper& e : m->elements) {
      for (const spec::Attachment* at : {&e.a, &e.b}) {
        if (Uses(at->offset_m.x, p) || Uses(at->offset_m.y, p)) {
          return where(absl::StrCat("an attachment offset of element ", e.name));
        }
      }
    }
    for (const spec::GroundInput& in : m->inputs) {
      const spec::CosineBump& b = in.bump;
      if (Uses(b.height_m, p) || Uses(b.length_m, p) || Uses(b.speed_m_per_s, p) ||
          Uses(b.start_time_s, p) || Uses(in.delay_s, p)) {
        return where(absl::StrCat("ground input ", in.name));
      }
    }
    for (const spec::Output& out : scene.outputs) {
      if (const auto* a = std::get_if<spec::BodyAccelerationOutput>(&out.kind)) {
        if (Uses(a->offset_m.x, p) || Uses(a->offset_m.y, p)) {
          return where(absl::StrCat("the offset of output ", out.name));
        }
      }
    }
  }
  return "";
}

LumpedSensitivityResult SimulateLumpedWithSensitivities(
    const spec::Scene& scene, const std::vector<double>& parameter_values_si,
    const std::vector<int>& parameters, const LumpedSensitivityOptions& options) {
  LumpedSensitivityResult result;
  engine::AnalysisReport& report = result.report;
  report.formulation = engine::Formulation::kDynamic;
  report.times_s = scene.time_grid.Instants();
  const auto* spec_model = std::get_if<spec::LumpedModel>(&scene.model);
  if (spec_model == nullptr) {
    report = Failed(report, "scene has no lumped model");
    return result;
  }
  if (const std::string why = LumpedSensitivityUnavailable(scene, parameters); !why.empty()) {
    report = Failed(report, why);
    return result;
  }
  if (parameter_values_si.size() != scene.parameters.size() || parameters.empty()) {
    report = Failed(report, absl::StrCat("got ", parameter_values_si.size(),
                                         " parameter values for ", scene.parameters.size(),
                                         " scene parameters and ", parameters.size(),
                                         " sensitivity parameters"));
    return result;
  }
  absl::StatusOr<model::LumpedModel> assembled =
      model::LumpedModel::Assemble(*spec_model, parameter_values_si);
  if (!assembled.ok()) {
    report = Failed(report, std::string(assembled.status().message()));
    return result;
  }
  const model::LumpedModel& m = *assembled;
  const int n = m.num_coordinates();
  const int ns = static_cast<int>(parameters.size());

  SensitivityProblem problem;
  problem.model = &m;
  problem.n = n;
  problem.inverse_mass = m.mass_diagonal().cwiseInverse();
  problem.minv_k = problem.inverse_mass.asDiagonal() * m.stiffness();
  problem.minv_c = problem.inverse_mass.asDiagonal() * m.damping();
  problem.zero = Eigen::VectorXd::Zero(n);
  problem.force = Eigen::VectorXd::Zero(n);
  problem.rhs = Eigen::VectorXd::Zero(n);
  problem.input_deflection.assign(m.elements().size(), 0.0);
  problem.input_rate.assign(m.elements().size(), 0.0);
  problem.max_wall_seconds = scene.integrator.max_wall_seconds;
  problem.start = std::chrono::steady_clock::now();
  for (int p : parameters) {
    ParameterDerivative d;
    d.mass_diagonal = Eigen::VectorXd::Zero(n);
    d.stiffness = Eigen::MatrixXd::Zero(n, n);
    d.damping = Eigen::MatrixXd::Zero(n, n);
    for (size_t b = 0; b < spec_model->bodies.size(); ++b) {
      const spec::Body& body = spec_model->bodies[b];
      const int body_index = static_cast<int>(b);
      if (Uses(body.mass_kg, p)) {
        for (spec::Dof dof : {spec::Dof::kX, spec::Dof::kY}) {
          const int i = m.CoordinateOf(body_index, dof);
          if (i >= 0) d.mass_diagonal[i] += 1.0;
        }
      }
      if (Uses(body.inertia_kg_m2, p)) {
        const int i = m.CoordinateOf(body_index, spec::Dof::kRotation);
        if (i >= 0) d.mass_diagonal[i] += 1.0;
      }
    }
    for (size_t e = 0; e < spec_model->elements.size(); ++e) {
      const Eigen::VectorXd& g = m.elements()[e].gradient;
      if (Uses(spec_model->elements[e].stiffness_n_per_m, p)) {
        d.stiffness += g * g.transpose();
        d.stiffness_elements.push_back(static_cast<int>(e));
      }
      if (Uses(spec_model->elements[e].damping_n_s_per_m, p)) {
        d.damping += g * g.transpose();
        d.damping_elements.push_back(static_cast<int>(e));
      }
    }
    problem.derivatives.push_back(std::move(d));
  }

  // Outputs to evaluate (as SimulateLumped).
  struct Plan {
    bool deflection = true;
    int index = -1;
    double ox = 0, oy = 0;
    spec::Axis axis = spec::Axis::kY;
  };
  std::vector<Plan> plans;
  for (const spec::Output& out : scene.outputs) {
    Plan plan;
    if (const auto* d = std::get_if<spec::ElementDeflectionOutput>(&out.kind)) {
      plan.index = d->element;
    } else if (const auto* a = std::get_if<spec::BodyAccelerationOutput>(&out.kind)) {
      plan.deflection = false;
      plan.index = a->body;
      plan.ox = a->offset_m.x.Resolve(parameter_values_si);
      plan.oy = a->offset_m.y.Resolve(parameter_values_si);
      plan.axis = a->axis;
    } else {
      report = Failed(report, absl::StrCat("output \"", out.name,
                                           "\" is not available for a lumped scene"));
      return result;
    }
    plans.push_back(plan);
    engine::OutputValues values;
    values.name = out.name;
    values.series_labels = {out.name};
    values.series.assign(1, std::vector<double>());
    report.outputs.push_back(std::move(values));
  }
  result.output_derivatives.assign(static_cast<size_t>(ns),
                                   std::vector<std::vector<double>>(plans.size()));

  // Tolerances as IntegrateLumped for either method; the module below uses
  // BDF with CVODES' dense Newton solver.
  Sundials s;
  std::string failure;
  auto check = [&](int flag, const char* call) {
    if (flag >= 0 || !failure.empty()) return flag >= 0;
    failure = absl::StrFormat("%s failed (%d)", call, flag);
    if (!problem.sundials_message.empty()) absl::StrAppend(&failure, ": ", problem.sundials_message);
    return false;
  };
  const spec::IntegratorSettings& settings = scene.integrator;
  const Eigen::VectorXd inverse_root_mass = problem.inverse_mass.cwiseSqrt();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> modes(
      inverse_root_mass.asDiagonal() * m.stiffness() * inverse_root_mass.asDiagonal(),
      Eigen::EigenvaluesOnly);
  const double omega_max = std::sqrt(std::max(0.0, modes.eigenvalues().maxCoeff()));
  std::vector<double> pbar(static_cast<size_t>(ns));
  for (int k = 0; k < ns; ++k) {
    const double value = std::abs(parameter_values_si[static_cast<size_t>(parameters[k])]);
    pbar[static_cast<size_t>(k)] = value > 0.0 ? value : 1.0;
  }

  // Appends the outputs and their derivatives at instant t from the state
  // (q, q') and sensitivity(k) -> (s, s') of parameter k.
  bool need_acceleration = false;
  for (const Plan& plan : plans) need_acceleration = need_acceleration || !plan.deflection;
  Eigen::VectorXd q(n), v(n), qddot(n), dqddot(n);
  auto record = [&](double t, const Eigen::Ref<const Eigen::VectorXd>& state,
                    const auto& sensitivity) {
    q = state.head(n);
    v = state.tail(n);
    m.Acceleration(t, q, v, &qddot);
    for (size_t o = 0; o < plans.size(); ++o) {
      const Plan& plan = plans[o];
      const double value = plan.deflection
                               ? m.Deflection(plan.index, q, t)
                               : m.PointAcceleration(plan.index, plan.ox, plan.oy, plan.axis, qddot);
      report.outputs[o].series[0].push_back(value);
    }
    for (int k = 0; k < ns; ++k) {
      const double* sk = sensitivity(k);
      const Eigen::Map<const Eigen::VectorXd> sq(sk, n), sv(sk + n, n);
      if (need_acceleration) problem.AccelerationDerivative(k, t, q, v, qddot, sq, sv, dqddot);
      for (size_t o = 0; o < plans.size(); ++o) {
        const Plan& plan = plans[o];
        const double derivative =
            plan.deflection
                ? m.elements()[static_cast<size_t>(plan.index)].gradient.dot(sq)
                : m.PointAcceleration(plan.index, plan.ox, plan.oy, plan.axis, dqddot);
        result.output_derivatives[static_cast<size_t>(k)][o].push_back(derivative);
      }
    }
  };

  if (options.method == LumpedSensitivityOptions::Method::kAugmentedSystem) {
    const std::string failure =
        IntegrateAugmented(&problem, settings, options, omega_max, pbar, report.times_s, record,
                           &report.counters, &result.counters);
    if (!failure.empty()) {
      report = Failed(report, failure);
      result.output_derivatives.clear();
    }
    return result;
  }
  if (!(options.tolerance_factor > 0.0) || !std::isfinite(options.tolerance_factor)) {
    report = Failed(report, absl::StrCat("sensitivity tolerance factor must be positive, got ",
                                         options.tolerance_factor));
    return result;
  }
  if (SUNContext_Create(nullptr, &s.context) != 0) {
    report = Failed(report, "SUNContext_Create failed");
    return result;
  }
  s.y = N_VNew_Serial(2 * n, s.context);
  s.abstol = N_VNew_Serial(2 * n, s.context);
  s.cvode = CVodeCreate(CV_BDF, s.context);
  if (s.y == nullptr || s.abstol == nullptr || s.cvode == nullptr) {
    report = Failed(report, "SUNDIALS allocation failed");
    return result;
  }
  if (options.fused_vector_operations && N_VEnableFusedOps_Serial(s.y, SUNTRUE) != 0) {
    report = Failed(report, "N_VEnableFusedOps_Serial failed");
    return result;
  }
  Eigen::Map<Eigen::VectorXd> y(N_VGetArrayPointer(s.y), 2 * n);
  y.setZero();
  Eigen::Map<Eigen::VectorXd> abstol(N_VGetArrayPointer(s.abstol), 2 * n);
  abstol.head(n).setConstant(settings.absolute_tolerance);
  abstol.tail(n).setConstant(settings.absolute_tolerance * std::max(1.0, omega_max));
  s.matrix = SUNDenseMatrix(2 * n, 2 * n, s.context);
  s.linear_solver = SUNLinSol_Dense(s.y, s.matrix, s.context);
  s.ys = N_VCloneVectorArray(ns, s.y);
  s.num_sensitivities = ns;
  if (s.matrix == nullptr || s.linear_solver == nullptr || s.ys == nullptr) {
    report = Failed(report, "SUNDIALS allocation failed");
    return result;
  }
  for (int k = 0; k < ns; ++k) N_VConst(0.0, s.ys[k]);
  int corrector = CV_STAGGERED;
  switch (options.corrector) {
    case LumpedSensitivityOptions::Corrector::kSimultaneous: corrector = CV_SIMULTANEOUS; break;
    case LumpedSensitivityOptions::Corrector::kStaggered: corrector = CV_STAGGERED; break;
    case LumpedSensitivityOptions::Corrector::kStaggered1: corrector = CV_STAGGERED1; break;
  }
  // Sensitivity tolerances: EE's own choice (rtol, atol_i / pbar_k), or the
  // same scaled by options.tolerance_factor.
  const bool estimated_tolerances = options.tolerance_factor == 1.0;
  N_Vector* sensitivity_abstol = nullptr;
  if (!estimated_tolerances) {
    sensitivity_abstol = N_VCloneVectorArray(ns, s.y);
    if (sensitivity_abstol == nullptr) {
      report = Failed(report, "SUNDIALS allocation failed");
      return result;
    }
    for (int k = 0; k < ns; ++k) {
      N_VScale(options.tolerance_factor / pbar[static_cast<size_t>(k)], s.abstol,
               sensitivity_abstol[k]);
    }
  }
  struct AbstolArray {
    N_Vector* v;
    int count;
    ~AbstolArray() {
      if (v != nullptr) N_VDestroyVectorArray(v, count);
    }
  } abstol_owner{sensitivity_abstol, ns};
  bool ok = check(CVodeSetErrHandlerFn(s.cvode, &CaptureMessage, &problem), "CVodeSetErrHandlerFn") &&
            check(CVodeInit(s.cvode, &Rhs, 0.0, s.y), "CVodeInit") &&
            check(CVodeSetUserData(s.cvode, &problem), "CVodeSetUserData") &&
            check(CVodeSVtolerances(s.cvode, settings.relative_tolerance, s.abstol),
                  "CVodeSVtolerances") &&
            check(CVodeSetLinearSolver(s.cvode, s.linear_solver, s.matrix),
                  "CVodeSetLinearSolver") &&
            check(CVodeSetJacFn(s.cvode, &Jacobian), "CVodeSetJacFn") &&
            check(CVodeSetMaxNumSteps(s.cvode, settings.max_steps), "CVodeSetMaxNumSteps") &&
            (options.jacobian_eval_frequency <= 0 ||
             check(CVodeSetJacEvalFrequency(s.cvode, options.jacobian_eval_frequency),
                   "CVodeSetJacEvalFrequency")) &&
            (options.linear_setup_frequency <= 0 ||
             check(CVodeSetLSetupFrequency(s.cvode, options.linear_setup_frequency),
                   "CVodeSetLSetupFrequency")) &&
            (corrector == CV_STAGGERED1
                 ? check(CVodeSensInit1(s.cvode, ns, corrector, &SensitivityRhs1, s.ys),
                         "CVodeSensInit1")
                 : check(CVodeSensInit(s.cvode, ns, corrector, &SensitivityRhs, s.ys),
                         "CVodeSensInit")) &&
            check(CVodeSetSensParams(s.cvode, nullptr, pbar.data(), nullptr),
                  "CVodeSetSensParams") &&
            (estimated_tolerances
                 ? check(CVodeSensEEtolerances(s.cvode), "CVodeSensEEtolerances")
                 : check(CVodeSensSVtolerances(
                             s.cvode, settings.relative_tolerance * options.tolerance_factor,
                             sensitivity_abstol),
                         "CVodeSensSVtolerances")) &&
            check(CVodeSetSensErrCon(s.cvode, options.error_control ? SUNTRUE : SUNFALSE),
                  "CVodeSetSensErrCon");

  const std::vector<double>& instants = report.times_s;
  const double t_last = instants.empty() ? 0.0 : instants.back();
  const std::vector<double> kinks = m.KinkTimes(0.0, t_last);
  size_t next_kink = 0;
  double t_now = 0.0;
  auto set_stop = [&]() {
    const double stop = next_kink < kinks.size() ? kinks[next_kink] : t_last;
    return stop <= t_now || check(CVodeSetStopTime(s.cvode, stop), "CVodeSetStopTime");
  };
  auto advance = [&](double t) {
    if (t <= t_now) return true;
    realtype reached = t_now;
    const int flag = CVode(s.cvode, t, s.y, &reached, CV_NORMAL);
    if (flag < 0) {
      failure = absl::StrFormat("integrator failed near t = %.9g (target %.9g): flag %d", reached,
                                t, flag);
      if (problem.wall_time_exceeded) {
        absl::StrAppend(&failure, ": wall-time limit of ", problem.max_wall_seconds, " s exceeded");
      }
      if (!problem.sundials_message.empty()) absl::StrAppend(&failure, " [", problem.sundials_message, "]");
      return false;
    }
    t_now = t;
    realtype t_sens = t;
    return check(CVodeGetSens(s.cvode, &t_sens, s.ys), "CVodeGetSens");
  };
  ok = ok && set_stop();
  // CVodeReInit (at every kink) zeroes CVODES' counters: they are summed
  // over the histories.
  bool history_counted = false;  // until the next CVodeReInit
  auto accumulate_counters = [&]() {
    long value = 0;
    auto add = [&](int (*get)(void*, long*), auto* total) {
      value = 0;
      if (get(s.cvode, &value) == CV_SUCCESS) *total += value;
    };
    add(&CVodeGetNumSteps, &report.counters.time_steps);
    add(&CVodeGetNumRhsEvals, &report.counters.rhs_evaluations);
    add(&CVodeGetNumJacEvals, &report.counters.jacobian_evaluations);
    add(&CVodeGetNumNonlinSolvIters, &report.counters.newton_iterations);
    LumpedSensitivityCounters& c = result.counters;
    add(&CVodeGetSensNumRhsEvals, &c.sensitivity_rhs_evaluations);
    add(&CVodeGetSensNumNonlinSolvIters, &c.sensitivity_newton_iterations);
    add(&CVodeGetNumLinSolvSetups, &c.linear_setups);
    add(&CVodeGetNumErrTestFails, &c.error_test_failures);
    add(&CVodeGetSensNumErrTestFails, &c.sensitivity_error_test_failures);
  };
  for (size_t i = 0; ok && i < instants.size(); ++i) {
    const double t = instants[i];
    while (ok && next_kink < kinks.size() && kinks[next_kink] <= t) {
      const double kink = kinks[next_kink++];
      if (!advance(kink)) {
        ok = false;
        break;
      }
      accumulate_counters();
      history_counted = true;
      ok = check(CVodeReInit(s.cvode, kink, s.y), "CVodeReInit");
      if (ok) history_counted = false;
      ok = ok && check(CVodeSensReInit(s.cvode, corrector, s.ys), "CVodeSensReInit") && set_stop();
    }
    if (!ok || !advance(t)) {
      ok = false;
      break;
    }
    record(t, y, [&](int k) { return N_VGetArrayPointer(s.ys[k]); });
  }
  if (!history_counted) accumulate_counters();
  if (!ok) {
    report = Failed(report, failure.empty() ? "sensitivity integration failed" : failure);
    result.output_derivatives.clear();
  }
  return result;
}

}  // namespace mbopt::solve
