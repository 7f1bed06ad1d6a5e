// Closed-form solutions of the test FMUs (tests/fmu/models), SI units.
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace mbopt::fmu::testing {

// m x'' + c x' + k x = 0, x(0) = x0, x'(0) = 0, underdamped (c^2 < 4 k m).
struct DampedOscillator {
  double mass_kg;
  double damping_n_s_per_m;
  double stiffness_n_per_m;
  double x0_m;

  double X(double t_s) const {
    const double natural = std::sqrt(stiffness_n_per_m / mass_kg);
    const double zeta = damping_n_s_per_m / (2.0 * std::sqrt(stiffness_n_per_m * mass_kg));
    const double damped = natural * std::sqrt(1.0 - zeta * zeta);
    return x0_m * std::exp(-zeta * natural * t_s) *
           (std::cos(damped * t_s) + zeta * natural / damped * std::sin(damped * t_s));
  }
};

// A ball dropped from h0 at rest: it lands at t1 = sqrt(2 h0 / g) with speed
// g t1, leaves the floor with e times the speed it hit it with, and each
// flight lasts 2 v / g.
struct BouncingBall {
  double h0_m;
  double g_m_per_s2;
  double e;

  std::vector<double> ImpactTimes(int count) const {
    std::vector<double> times;
    double t = std::sqrt(2.0 * h0_m / g_m_per_s2);
    double speed = g_m_per_s2 * t;
    for (int k = 0; k < count; ++k) {
      times.push_back(t);
      speed *= e;
      t += 2.0 * speed / g_m_per_s2;
    }
    return times;
  }

  double Height(double t_s) const {
    const double t1 = std::sqrt(2.0 * h0_m / g_m_per_s2);
    if (t_s <= t1) return h0_m - 0.5 * g_m_per_s2 * t_s * t_s;
    double impact = t1;
    double speed = e * g_m_per_s2 * t1;
    while (t_s > impact + 2.0 * speed / g_m_per_s2) {
      impact += 2.0 * speed / g_m_per_s2;
      speed *= e;
    }
    const double tau = t_s - impact;
    return speed * tau - 0.5 * g_m_per_s2 * tau * tau;
  }
};

// y' = (u - y) / tau, y(0) = 0, u = 0 before t_step and 1 after.
struct StepResponse {
  double tau_s;
  double t_step_s;
  double Y(double t_s) const { return t_s <= t_step_s ? 0.0 : 1.0 - std::exp(-(t_s - t_step_s) / tau_s); }
};

// The Van der Pol limit cycle for mu = 1 (x'' - (1 - x^2) x' + x = 0):
// amplitude and period as published to many digits (e.g. in the numerical
// ODE literature's reference solutions of this oscillator).
constexpr double kVanDerPolAmplitudeMu1 = 2.00861986087484;
constexpr double kVanDerPolPeriodMu1_s = 6.66328685933633;

inline std::string TestFmu(const std::string& name) { return std::string(MBOPT_TEST_FMU_DIR) + "/" + name + ".fmu"; }

inline std::vector<double> Grid(double start_s, double stop_s, int intervals) {
  std::vector<double> times;
  for (int i = 0; i <= intervals; ++i) times.push_back(start_s + (stop_s - start_s) * i / intervals);
  return times;
}

}  // namespace mbopt::fmu::testing
