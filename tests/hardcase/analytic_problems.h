// Analytic problems for the hard-case suite, as evaluators for the SLP core:
// each has a closed-form or published optimum, so a hard case can check that
// the method still finds it.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "server/slp/problem.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::hardcase {

// Values of one design: objective terms and constraint values g_h.
using Values = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd* terms, Eigen::VectorXd* g)>;

inline slp::ProblemSpec MakeSpec(const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                                 const Eigen::VectorXd& initial, const Eigen::VectorXd& limits,
                                 const Eigen::VectorXd& scales) {
  slp::ProblemSpec s;
  s.lower = lower;
  s.upper = upper;
  s.initial = initial;
  // Names built by appending: GCC 12 warns (-Wrestrict, falsely) on "x" + std::string at -O3.
  for (int i = 0; i < lower.size(); ++i) s.variable_names.push_back(std::string("x").append(std::to_string(i + 1)));
  s.constraint_limits = limits;
  s.constraint_scales = scales;
  for (int h = 0; h < limits.size(); ++h) s.constraint_names.push_back(std::string("g").append(std::to_string(h + 1)));
  return s;
}

// The evaluator of RunToCompletion for `values`: kOk with what it computes.
inline slp::AnalysisResult Evaluate(const Values& values, const slp::AnalysisRequest& request) {
  slp::AnalysisResult r;
  values(request.x, &r.objective_terms, &r.constraint_values);
  return r;
}

// HS 43 (Rosen-Suzuki; Hock & Schittkowski, Lecture Notes in Economics and
// Mathematical Systems 187, 1981) in variables u: min u1^2 + u2^2 + 2u3^2 +
// u4^2 - 5u1 - 5u2 - 21u3 + 7u4 s.t. three quadratic constraints. Optimum
// u = (0, 1, 2, -1), F = -44, two constraints active.
inline void Hs43(const Eigen::VectorXd& u, Eigen::VectorXd* f, Eigen::VectorXd* g) {
  const double u1 = u[0], u2 = u[1], u3 = u[2], u4 = u[3];
  *f = Eigen::VectorXd::Constant(
      1, u1 * u1 + u2 * u2 + 2 * u3 * u3 + u4 * u4 - 5 * u1 - 5 * u2 - 21 * u3 + 7 * u4);
  g->resize(3);
  (*g)[0] = u1 * u1 + u2 * u2 + u3 * u3 + u4 * u4 + u1 - u2 + u3 - u4;
  (*g)[1] = u1 * u1 + 2 * u2 * u2 + u3 * u3 + 2 * u4 * u4 - u1 - u4;
  (*g)[2] = 2 * u1 * u1 + u2 * u2 + u3 * u3 + 2 * u1 - u2 - u4;
}
inline constexpr double kHs43Optimum = -44.0;
inline Eigen::Vector4d Hs43OptimumDesign() { return {0.0, 1.0, 2.0, -1.0}; }
inline Eigen::Vector3d Hs43Limits() { return {8.0, 10.0, 5.0}; }

// A deterministic pseudo-random choice keyed on the bits of a design point
// and a seed (FNV-1a over the bytes): the same design always gets the same
// answer, whatever the order of the requests.
inline std::uint64_t DesignHash(const Eigen::VectorXd& x, std::uint64_t seed) {
  std::uint64_t h = 1469598103934665603ull ^ seed;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    unsigned char bytes[sizeof(double)];
    const double v = x[i];
    std::memcpy(bytes, &v, sizeof v);
    for (unsigned char b : bytes) {
      h ^= b;
      h *= 1099511628211ull;
    }
  }
  // Final avalanche (splitmix64's) so that the low digits are well mixed.
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebull;
  h ^= h >> 31;
  return h;
}

}  // namespace mbopt::hardcase
