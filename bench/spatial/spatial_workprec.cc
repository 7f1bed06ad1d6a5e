// Work-precision of the spatial engine against Simbody (issue 31,
// docs/benchmarks.md): the ten-bar chain on spherical joints closed back to
// ground (tests/spatial/spatial_mechanisms.h, SphericalChain) falls for 2 s
// and both codes integrate it at a range of tolerances. Each run's error is
// the largest difference of the bars' centres of mass (m) and rotation
// matrix entries at 20 output instants from a tight reference of the same
// code (tolerance 1e-12); the two references are compared with each other.
// A run's cost is the median CPU time of the integration alone over the
// repeats. The time ratio at equal error is read off Simbody's curve by
// linear interpolation in log-log.
//
// mbopt runs in this process (IDAS, rtol = atol = tolerance, the bars
// being 1 m), with the Newton matrix the system provides and, when that is
// analytic, also with IDAS's difference quotients of the residual (the
// curve "idas-dq": what the engine did before), so both are measured in
// the same run, and on the explicit path (curve "erk": ARKODE's Verner
// 6(5) pair on the index-1 form, projected onto the joints' and the Euler
// parameters' norm rows after every step). Simbody runs as the program mbopt_simbody_spatial_oracle
// (tests/spatial) with Runge-Kutta-Merson (its default) and CPodes' BDF,
// accuracy = tolerance.
//
//   build/bench/spatial/bench_spatial_workprec [--repeats=5] [--out=spatial_workprec.csv]
//
// Writes one CSV row per run and the ratios to OUT's name with _ratios
// before .csv, and prints both.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/spatial/workprec_support.h"
#include "tests/spatial/mechanism_model.h"
#include "tests/spatial/spatial_mechanisms.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_system.h"

namespace {

using namespace mbopt;
using bench::CpuSeconds;
using bench::Median;
using Values = std::vector<std::vector<double>>;  // [instant][value]

constexpr double kEnd_s = 2.0;
constexpr int kIntervals = 20;
constexpr double kReferenceTolerance = 1e-12;
// CPodes is slower than Runge-Kutta-Merson wherever both were tried on the
// planar chains (bench/multibody/workprec_bench.cc); not run tighter.
constexpr double kCpodesTightest = 1e-8;

struct Run {
  std::string code, integrator;
  double tolerance = 0.0;
  bool ok = false;
  std::string failure;
  Values values;
  double cpu_s = 0.0;
  long steps = 0;
  multibody::ForwardDynamicsCounters counters;  // mbopt's only
  double error = NAN;
};

// A system's equations with its analytic derivatives hidden: IDAS then
// forms the Newton matrix by difference quotients of the residual.
class DifferenceQuotientNewton : public multibody::ConstrainedSystem {
 public:
  explicit DifferenceQuotientNewton(const multibody::ConstrainedSystem& s) : s_(s) {}
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

