#include "bench/compare/nlopt_peer.h"

#include <nlopt.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"

namespace mbopt::compare {
namespace {

// What the callbacks report for a design whose analysis failed: a large
// normalized value, so the peer sees an infeasible, bad point and backs off.
constexpr double kFailedValue = 1e6;

struct PeerContext {
  CountedStudy* study = nullptr;
  nlopt_opt opt = nullptr;
  bool min_max = false;
  int n = 0;                  // design variables (without b)
  double objective_scale = 1; // |F(x0)|
  std::int64_t cap = 0;
  bool cap_reached = false;
  absl::Status error;
  MethodRun* run = nullptr;
  std::vector<std::pair<Eigen::VectorXd, Candidate>> visited;

  // Cache of the last analysed design.
  std::optional<Eigen::VectorXd> x;
  CountedStudy::Point point;
  bool have_jacobians = false;
  Eigen::MatrixXd d_terms, d_rows;
};

void Stop(PeerContext* c) { nlopt_force_stop(c->opt); }

// Makes the cache hold x's values (and Jacobians if asked). False when the
// run must stop (cap, error); the callback then returns anything.
bool Ensure(PeerContext* c, const double* v, bool need_gradient) {
  const Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(v, c->n);
  if (!c->x.has_value() || *c->x != x) {
    if (c->study->analyses() + 1 > c->cap) {
      c->cap_reached = true;
      Stop(c);
      return false;
    }
    absl::StatusOr<CountedStudy::Point> p = c->study->Evaluate(x);
    if (!p.ok()) {
      c->error = p.status();
      Stop(c);
      return false;
    }
    c->x = x;
    c->point = *std::move(p);
    ++c->run->evaluations;
    c->have_jacobians = false;
    if (c->point.ok) {
      const Candidate cand{c->study->analyses(), c->point.objective, c->point.max_violation};
      c->run->candidates.push_back(cand);
      c->visited.emplace_back(x, cand);
    }
  }
  if (need_gradient && !c->have_jacobians) {
    if (!c->point.ok) {
      c->d_terms.setZero(c->study->layout().num_objective_terms(), c->n);
      c->d_rows.setZero(c->study->layout().num_constraints(), c->n);
    } else {
      if (c->study->analyses() + c->n > c->cap) {
        c->cap_reached = true;
        Stop(c);
        return false;
      }
      const absl::Status s = c->study->Jacobians(x, c->point, &c->d_terms, &c->d_rows);
      if (!s.ok()) {
        c->error = s;
        Stop(c);
        return false;
      }
    }
    c->have_jacobians = true;
  }
  return true;
}

double Objective(unsigned n_all, const double* v, double* grad, void* data) {
  auto* c = static_cast<PeerContext*>(data);
  if (c->min_max) {
    // f = b: no analysis needed.
    if (grad != nullptr) {
      for (unsigned j = 0; j < n_all; ++j) grad[j] = 0;
      grad[n_all - 1] = 1;
    }
    return v[n_all - 1];
  }
  if (!Ensure(c, v, grad != nullptr)) return 0;
  if (grad != nullptr) {
    for (int j = 0; j < c->n; ++j) grad[j] = c->d_terms(0, j) / c->objective_scale;
  }
  return c->point.ok ? c->point.terms[0] / c->objective_scale : kFailedValue;
}

void Constraints(unsigned m, double* result, unsigned n_all, const double* v, double* grad,
                 void* data) {
  auto* c = static_cast<PeerContext*>(data);
  if (!Ensure(c, v, grad != nullptr)) {
    for (unsigned i = 0; i < m; ++i) result[i] = 0;
    return;
  }
  const int terms = c->min_max ? static_cast<int>(c->study->layout().num_objective_terms()) : 0;
  const int rows = c->study->layout().num_constraints();
  const double b = c->min_max ? v[n_all - 1] : 0;
  for (int i = 0; i < terms; ++i) {
    result[i] = c->point.ok ? c->point.terms[i] / c->objective_scale - b : kFailedValue;
  }
  for (int h = 0; h < rows; ++h) {
    result[terms + h] = c->point.ok ? c->point.normalized[h] : kFailedValue;
  }
  if (grad == nullptr) return;
  for (int i = 0; i < terms; ++i) {
    double* g = grad + static_cast<size_t>(i) * n_all;
    for (int j = 0; j < c->n; ++j) g[j] = c->d_terms(i, j) / c->objective_scale;
    g[n_all - 1] = -1;
  }
  for (int h = 0; h < rows; ++h) {
    double* g = grad + static_cast<size_t>(terms + h) * n_all;
    for (int j = 0; j < c->n; ++j) g[j] = c->d_rows(h, j);
    if (c->min_max) g[n_all - 1] = 0;
  }
}

}  // namespace

const char* PeerAlgorithmName(PeerAlgorithm algorithm) {
  return algorithm == PeerAlgorithm::kSlsqp ? "NLopt SLSQP" : "NLopt MMA";
}

absl::StatusOr<MethodRun> RunNloptPeer(const spec::Study& study, PeerAlgorithm algorithm,
                                       const slp::SlpOptions& fd_options,
                                       const PeerOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(study));
  CountedStudy counted(study, std::move(layout), fd_options);
  MethodRun run;
  run.method = PeerAlgorithmName(algorithm);
  run.study = study.name;

