// Forward dynamics of the multibody engine (docs/benchmarks.md, issue 30):
//
//   BM_TenBodyChain/<solver>   the ten-body mechanism with closed loops of
//                              tests/multibody/mechanisms.h (the same model
//                              as Simbody's in tests/oracle), 2 s at rtol 1e-6
//   BM_RodChain/<rods>/<solver> a closed chain of 4 to 40 rods between
//                              two ground pins, 2 s at rtol 1e-6 (ten rods:
//                              the chain of issue 30; the longer ones find
//                              where KLU overtakes dense LU)
//   BM_StiffSprings/<solver>   two masses on a slide joined by springs of
//                              100 N/m and 1e8 N/m (a stiffness ratio of 1e6)
//   BM_CorotationalFourBar     one analysis of
//                              examples/fourbar/fourbar_corotational.scene.textproto
//                              at the report's optimum (run from the source tree)
//
// <solver>: 0 dense LU, 1 KLU, 2 the automatic choice (ForwardDynamicsOptions),
// 3 IDAS's difference quotients with dense LU (the engine before the
// analytic Newton matrix), 4 the explicit Runge-Kutta path with projection
// (explicit_dynamics.h; no linear solver of Newton systems).
// mbopt is timed by Google Benchmark (assembly included); Simbody by its own
// program (it cannot share a process with the engine), as the median of as
// many integrations of the ten-body mechanism. Prints the ratio at the end,
// against the automatic choice.
//
//   build/bench/multibody/bench_multibody --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace {

using namespace mbopt::multibody;

constexpr double kTolerance = 1e-6;
constexpr double kEndS = 2.0;
constexpr int kIntervals = 200;

std::vector<double> Times() {
  std::vector<double> t;
  for (int i = 0; i <= kIntervals; ++i) t.push_back(kEndS * i / kIntervals);
  return t;
}

