// Analytic test problems with published optima, as evaluators for the SLP
// core. Hock & Schittkowski, "Test Examples for Nonlinear Programming Codes",
// Lecture Notes in Economics and Mathematical Systems 187, Springer 1981
// (HS nn below); CB2 from Luksan & Vlcek, "Test problems for nonsmooth
// unconstrained and linearly constrained optimization", TR 798, ICS Prague
// 2000 (problem 2.5). Bounds that the original problems lack are wide and
// inactive at the optimum (noted per problem).
#pragma once

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "server/slp/problem.h"
#include "tests/slp_testing/drive_optimizer.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::slp::testing {

struct TestProblem {
  std::string name;
  ProblemSpec spec;
  double optimum_objective = 0;      // published
  Eigen::VectorXd optimum_design;    // published (scaled like spec)
  // objective terms, constraint values (g_h, compared with c_h)
  std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd* terms,
                     Eigen::VectorXd* constraints)>
      evaluate;
};

inline ProblemSpec MakeSpec(std::vector<double> lower, std::vector<double> upper,
                            std::vector<double> initial, std::vector<double> limits,
                            std::vector<double> scales) {
  ProblemSpec s;
  const int n = static_cast<int>(lower.size());
  s.lower = Eigen::Map<Eigen::VectorXd>(lower.data(), n);
  s.upper = Eigen::Map<Eigen::VectorXd>(upper.data(), n);
  s.initial = Eigen::Map<Eigen::VectorXd>(initial.data(), n);
  for (int i = 0; i < n; ++i) s.variable_names.push_back("x" + std::to_string(i + 1));
  const int m = static_cast<int>(limits.size());
  s.constraint_limits = Eigen::Map<Eigen::VectorXd>(limits.data(), m);
  s.constraint_scales = Eigen::Map<Eigen::VectorXd>(scales.data(), m);
  for (int h = 0; h < m; ++h) s.constraint_names.push_back("g" + std::to_string(h + 1));
  return s;
}

// HS 21: min 0.01 x1^2 + x2^2 - 100 s.t. 10 x1 - x2 >= 10, 2 <= x1 <= 50,
// -50 <= x2 <= 50. Optimum x = (2, 0), F = -99.96. The published start
// (-1, -1) is outside the bounds; we start at (10, 10).
inline TestProblem Hs21(std::vector<double> initial = {10.0, 10.0}) {
  TestProblem p;
  p.name = "HS21";
  // g = -10 x1 + x2 + 10 <= 0; c = 0, so the scale is the gradient's size.
  p.spec = MakeSpec({2, -50}, {50, 50}, initial, {0.0}, {10.0});
  p.optimum_objective = -99.96;
  p.optimum_design = Eigen::Vector2d(2.0, 0.0);
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    *f = Eigen::VectorXd::Constant(1, 0.01 * x[0] * x[0] + x[1] * x[1] - 100.0);
    *g = Eigen::VectorXd::Constant(1, -10.0 * x[0] + x[1] + 10.0);
  };
  return p;
}

// HS 35: min 9 - 8x1 - 6x2 - 4x3 + 2x1^2 + 2x2^2 + x3^2 + 2x1x2 + 2x1x3
// s.t. x1 + x2 + 2x3 <= 3, x >= 0. Optimum (4/3, 7/9, 4/9), F = 1/9.
// Upper bounds 3 are implied by the constraint.
inline TestProblem Hs35() {
  TestProblem p;
  p.name = "HS35";
  p.spec = MakeSpec({0, 0, 0}, {3, 3, 3}, {0.5, 0.5, 0.5}, {3.0}, {3.0});
  p.optimum_objective = 1.0 / 9.0;
  p.optimum_design = Eigen::Vector3d(4.0 / 3.0, 7.0 / 9.0, 4.0 / 9.0);
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    *f = Eigen::VectorXd::Constant(
        1, 9 - 8 * x[0] - 6 * x[1] - 4 * x[2] + 2 * x[0] * x[0] + 2 * x[1] * x[1] +
               x[2] * x[2] + 2 * x[0] * x[1] + 2 * x[0] * x[2]);
    *g = Eigen::VectorXd::Constant(1, x[0] + x[1] + 2 * x[2]);
  };
  return p;
}