  PeerContext c;
  c.study = &counted;
  c.run = &run;
  c.cap = options.max_analyses;
  c.n = static_cast<int>(study.variables.size());
  c.min_max = counted.layout().objective_form == spec::ObjectiveForm::kMinMax;

  // F(x0) sets the objective's scale (and b's start).
  const Eigen::VectorXd x0 = counted.initial();
  MBOPT_ASSIGN_OR_RETURN(CountedStudy::Point p0, counted.Evaluate(x0));
  if (!p0.ok) return absl::FailedPreconditionError(absl::StrCat(study.name, ": initial design fails: ", p0.failure_reason));
  c.objective_scale = std::abs(p0.objective) > 0 ? std::abs(p0.objective) : 1.0;
  c.x = x0;
  c.point = p0;
  const Candidate first{counted.analyses(), p0.objective, p0.max_violation};
  run.candidates.push_back(first);
  c.visited.emplace_back(x0, first);

  const int n_all = c.n + (c.min_max ? 1 : 0);
  const int m = counted.layout().num_constraints() +
                (c.min_max ? counted.layout().num_objective_terms() : 0);
  nlopt_opt opt = nlopt_create(algorithm == PeerAlgorithm::kSlsqp ? NLOPT_LD_SLSQP : NLOPT_LD_MMA,
                               static_cast<unsigned>(n_all));
  if (opt == nullptr) return absl::InternalError("nlopt_create failed");
  c.opt = opt;
  std::vector<double> lb(n_all), ub(n_all), v(n_all);
  for (int j = 0; j < c.n; ++j) {
    lb[j] = study.variables[j].lower;
    ub[j] = study.variables[j].upper;
    v[j] = x0[j];
  }
  if (c.min_max) {
    // b = beta / |F0| starts at F0 / |F0| = +-1; a wide finite box (MMA
    // needs finite bounds for its asymptotes).
    lb[c.n] = -10;
    ub[c.n] = 10;
    v[c.n] = p0.objective / c.objective_scale;
  }
  std::vector<double> tol(m, options.constraint_tolerance);
  const bool set_ok = nlopt_set_lower_bounds(opt, lb.data()) == NLOPT_SUCCESS &&
                      nlopt_set_upper_bounds(opt, ub.data()) == NLOPT_SUCCESS &&
                      nlopt_set_min_objective(opt, Objective, &c) == NLOPT_SUCCESS &&
                      (m == 0 || nlopt_add_inequality_mconstraint(opt, static_cast<unsigned>(m), Constraints,
                                                                  &c, tol.data()) == NLOPT_SUCCESS) &&
                      nlopt_set_ftol_rel(opt, options.ftol_rel) == NLOPT_SUCCESS &&
                      nlopt_set_xtol_rel(opt, options.xtol_rel) == NLOPT_SUCCESS &&
                      // The study's objective_target is NLopt's stopval: the
                      // same "good enough" for every method.
                      (!fd_options.objective_target.has_value() ||
                       nlopt_set_stopval(opt, *fd_options.objective_target / c.objective_scale) == NLOPT_SUCCESS);
  if (!set_ok) {
    nlopt_destroy(opt);
    return absl::InternalError("configuring NLopt failed");
  }
  double f_opt = 0;
  const nlopt_result result = nlopt_optimize(opt, v.data(), &f_opt);
  nlopt_destroy(opt);
  if (!c.error.ok()) return c.error;

  run.end = c.cap_reached ? absl::StrCat("cap (", options.max_analyses, " analyses)")
                          : std::string(nlopt_result_to_string(result));
  // NLopt's answer: the design it returned, as analysed during the run.
  const Eigen::VectorXd x_final = Eigen::Map<const Eigen::VectorXd>(v.data(), c.n);
  std::optional<Candidate> final_values;
  for (const auto& [x, cand] : c.visited) {
    if (x == x_final) final_values = cand;
  }
  if (!final_values.has_value()) {
    // Not among the analysed points (should not happen): analyse it once more,
    // outside the count.
    MBOPT_ASSIGN_OR_RETURN(CountedStudy::Point pf, counted.Evaluate(x_final));
    final_values = Candidate{counted.analyses() - 1, pf.ok ? pf.objective : NAN,
                             pf.ok ? pf.max_violation : NAN};
    run.end += " (final design re-analysed)";
    run.analyses = counted.analyses() - 1;
  } else {
    run.analyses = counted.analyses();
  }
  run.final_objective = final_values->objective;
  run.final_max_violation = final_values->max_violation;
  run.failed_analyses = counted.failed();
  run.num_variables = c.n;
  run.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace mbopt::compare