 private:
  const multibody::ConstrainedSystem& s_;
};

std::vector<double> Times() {
  std::vector<double> t;
  for (int i = 0; i <= kIntervals; ++i) t.push_back(kEnd_s * i / kIntervals);
  return t;
}

// `integrator`: "idas", "idas-dq" (IDAS with difference-quotient Newton
// matrices) or "erk" (the explicit path, Verner 6(5) with projection).
Run RunMbopt(const spatial::SpatialSystem& system, const std::string& integrator, double tolerance, int repeats) {
  const bool difference_quotients = integrator == "idas-dq";
  Run run;
  run.code = "mbopt";
  run.integrator = integrator;
  run.tolerance = tolerance;
  const spatial::SpatialAssembly assembled = spatial::AssembleSpatial(system, 0.0);
  if (!assembled.failure.ok()) {
    run.failure = assembled.failure.reason;
    return run;
  }
  const DifferenceQuotientNewton hidden(system);
  const multibody::ConstrainedSystem& integrated =
      difference_quotients ? static_cast<const multibody::ConstrainedSystem&>(hidden) : system;
  multibody::ForwardDynamicsOptions options;
  options.relative_tolerance = tolerance;
  options.absolute_tolerance = tolerance;  // the bars are 1 m
  if (integrator == "erk") options.method = multibody::ForwardDynamicsOptions::Method::kExplicitRungeKutta;
  const int bodies = static_cast<int>(system.model().bodies.size());
  std::vector<double> cpu;
  for (int r = 0; r < repeats; ++r) {
    run.values.clear();
    run.counters = multibody::ForwardDynamicsCounters{};
    const double start = CpuSeconds();
    const spec::AnalysisFailure f = multibody::IntegrateForward(
        integrated, 0.0, assembled.q, assembled.v, Times(), options,
        [&](const multibody::MotionSample& s) {
          std::vector<double> row;
          for (int b = 0; b < bodies; ++b) {
            for (int k = 0; k < 3; ++k) row.push_back(s.q[7 * b + k]);
            const Eigen::Matrix3d rotation = system.BodyRotation(b, s.q);
            for (int i = 0; i < 3; ++i) {
              for (int k = 0; k < 3; ++k) row.push_back(rotation(i, k));
            }
          }
          run.values.push_back(std::move(row));
          return spec::AnalysisFailure::Ok();
        },
        &run.counters);
    cpu.push_back(CpuSeconds() - start);
    if (!f.ok()) {
      run.failure = f.reason;
      return run;
    }
  }
  run.ok = true;
  run.cpu_s = Median(cpu);
  run.steps = static_cast<long>(run.counters.steps);
  return run;
}

Run RunSimbody(const std::string& integrator, double tolerance, int repeats) {
  Run run;
  run.code = "simbody";
  run.integrator = integrator;
  run.tolerance = tolerance;
  char accuracy[32];
  std::snprintf(accuracy, sizeof accuracy, "%.17g", tolerance);
  const std::string command = std::string(MBOPT_SIMBODY_SPATIAL_ORACLE) + " --integrator=" + integrator +
                              " --cpu=" + std::to_string(repeats) + " spherical_chain " + accuracy + " " +
                              std::to_string(kEnd_s) + " " + std::to_string(kIntervals) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    run.failure = "cannot start " + command;
    return run;
  }
  char line[16384];
  std::string unparsed;
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    if (line[0] == '#') {
      std::istringstream in(line + 1);
      in >> run.cpu_s >> run.steps;
      continue;
    }
    std::istringstream in(line);
    double t = 0.0, v = 0.0;
    if (!(in >> t)) {
      unparsed += line;
      continue;
    }
    std::vector<double> values;
    while (in >> v) values.push_back(v);
    run.values.push_back(std::move(values));
  }
  run.ok = pclose(pipe) == 0 && static_cast<int>(run.values.size()) == kIntervals + 1;
  if (!run.ok) run.failure = unparsed.empty() ? command + " failed" : unparsed;
  return run;
}