// A system without analytic derivatives: IDAS forms the Newton matrix by
// difference quotients, one residual per unknown, and factors it densely
// (the engine before issue 30).
class DifferenceQuotients : public ConstrainedSystem {
 public:
  explicit DifferenceQuotients(const ConstrainedSystem& s) : s_(s) {}
  int num_coordinates() const override { return s_.num_coordinates(); }
  int num_constraints() const override { return s_.num_constraints(); }
  int MassMatrix(const Eigen::VectorXd& q, Eigen::MatrixXd* mass) const override { return s_.MassMatrix(q, mass); }
  int AppliedForces(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                    Eigen::VectorXd* forces) const override {
    return s_.AppliedForces(t, q, v, forces);
  }
  int Constraints(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi) const override {
    return s_.Constraints(t, q, phi);
  }
  int ConstraintJacobian(double t, const Eigen::VectorXd& q, Eigen::MatrixXd* phi_q) const override {
    return s_.ConstraintJacobian(t, q, phi_q);
  }
  int ConstraintTimeDerivative(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const override {
    return s_.ConstraintTimeDerivative(t, q, phi_t);
  }
  int AccelerationRightSide(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                            Eigen::VectorXd* gamma) const override {
    return s_.AccelerationRightSide(t, q, v, gamma);
  }
  void ContinuePastBounds(bool on) const override { s_.ContinuePastBounds(on); }
  double DefinedUntil_s() const override { return s_.DefinedUntil_s(); }

 private:
  const ConstrainedSystem& s_;
};

// 0 dense LU, 1 KLU, 2 automatic, 3 difference quotients with dense LU.
ForwardDynamicsOptions::LinearSolver SolverOf(int64_t arg) {
  return arg == 0 ? ForwardDynamicsOptions::LinearSolver::kDense
         : arg == 1 ? ForwardDynamicsOptions::LinearSolver::kSparse
                    : ForwardDynamicsOptions::LinearSolver::kAutomatic;
}

// Assembles and integrates `model` once per iteration; the wall time of each
// iteration goes to `seconds` when given.
void Integrate(benchmark::State& state, const Model& model, int64_t solver_arg, std::vector<double>* seconds) {
  const ForwardDynamicsOptions::LinearSolver solver = SolverOf(solver_arg);
  const std::vector<double> times = Times();
  ForwardDynamicsCounters counters;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Mechanism m(model);
    const Assembly assembled = Assemble(m, 0.0);
    ForwardDynamicsOptions options;
    options.relative_tolerance = kTolerance;
    options.absolute_tolerance = kTolerance;
    options.linear_solver = solver;
    if (solver_arg == 4) options.method = ForwardDynamicsOptions::Method::kExplicitRungeKutta;
    counters = ForwardDynamicsCounters{};
    const DifferenceQuotients without_derivatives(m);
    const ConstrainedSystem& system = solver_arg == 3 ? static_cast<const ConstrainedSystem&>(without_derivatives) : m;
    const mbopt::spec::AnalysisFailure f = IntegrateForward(
        system, 0.0, assembled.q, assembled.v, times, options,
        [](const MotionSample&) { return mbopt::spec::AnalysisFailure::Ok(); }, &counters);
    if (!f.ok()) state.SkipWithError(f.reason.c_str());
    if (seconds != nullptr) {
      seconds->push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  }
  state.counters["unknowns"] = 2.0 * (3.0 * static_cast<double>(model.bodies.size())) +
                               2.0 * static_cast<double>(Mechanism(model).num_constraints());
  state.counters["steps"] = static_cast<double>(counters.steps);
  state.counters["residuals"] =
      static_cast<double>(counters.residual_evaluations + counters.jacobian_residual_evaluations);
  state.counters["jacobians"] = static_cast<double>(counters.jacobian_evaluations);
  state.counters["klu"] = counters.sparse_linear_solver ? 1.0 : 0.0;
  state.counters["newton_fails"] = static_cast<double>(counters.convergence_failures);
  state.counters["error_fails"] = static_cast<double>(counters.error_test_failures);
}

std::vector<double> g_mbopt_seconds;

void BM_TenBodyChain(benchmark::State& state) {
  Integrate(state, testing::TenBodyChain(), state.range(0), state.range(0) == 2 ? &g_mbopt_seconds : nullptr);
}
BENCHMARK(BM_TenBodyChain)->Arg(3)->Arg(0)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

void BM_RodChain(benchmark::State& state) {
  Integrate(state, testing::RodChain(static_cast<int>(state.range(0))), state.range(1), nullptr);
}
// Difference quotients only up to ten rods: at 40 one iteration takes
// minutes.
BENCHMARK(BM_RodChain)
    ->ArgsProduct({{4, 6, 10}, {3, 0, 1}})
    ->ArgsProduct({{20, 40}, {0, 1}})
    ->ArgsProduct({{4, 6, 10, 20, 40}, {4}})
    ->Unit(benchmark::kMillisecond);

// MultibodyHardcase.StiffnessRatioOfAMillion's model: two 1 kg masses in
// series on a slide, springs of 100 N/m and 1e8 N/m, 1 s from the soft
// spring stretched by 0.1 m (at the benchmark's tolerances, 1e-6).
Model StiffSprings() {
  Model m;
  for (int i = 0; i < 2; ++i) {
    Body b;
    b.name = i == 0 ? "heavy" : "light";
    b.mass_kg = 1.0;
    b.inertia_kg_m2 = 0.1;
    b.position_m = {1.0 + i * 0.1, 0.0};
    m.bodies.push_back(b);
    Joint slide;
    slide.name = "slide" + std::to_string(i);
    slide.kind = JointKind::kPrismatic;
    slide.b = testing::At(i, 0.0);
    m.joints.push_back(slide);
  }
  m.joints[0].initial_value = 1.1;
  m.joints[1].initial_value = 1.2;
  SpringDamper soft;
  soft.name = "soft";
  soft.b = testing::At(0, 0.0);
  soft.free_length_m = 1.0;
  soft.stiffness_n_per_m = 100.0;
  m.springs.push_back(soft);
  SpringDamper stiff;
  stiff.name = "stiff";
  stiff.a = testing::At(0, 0.0);
  stiff.b = testing::At(1, 0.0);
  stiff.free_length_m = 0.1;
  stiff.stiffness_n_per_m = 1e8;
  stiff.damping_n_s_per_m = 10.0;
  m.springs.push_back(stiff);
  return m;
}

void BM_StiffSprings(benchmark::State& state) { Integrate(state, StiffSprings(), state.range(0), nullptr); }
BENCHMARK(BM_StiffSprings)->Arg(3)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_CorotationalFourBar(benchmark::State& state) {
  absl::StatusOr<mbopt::spec::Scene> scene =
      mbopt::spec::io::LoadSceneFile("examples/fourbar/fourbar_corotational.scene.textproto");
  if (!scene.ok()) {
    state.SkipWithError("run from the source tree: examples/fourbar/fourbar_corotational.scene.textproto");
    return;
  }
  mbopt::spec::AnalysisReport report;
  for (auto _ : state) {
    report = AnalyzeMultibodyScene(*scene, {9.65e-4, 3.92e-4, 2.69e-4});
    if (!report.ok()) state.SkipWithError(report.failure.reason.c_str());
  }
  state.counters["steps"] = static_cast<double>(report.counters.time_steps);
  state.counters["jacobians"] = static_cast<double>(report.counters.jacobian_evaluations);
}
BENCHMARK(BM_CorotationalFourBar)->Unit(benchmark::kMillisecond);

double SimbodyMedianSeconds(int repeats) {
  const std::string command = std::string(MBOPT_SIMBODY_ORACLE) + " ten_body_chain " + std::to_string(kTolerance) +
                              " " + std::to_string(kEndS) + " " + std::to_string(kIntervals) + " " +
                              std::to_string(repeats);
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return -1.0;
  double seconds = -1.0;
  if (std::fscanf(pipe, "%lf", &seconds) != 1) seconds = -1.0;
  return pclose(pipe) == 0 ? seconds : -1.0;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (g_mbopt_seconds.empty()) return 0;
  std::sort(g_mbopt_seconds.begin(), g_mbopt_seconds.end());
  const double mbopt_median = g_mbopt_seconds[g_mbopt_seconds.size() / 2];
  const double simbody_median = SimbodyMedianSeconds(5);
  if (simbody_median <= 0.0) {
    std::printf("Simbody: the oracle program failed\n");
    return 1;
  }
  std::printf("ten-body chain, 2 s at rtol 1e-6: mbopt median %.3f ms over %zu runs, Simbody median %.3f ms over 5: "
              "Simbody / mbopt = %.2f\n",
              1e3 * mbopt_median, g_mbopt_seconds.size(), 1e3 * simbody_median, simbody_median / mbopt_median);
  return 0;
}
