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
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "worker/model/lumped_model.h"

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
  Eigen::VectorXd s, sv, a;    // scratch of the sensitivity right-hand side
  Eigen::VectorXd zero;        // q = 0, for the ground-input part of a deflection
  std::string sundials_message;
  // IntegratorSettings::max_wall_seconds (<= 0: none), checked in Rhs.
  double max_wall_seconds = 0;
  std::chrono::steady_clock::time_point start;
  bool wall_time_exceeded = false;

  // d f / dp_k at t.
  void ForcingDerivative(int k, double t, Eigen::VectorXd* out) const {
    out->setZero(n);
    const ParameterDerivative& d = derivatives[static_cast<size_t>(k)];
    for (int e : d.stiffness_elements) {
      *out -= model->elements()[static_cast<size_t>(e)].gradient * model->Deflection(e, zero, t);
    }
    for (int e : d.damping_elements) {
      *out -= model->elements()[static_cast<size_t>(e)].gradient *
              model->DeflectionRate(e, zero, t);
    }
  }
  // d q'' / dp_k from the differentiated equations of motion.
  void AccelerationDerivative(int k, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              const Eigen::VectorXd& qddot, const Eigen::VectorXd& s,
                              const Eigen::VectorXd& sv, Eigen::VectorXd* out) {
    const ParameterDerivative& d = derivatives[static_cast<size_t>(k)];
    ForcingDerivative(k, t, &rhs);
    rhs -= d.mass_diagonal.cwiseProduct(qddot);
    rhs.noalias() -= d.damping * v;
    rhs.noalias() -= d.stiffness * q;
    *out = inverse_mass.cwiseProduct(rhs);
    out->noalias() -= minv_k * s;
    out->noalias() -= minv_c * sv;
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
  Eigen::VectorXd& s = p->s;
  Eigen::VectorXd& sv = p->sv;
  Eigen::VectorXd& a = p->a;
  for (int k = 0; k < num_sensitivities; ++k) {
    s = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(ys[k]), n);
    sv = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(ys[k]) + n, n);
    p->AccelerationDerivative(k, t, q, v, qddot, s, sv, &a);
    double* out = N_VGetArrayPointer(ysdot[k]);
    Eigen::Map<Eigen::VectorXd>(out, n) = sv;
    Eigen::Map<Eigen::VectorXd>(out + n, n) = a;
    if (!a.allFinite()) return -1;
  }
  return 0;
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
    const std::vector<int>& parameters) {
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

  // SUNDIALS setup: BDF, dense Newton, tolerances as IntegrateLumped.
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
  std::vector<realtype> pbar(static_cast<size_t>(ns));
  for (int k = 0; k < ns; ++k) {
    const double value = std::abs(parameter_values_si[static_cast<size_t>(parameters[k])]);
    pbar[static_cast<size_t>(k)] = value > 0.0 ? value : 1.0;
  }
  bool ok = check(CVodeSetErrHandlerFn(s.cvode, &CaptureMessage, &problem), "CVodeSetErrHandlerFn") &&
            check(CVodeInit(s.cvode, &Rhs, 0.0, s.y), "CVodeInit") &&
            check(CVodeSetUserData(s.cvode, &problem), "CVodeSetUserData") &&
            check(CVodeSVtolerances(s.cvode, settings.relative_tolerance, s.abstol),
                  "CVodeSVtolerances") &&
            check(CVodeSetLinearSolver(s.cvode, s.linear_solver, s.matrix),
                  "CVodeSetLinearSolver") &&
            check(CVodeSetJacFn(s.cvode, &Jacobian), "CVodeSetJacFn") &&
            check(CVodeSetMaxNumSteps(s.cvode, settings.max_steps), "CVodeSetMaxNumSteps") &&
            check(CVodeSensInit(s.cvode, ns, CV_STAGGERED, &SensitivityRhs, s.ys),
                  "CVodeSensInit") &&
            check(CVodeSetSensParams(s.cvode, nullptr, pbar.data(), nullptr),
                  "CVodeSetSensParams") &&
            check(CVodeSensEEtolerances(s.cvode), "CVodeSensEEtolerances") &&
            check(CVodeSetSensErrCon(s.cvode, SUNTRUE), "CVodeSetSensErrCon");

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
  Eigen::VectorXd q(n), v(n), qddot(n), sq(n), sv(n), dqddot(n);
  for (size_t i = 0; ok && i < instants.size(); ++i) {
    const double t = instants[i];
    while (ok && next_kink < kinks.size() && kinks[next_kink] <= t) {
      const double kink = kinks[next_kink++];
      ok = advance(kink) && check(CVodeReInit(s.cvode, kink, s.y), "CVodeReInit") &&
           check(CVodeSensReInit(s.cvode, CV_STAGGERED, s.ys), "CVodeSensReInit") && set_stop();
    }
    if (!ok || !advance(t)) {
      ok = false;
      break;
    }
    q = y.head(n);
    v = y.tail(n);
    m.Acceleration(t, q, v, &qddot);
    for (size_t o = 0; o < plans.size(); ++o) {
      const Plan& plan = plans[o];
      const double value = plan.deflection
                               ? m.Deflection(plan.index, q, t)
                               : m.PointAcceleration(plan.index, plan.ox, plan.oy, plan.axis, qddot);
      report.outputs[o].series[0].push_back(value);
    }
    for (int k = 0; k < ns; ++k) {
      sq = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(s.ys[k]), n);
      sv = Eigen::Map<const Eigen::VectorXd>(N_VGetArrayPointer(s.ys[k]) + n, n);
      bool need_acceleration = false;
      for (const Plan& plan : plans) need_acceleration = need_acceleration || !plan.deflection;
      if (need_acceleration) problem.AccelerationDerivative(k, t, q, v, qddot, sq, sv, &dqddot);
      for (size_t o = 0; o < plans.size(); ++o) {
        const Plan& plan = plans[o];
        const double derivative =
            plan.deflection
                ? m.elements()[static_cast<size_t>(plan.index)].gradient.dot(sq)
                : m.PointAcceleration(plan.index, plan.ox, plan.oy, plan.axis, dqddot);
        result.output_derivatives[static_cast<size_t>(k)][o].push_back(derivative);
      }
    }
  }
  long steps = 0, rhs = 0, jacobians = 0, newton = 0;
  CVodeGetNumSteps(s.cvode, &steps);
  CVodeGetNumRhsEvals(s.cvode, &rhs);
  CVodeGetNumJacEvals(s.cvode, &jacobians);
  CVodeGetNumNonlinSolvIters(s.cvode, &newton);
  report.counters.time_steps = steps;
  report.counters.rhs_evaluations = rhs;
  report.counters.jacobian_evaluations = jacobians;
  report.counters.newton_iterations = newton;
  if (!ok) {
    report = Failed(report, failure.empty() ? "sensitivity integration failed" : failure);
    result.output_derivatives.clear();
  }
  return result;
}

}  // namespace mbopt::solve