// HS 35 badly scaled: the core's variables are y = (1e3 x1, 1e-3 x2, x3), the
// objective is multiplied by 1e4 and the constraint by 1e-5. Same optimum.
inline TestProblem Hs35BadlyScaled() {
  TestProblem p = Hs35();
  p.name = "HS35-badly-scaled";
  const Eigen::Vector3d s(1e3, 1e-3, 1.0);
  p.spec.lower = Eigen::Vector3d::Zero();
  p.spec.upper = 3.0 * s;
  p.spec.initial = 0.5 * s;
  p.spec.constraint_limits[0] = 3e-5;
  p.spec.constraint_scales[0] = 3e-5;
  p.optimum_objective = 1e4 / 9.0;
  p.optimum_design = p.optimum_design.cwiseProduct(s);
  auto base = Hs35().evaluate;
  p.evaluate = [base, s](const Eigen::VectorXd& y, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    base(y.cwiseQuotient(s), f, g);
    *f *= 1e4;
    *g *= 1e-5;
  };
  return p;
}

// HS 43 (Rosen-Suzuki): min x1^2 + x2^2 + 2x3^2 + x4^2 - 5x1 - 5x2 - 21x3 + 7x4
// s.t. three quadratic constraints. Optimum (0, 1, 2, -1), F = -44, two
// constraints active. Bounds [-10, 10] are ours.
inline TestProblem Hs43() {
  TestProblem p;
  p.name = "HS43";
  p.spec = MakeSpec({-10, -10, -10, -10}, {10, 10, 10, 10}, {0, 0, 0, 0}, {8, 10, 5},
                    {8, 10, 5});
  p.optimum_objective = -44.0;
  p.optimum_design = Eigen::Vector4d(0, 1, 2, -1);
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    const double x1 = x[0], x2 = x[1], x3 = x[2], x4 = x[3];
    *f = Eigen::VectorXd::Constant(1, x1 * x1 + x2 * x2 + 2 * x3 * x3 + x4 * x4 - 5 * x1 -
                                          5 * x2 - 21 * x3 + 7 * x4);
    g->resize(3);
    (*g)[0] = x1 * x1 + x2 * x2 + x3 * x3 + x4 * x4 + x1 - x2 + x3 - x4;
    (*g)[1] = x1 * x1 + 2 * x2 * x2 + x3 * x3 + 2 * x4 * x4 - x1 - x4;
    (*g)[2] = 2 * x1 * x1 + x2 * x2 + x3 * x3 + 2 * x1 - x2 - x4;
  };
  return p;
}

// HS 76: min x1^2 + 0.5x2^2 + x3^2 + 0.5x4^2 - x1x3 + x3x4 - x1 - 3x2 + x3 - x4
// s.t. x1 + 2x2 + x3 + x4 <= 5, 3x1 + x2 + 2x3 - x4 <= 4, x2 + 4x3 >= 1.5,
// x >= 0. Optimum (0.2727273, 2.090909, 0, 0.5454545), F = -4.681818181
// (= -103/22). Upper bounds 5 are ours (implied by the first constraint).
inline TestProblem Hs76(std::vector<double> initial = {0.5, 0.5, 0.5, 0.5}) {
  TestProblem p;
  p.name = "HS76";
  p.spec = MakeSpec({0, 0, 0, 0}, {5, 5, 5, 5}, initial, {5, 4, -1.5}, {5, 4, 1.5});
  p.optimum_objective = -103.0 / 22.0;
  p.optimum_design = Eigen::Vector4d(3.0 / 11.0, 23.0 / 11.0, 0.0, 6.0 / 11.0);
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    const double x1 = x[0], x2 = x[1], x3 = x[2], x4 = x[3];
    *f = Eigen::VectorXd::Constant(1, x1 * x1 + 0.5 * x2 * x2 + x3 * x3 + 0.5 * x4 * x4 -
                                          x1 * x3 + x3 * x4 - x1 - 3 * x2 + x3 - x4);
    g->resize(3);
    (*g)[0] = x1 + 2 * x2 + x3 + x4;
    (*g)[1] = 3 * x1 + x2 + 2 * x3 - x4;
    (*g)[2] = -x2 - 4 * x3;
  };
  return p;
}