// The largest difference over instants and values (NaN when either run
// failed or their shapes differ).
double LargestDifference(const Values& a, const Values& b) {
  if (a.size() != b.size() || a.empty()) return NAN;
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].size() != b[i].size()) return NAN;
    for (size_t k = 0; k < a[i].size(); ++k) worst = std::max(worst, std::abs(a[i][k] - b[i][k]));
  }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  std::string out = "spatial_workprec.csv";
  if (!bench::ParseRepeatsAndOut(argc, argv, &repeats, &out)) return 2;
  std::ofstream csv(out);
  if (!csv) {
    std::cerr << "cannot write " << out << "\n";
    return 1;
  }
  csv << "code,integrator,tolerance,error,cpu_s,steps,newton_iterations,jacobians,residuals,error_test_failures,"
         "newton_failures,failure\n";
  const std::string ratios_path = out.substr(0, out.rfind(".csv")) + "_ratios.csv";
  std::ofstream ratios(ratios_path);
  ratios << "integrator,mbopt_tolerance,error,mbopt_cpu_s,ratio_to_rkm,ratio_to_cpodes,ratio_to_fastest\n";

  const spatial::Model model = spatial::ModelOf(oracle::SphericalChain());
  const spatial::SpatialSystem system(model);
  const std::vector<double> tolerances = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  std::vector<std::vector<Run>> curves;
  std::vector<std::string> mbopt_curves = {"idas"};
  if (system.has_analytic_derivatives()) mbopt_curves.push_back("idas-dq");
  mbopt_curves.push_back("erk");
  const Run mbopt_reference = RunMbopt(system, "idas", kReferenceTolerance, 1);
  for (const std::string& integrator : mbopt_curves) {
    std::vector<Run> runs;
    for (double tol : tolerances) runs.push_back(RunMbopt(system, integrator, tol, repeats));
    curves.push_back(runs);
  }
  const Run simbody_reference = RunSimbody("rkm", kReferenceTolerance, 1);
  std::vector<Run> rkm, cpodes;
  for (double tol : tolerances) {
    rkm.push_back(RunSimbody("rkm", tol, repeats));
    if (tol >= kCpodesTightest) cpodes.push_back(RunSimbody("cpodes", tol, repeats));
  }
  curves.push_back(std::move(rkm));
  curves.push_back(std::move(cpodes));
  std::printf("references at %.0e: mbopt %s, Simbody rkm %s; they differ by %.3g\n", kReferenceTolerance,
              mbopt_reference.ok ? "ok" : mbopt_reference.failure.c_str(),
              simbody_reference.ok ? "ok" : simbody_reference.failure.c_str(),
              LargestDifference(mbopt_reference.values, simbody_reference.values));
  for (std::vector<Run>& curve : curves) {
    for (Run& r : curve) {
      const Run& reference = r.code == "mbopt" ? mbopt_reference : simbody_reference;
      if (r.ok) r.error = LargestDifference(r.values, reference.values);
      std::string failure = r.failure;
      std::replace(failure.begin(), failure.end(), ',', ';');
      std::replace(failure.begin(), failure.end(), '\n', ' ');
      csv << r.code << "," << r.integrator << "," << r.tolerance << "," << r.error << "," << r.cpu_s << ","
          << r.steps << "," << r.counters.nonlinear_iterations << "," << r.counters.jacobian_evaluations << ","
          << r.counters.residual_evaluations + r.counters.jacobian_residual_evaluations << ","
          << r.counters.error_test_failures << "," << r.counters.convergence_failures << "," << failure << "\n";
      std::printf("  %-7s %-7s tol %.0e: %s error %.3g, CPU %.4g s, %ld steps, %lld Newton matrices\n",
                  r.code.c_str(), r.integrator.c_str(), r.tolerance, r.ok ? "" : ("FAILED " + r.failure).c_str(),
                  r.error, r.cpu_s, r.steps, static_cast<long long>(r.counters.jacobian_evaluations));
    }
  }
  // mbopt's time over Simbody's at each of mbopt's errors.
  const auto points = [](const std::vector<Run>& curve) {
    std::vector<bench::CurvePoint> p;
    for (const Run& r : curve) p.push_back({r.ok, r.error, r.cpu_s});
    return p;
  };
  const std::vector<bench::CurvePoint> rkm_curve = points(curves[mbopt_curves.size()]);
  const std::vector<bench::CurvePoint> cpodes_curve = points(curves[mbopt_curves.size() + 1]);
  for (size_t c = 0; c < mbopt_curves.size(); ++c) {
    for (const Run& r : curves[c]) {
      if (!r.ok) continue;
      const std::optional<double> t_rkm = bench::CpuAtError(rkm_curve, r.error);
      const std::optional<double> t_cpodes = bench::CpuAtError(cpodes_curve, r.error);
      std::optional<double> fastest = t_rkm;
      if (t_cpodes && (!fastest || *t_cpodes < *fastest)) fastest = t_cpodes;
      auto ratio = [&](const std::optional<double>& simbody_s) { return simbody_s ? r.cpu_s / *simbody_s : NAN; };
      std::printf("  ratio mbopt (%s) / Simbody at error %.3g (mbopt tol %.0e): rkm %.3g, cpodes %.3g, fastest %.3g\n",
                  r.integrator.c_str(), r.error, r.tolerance, ratio(t_rkm), ratio(t_cpodes), ratio(fastest));
      ratios << r.integrator << "," << r.tolerance << "," << r.error << "," << r.cpu_s << "," << ratio(t_rkm) << ","
             << ratio(t_cpodes) << "," << ratio(fastest) << "\n";
    }
  }
  return 0;
}
