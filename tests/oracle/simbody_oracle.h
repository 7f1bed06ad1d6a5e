// Simbody (the multibody engine under OpenSim, Debian libsimbody-dev) as an
// independent oracle for mbopt's multibody engine: the same planar mechanisms
// simulated by a relative-coordinate code with its own integrator. This
// header is plain C++ (no Simbody types) so that the C++20 tests include it;
// the implementation is the C++17 program mbopt_simbody_oracle (Simbody
// 3.7's headers do not compile as C++20, and its SimTKmath exports an old
// SUNDIALS' N_Vector symbols that would replace the engine's in one process).
//
// Conventions (shared with the mbopt models the tests build): planar motion
// in x, y; angles counter-clockwise from +x, in rad; gravity, when present,
// along -y; bars are uniform (inertia m L^2 / 12 about the centre of mass);
// every mechanism starts at rest. Each function returns the quantity named
// at `times_s` (ascending, from 0), integrated at the given accuracy.
#pragma once

#include <string>
#include <vector>

namespace mbopt::oracle {

struct OracleRun {
  bool ok = false;
  std::string error;                       // when !ok
  std::vector<std::vector<double>> values;  // [instant][quantity]
  // The integration alone (stepping and reading, not building the model):
  // process CPU time and Simbody's step count, for the work-precision
  // benchmark (bench/multibody).
  double cpu_seconds = 0.0;
  long steps = 0;
};

// Simbody's integrator for the runs that follow: "rkm" (Runge-Kutta-Merson,
// the default and what the comparison tests use) or "cpodes" (CPodes' BDF
// with Newton iterations, Simbody's implicit choice). Returns false for an
// unknown name.
bool UseIntegrator(const std::string& name);

// Two bars pinned in a chain at the origin (upper: mass m1, length l1;
// lower: m2, l2), released from absolute angles phi1, phi2 of their axes
// (pointing from the pin outwards). Values: phi1, phi2.
struct DoublePendulum {
  double m1 = 1.0, l1 = 1.0, m2 = 0.5, l2 = 0.7, g = 9.81;
  double phi1 = -0.5, phi2 = 0.2;
};
OracleRun SimulateDoublePendulum(const DoublePendulum& p, const std::vector<double>& times_s, double accuracy);

// A four-bar under gravity, no driver: ground pivots A = (0, 0) and
// D = (d, 0); crank AB (m_a, a), coupler BC (m_b, b), rocker DC (m_c, c),
// each a bar from its first joint to its second; assembled with the crank
// at angle theta (the coupler and rocker above the ground line) and
// released at rest. Values: the crank's angle.
struct FourBar {
  double d = 1.0, a = 0.3, b = 1.1, c = 0.8;
  double m_a = 1.0, m_b = 2.0, m_c = 1.5, g = 9.81;
  double theta = 1.2;
};
OracleRun SimulateFourBar(const FourBar& p, const std::vector<double>& times_s, double accuracy);

// A slider-crank without gravity: a crank (mass m_crank, inertia j_crank
// about its pivot at the origin, which is its centre of mass: a flywheel)
// of radius r; a uniform rod (m_rod, l) from the crank pin to a slider (m_s)
// on the x axis; a constant force f_x along x on the slider. Assembled with
// the crank at angle theta (slider on +x) and released at rest. Values: the
// crank's angle and the slider's x.
struct SliderCrank {
  double r = 0.2, l = 0.7, m_crank = 5.0, j_crank = 0.5, m_rod = 2.0, m_s = 3.0, f_x = -50.0;
  double theta = 1.0;
};
OracleRun SimulateSliderCrank(const SliderCrank& p, const std::vector<double>& times_s, double accuracy);

// Ten bodies with closed loops, for the speed benchmark: five rockers
// (uniform bars, 1 kg, length 1 m) hang from ground pivots at x = 0, 1, ..., 4
// and swing at the same angle; four couplers (uniform bars, 1 kg, 1 m) join
// the rockers' lower ends (a chain of four parallelograms: one degree of
// freedom); a free pendulum (uniform bar, 0.5 kg, 0.6 m) hangs from the last
// rocker's lower end. Released at rest with the rockers at angle theta
// (from +x; -pi/2 hangs down) and the pendulum at angle pendulum_angle, under
// gravity. Values: the first rocker's and the pendulum's angles. Also
// returns, in wall_seconds, the time of the integration alone (no model
// building), which is what the benchmark compares.
struct TenBodyChain {
  double theta = -1.2, pendulum_angle = -2.0, g = 9.81;
};
OracleRun SimulateTenBodyChain(const TenBodyChain& p, const std::vector<double>& times_s, double accuracy,
                               double* wall_seconds);

// A closed chain of `rods` uniform rods (1 kg, 1 m) between ground pins at
// (0, 0) and (rods - 2, 0): the first two rods start 60 degrees below the
// horizontal, the last two 60 degrees above it, the rest horizontal (a
// closed start), released at rest under gravity (tests/multibody's
// RodChain). Values: each rod's absolute angle.
OracleRun SimulateRodChain(int rods, const std::vector<double>& times_s, double accuracy);

// Andrews' squeezing mechanism (Hairer and Wanner, the Test Set for IVP
// solvers; examples/andrews has the same model as an mbopt scene): seven
// bodies, constant drive torque, a spring, no gravity, from the published
// consistent initial angles at rest. Values: the seven published angles
// beta, Theta, gamma, Phi, delta, Omega, epsilon (rad).
OracleRun SimulateAndrews(const std::vector<double>& times_s, double accuracy);

}  // namespace mbopt::oracle