// HS 100: 7 variables, 4 nonlinear inequality constraints. Optimum
// F = 680.6300573 at (2.330499, 1.951372, -0.4775414, 4.365726, -0.6244870,
// 1.038131, 1.594227). Bounds [-10, 10] are ours.
inline TestProblem Hs100() {
  TestProblem p;
  p.name = "HS100";
  p.spec = MakeSpec(std::vector<double>(7, -10.0), std::vector<double>(7, 10.0),
                    {1, 2, 0, 4, 0, 1, 1}, {127, 282, 196, 0}, {127, 282, 196, 100});
  p.optimum_objective = 680.6300573;
  Eigen::VectorXd xs(7);
  xs << 2.330499, 1.951372, -0.4775414, 4.365726, -0.6244870, 1.038131, 1.594227;
  p.optimum_design = xs;
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    const double x1 = x[0], x2 = x[1], x3 = x[2], x4 = x[3], x5 = x[4], x6 = x[5], x7 = x[6];
    *f = Eigen::VectorXd::Constant(
        1, std::pow(x1 - 10, 2) + 5 * std::pow(x2 - 12, 2) + std::pow(x3, 4) +
               3 * std::pow(x4 - 11, 2) + 10 * std::pow(x5, 6) + 7 * x6 * x6 + std::pow(x7, 4) -
               4 * x6 * x7 - 10 * x6 - 8 * x7);
    g->resize(4);
    // HS writes them as >= 0; here as g_h <= c_h.
    (*g)[0] = 2 * x1 * x1 + 3 * std::pow(x2, 4) + x3 + 4 * x4 * x4 + 5 * x5;
    (*g)[1] = 7 * x1 + 3 * x2 + 10 * x3 * x3 + x4 - x5;
    (*g)[2] = 23 * x1 + x2 * x2 + 6 * x6 * x6 - 8 * x7;
    (*g)[3] = 4 * x1 * x1 + x2 * x2 - 3 * x1 * x2 + 2 * x3 * x3 + 5 * x6 - 11 * x7;
  };
  return p;
}

// CB2 (Charalambous & Bandler), min-max: F = max(x1^2 + x2^4,
// (2 - x1)^2 + (2 - x2)^2, 2 exp(x2 - x1)). Optimum F = 1.9522245 at
// (1.139286, 0.899365). Start (2, 2); bounds [-5, 5] are ours.
inline TestProblem Cb2() {
  TestProblem p;
  p.name = "CB2";
  p.spec = MakeSpec({-5, -5}, {5, 5}, {2, 2}, {}, {});
  p.spec.objective_form = ObjectiveForm::kMinMax;
  p.spec.num_objective_terms = 3;
  p.optimum_objective = 1.9522245;
  p.optimum_design = Eigen::Vector2d(1.139286, 0.899365);
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    f->resize(3);
    (*f)[0] = x[0] * x[0] + std::pow(x[1], 4);
    (*f)[1] = std::pow(2 - x[0], 2) + std::pow(2 - x[1], 2);
    (*f)[2] = 2 * std::exp(x[1] - x[0]);
    g->resize(0);
  };
  return p;
}

// Best uniform (Chebyshev) linear approximation of e^t on [0, 1], as a
// min-max over a 101-point time grid like the report's: F = max_i |e^t_i -
// x1 - x2 t_i| (each |.| is two terms: 202 rows, so the LP is tall). The
// continuous optimum equioscillates at 0, t* = ln(e - 1) and 1: x2 = e - 1,
// x1 = (e - (e - 1) t*) / 2, F = 1 - x1 = 0.1059334... The grid misses t* by
// 1.3e-3, which lowers the discrete optimum by O(1e-6) relative.
inline TestProblem ChebyshevExp() {
  TestProblem p;
  p.name = "Chebyshev-exp";
  p.spec = MakeSpec({-5, -5}, {5, 5}, {0.5, 0.5}, {}, {});
  p.spec.objective_form = ObjectiveForm::kMinMax;
  p.spec.num_objective_terms = 202;
  const double e = std::exp(1.0);
  const double t_star = std::log(e - 1.0);
  const double x1 = (e - (e - 1.0) * t_star) / 2.0;
  p.optimum_objective = 1.0 - x1;
  p.optimum_design = Eigen::Vector2d(x1, e - 1.0);
  p.evaluate = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    f->resize(202);
    for (int i = 0; i <= 100; ++i) {
      const double t = i / 100.0;
      const double r = std::exp(t) - x[0] - x[1] * t;
      (*f)[2 * i] = r;
      (*f)[2 * i + 1] = -r;
    }
    g->resize(0);
  };
  return p;
}

inline Evaluator MakeEvaluator(const TestProblem& p) {
  auto eval = p.evaluate;
  return [eval](const AnalysisRequest& req) {
    AnalysisResult r;
    r.outcome = AnalysisOutcome::kOk;
    eval(req.x, &r.objective_terms, &r.constraint_values);
    return r;
  };
}

}  // namespace mbopt::slp::testing
