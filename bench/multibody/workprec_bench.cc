// Work-precision of the multibody engine against Simbody (issue 30,
// docs/benchmarks.md): for each planar mechanism both codes integrate at a
// range of tolerances; each run's error is the largest difference of the
// mechanism's angles at the output instants from a tight reference of the
// same code's own model, and its cost the median CPU time of the
// integration alone over the repeats. The time ratio at equal error is read
// off the other code's curve by linear interpolation in log-log.
//
//   ten_body_chain  tests/multibody/mechanisms.h's TenBodyChain, 2 s
//   rod_chain       ten rods closed between two ground pins (8 degrees of
//                   freedom), 2 s under gravity
//   andrews         examples/andrews/andrews.scene.textproto, 0.03 s; also
//                   the error against the published reference at 0.03 s
//
// mbopt runs in this process, with each of its integrators: IDAS (the
// engine's automatic linear solver) and the explicit Runge-Kutta path with
// projection (explicit_dynamics.h), rtol = tolerance, atol = tolerance
// times the mechanism's length scale; both against the IDAS reference;
// Simbody runs as the oracle program of tests/oracle (it cannot share a
// process with the engine), with Runge-Kutta-Merson (its default) and with
// CPodes' BDF, accuracy = tolerance.
//
//   build/bench/multibody/bench_multibody_workprec [--repeats=5] [--only=MECHANISM]
//       [--out=docs/svg/workprec_multibody.csv] [--explicit-pair=verner-6-5]
//       [--explicit-outputs=interpolated|stop]
//
// Writes one CSV row per run (code, integrator, tolerance, error, CPU,
// counters), the ratios to OUT's name with _ratios before .csv, and prints
// both with the references' differences.
// bench/multibody/workprec_svg.py draws the table.
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

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace {

using namespace mbopt::multibody;
using Values = std::vector<std::vector<double>>;  // [instant][angle], rad

// The published reference of the Test Set for IVP solvers at t = 0.03 s
// (beta, Theta, gamma, Phi, delta, Omega, epsilon; the same numbers as
// tests/multibody/hardcase_test.cc).
constexpr double kAndrewsPublished[7] = {0.1581077119629904e+2, -0.1575637105984298e+2, 0.4082224013073101e-1,
                                         -0.5347301163226948,   0.5244099658805304,     0.5347301163226948,
                                         0.1048080741042263e+1};

// CPodes' runs stop here: at 1e-13 it had not finished the rod chain after
// 2.5 min of CPU, and down to 1e-9 Runge-Kutta-Merson is the faster of the
// two wherever both reach an error.
constexpr double kCpodesTightest = 1e-9;

struct Bench {
  std::string name;  // also the oracle program's mechanism
  Model model;
  double end_s = 0.0;
  int intervals = 0;
  // atol = rtol * this: the chains' links are 1 m, Andrews' 7-70 mm (its
  // accuracy table: atol rtol / 100).
  double absolute_per_relative = 1.0;
  std::vector<double> tolerances, simbody_tolerances;
  double mbopt_reference_tolerance = 0.0, simbody_reference_tolerance = 0.0;
  // The angles compared, from the engine's state.
  std::vector<int> body_angles, joint_coordinates;
};

struct Run {
  std::string code, integrator;
  double tolerance = 0.0;
  bool ok = false;
  std::string failure;
  Values values;
  double cpu_s = 0.0;
  long steps = 0;
  ForwardDynamicsCounters counters;  // mbopt's only
  double error_rad = NAN;
};

double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<double> Times(const Bench& b) {
  std::vector<double> t;
  for (int i = 0; i <= b.intervals; ++i) t.push_back(b.end_s * i / b.intervals);
  return t;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The explicit path's pair (--explicit-pair): the default unless measured.
ForwardDynamicsOptions::ExplicitPair explicit_pair = ForwardDynamicsOptions{}.explicit_pair;
// Its outputs (--explicit-outputs=interpolated|stop): the default unless measured.
bool explicit_stop_at_instants = ForwardDynamicsOptions{}.explicit_stop_at_instants;

Run RunMbopt(const Bench& b, double tolerance, int repeats,
             ForwardDynamicsOptions::Method method = ForwardDynamicsOptions::Method::kImplicitBdf) {
  Run run;
  run.code = "mbopt";
  run.integrator = method == ForwardDynamicsOptions::Method::kImplicitBdf ? "idas" : "erk";
  run.tolerance = tolerance;
  const Mechanism m(b.model);
  const Assembly assembled = Assemble(m, 0.0);
  if (!assembled.failure.ok()) {
    run.failure = assembled.failure.reason;
    return run;
  }
  ForwardDynamicsOptions options;
  options.method = method;
  options.explicit_pair = explicit_pair;
  options.explicit_stop_at_instants = explicit_stop_at_instants;
  options.relative_tolerance = tolerance;
  options.absolute_tolerance = tolerance * b.absolute_per_relative;
  std::vector<double> cpu;
  for (int r = 0; r < repeats; ++r) {
    run.values.clear();
    run.counters = ForwardDynamicsCounters{};
    const double start = CpuSeconds();
    const mbopt::spec::AnalysisFailure f = IntegrateForward(
        m, 0.0, assembled.q, assembled.v, Times(b), options,
        [&](const MotionSample& s) {
          std::vector<double> angles;
          for (int body : b.body_angles) angles.push_back(s.q[3 * body + 2]);
          for (int joint : b.joint_coordinates) angles.push_back(m.JointCoordinate(joint, s.q));
          run.values.push_back(std::move(angles));
          return mbopt::spec::AnalysisFailure::Ok();
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

Run RunSimbody(const Bench& b, const std::string& integrator, double tolerance, int repeats) {
  Run run;
  run.code = "simbody";
  run.integrator = integrator;
  run.tolerance = tolerance;
  char accuracy[32];
  std::snprintf(accuracy, sizeof accuracy, "%.17g", tolerance);
  const std::string command = std::string(MBOPT_SIMBODY_ORACLE) + " --integrator=" + integrator +
                              " --cpu=" + std::to_string(repeats) + " " + b.name + " " + accuracy + " " +
                              std::to_string(b.end_s) + " " + std::to_string(b.intervals) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    run.failure = "cannot start " + command;
    return run;
  }
  char line[8192];
  std::string unparsed;
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    std::istringstream in(line[0] == '#' ? line + 1 : line);
    if (line[0] == '#') {
      in >> run.cpu_s >> run.steps;
      continue;
    }
    double t = 0.0, v = 0.0;
    if (!(in >> t)) {
      unparsed += line;
      continue;
    }
    std::vector<double> values;
    while (in >> v) values.push_back(v);
    run.values.push_back(std::move(values));
  }
  run.ok = pclose(pipe) == 0 && static_cast<int>(run.values.size()) == b.intervals + 1;
  if (!run.ok) run.failure = unparsed.empty() ? command + " failed" : unparsed;
  return run;
}

// The largest difference over instants and angles (NaN when either run
// failed or they do not have the same shape).
double LargestDifference(const Values& a, const Values& b) {
  if (a.size() != b.size() || a.empty()) return NAN;
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].size() != b[i].size()) return NAN;
    for (size_t k = 0; k < a[i].size(); ++k) worst = std::max(worst, std::abs(a[i][k] - b[i][k]));
  }
  return worst;
}

// The time `curve` takes at `error`, by linear interpolation in
// log(error)-log(time) between the two of its runs whose errors bracket it
// (the pair with the smallest times when several do); none outside the
// curve's range.
std::optional<double> TimeAtError(const std::vector<Run>& curve, double error) {
  std::optional<double> best;
  for (const Run& a : curve) {
    for (const Run& b : curve) {
      if (!a.ok || !b.ok || !(a.error_rad > 0.0) || !(b.error_rad > 0.0)) continue;
      if (!(a.error_rad >= error && b.error_rad <= error) || a.error_rad == b.error_rad) continue;
      const double w = std::log(error / a.error_rad) / std::log(b.error_rad / a.error_rad);
      const double t = std::exp((1 - w) * std::log(a.cpu_s) + w * std::log(b.cpu_s));
      if (!best || t < *best) best = t;
    }
  }
  return best;
}

std::vector<Bench> Benches() {
  std::vector<Bench> benches;
  // Both references at 1e-12: Simbody fails at 1e-13 (it cannot advance
  // time past 0.093 s on the rod chain).
  const std::vector<double> tolerances = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  Bench ten{"ten_body_chain", testing::TenBodyChain(), 2.0, 20, 1.0, tolerances, tolerances, 1e-12, 1e-12, {0, 9}, {}};
  benches.push_back(ten);
  Bench rods{"rod_chain", testing::RodChain(10), 2.0, 20, 1.0, tolerances, tolerances, 1e-12, 1e-12, {}, {}};
  for (int i = 0; i < 10; ++i) rods.body_angles.push_back(i);
  benches.push_back(rods);
  absl::StatusOr<mbopt::spec::Scene> scene =
      mbopt::spec::io::LoadSceneFile(MBOPT_SOURCE_DIR "/examples/andrews/andrews.scene.textproto");
  if (!scene.ok()) {
    std::cerr << "andrews: " << scene.status() << "\n";
    return benches;
  }
  std::vector<double> defaults;
  for (const mbopt::spec::Parameter& p : scene->parameters) defaults.push_back(p.value_si);
  absl::StatusOr<Model> model = CompileModel(*scene, defaults);
  if (!model.ok()) {
    std::cerr << "andrews: " << model.status() << "\n";
    return benches;
  }
  // rtol 1e-10 is the tightest at which the engine runs it
  // (docs/accuracy_multibody.md).
  Bench andrews{"andrews", *model, 0.03, 30, 0.01, {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9},
                tolerances, 1e-10, 1e-12, {}, {}};
  for (const char* name : {"beta", "theta", "gamma", "phi", "delta", "omega", "epsilon"}) {
    for (size_t j = 0; j < model->joints.size(); ++j) {
      if (model->joints[j].name == name) andrews.joint_coordinates.push_back(static_cast<int>(j));
    }
  }
  benches.push_back(andrews);
  return benches;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  std::string only, out = "workprec_multibody.csv";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--repeats=", 0) == 0 && std::atoi(a.c_str() + 10) > 0) {
      repeats = std::atoi(a.c_str() + 10);
    } else if (a.rfind("--only=", 0) == 0) {
      only = a.substr(7);
    } else if (a == "--explicit-pair=dormand-prince-5-4") {
      explicit_pair = ForwardDynamicsOptions::ExplicitPair::kDormandPrince54;
    } else if (a == "--explicit-pair=verner-6-5") {
      explicit_pair = ForwardDynamicsOptions::ExplicitPair::kVerner65;
    } else if (a == "--explicit-pair=fehlberg-8-7") {
      explicit_pair = ForwardDynamicsOptions::ExplicitPair::kFehlberg87;
    } else if (a == "--explicit-outputs=interpolated" || a == "--explicit-outputs=stop") {
      explicit_stop_at_instants = a == "--explicit-outputs=stop";
    } else if (a.rfind("--out=", 0) == 0) {
      out = a.substr(6);
    } else {
      std::cerr << "unknown argument '" << a
                << "' (expected --repeats=N > 0, --only=ten_body_chain|rod_chain|andrews, --out=FILE.csv, "
                   "--explicit-pair=dormand-prince-5-4|verner-6-5|fehlberg-8-7, "
                   "--explicit-outputs=interpolated|stop)\n";
      return 2;
    }
  }
  std::ofstream csv(out);
  if (!csv) {
    std::cerr << "cannot write " << out << "\n";
    return 1;
  }
  csv << "mechanism,code,integrator,tolerance,error_rad,cpu_s,steps,newton_iterations,jacobians,residuals,"
         "error_test_failures,newton_failures,failure\n";
  // NaN where Simbody's curve does not reach mbopt's error.
  const std::string ratios_path = out.substr(0, out.rfind(".csv")) + "_ratios.csv";
  std::ofstream ratios(ratios_path);
  ratios << "mechanism,mbopt_integrator,mbopt_tolerance,error_rad,mbopt_cpu_s,ratio_to_rkm,ratio_to_cpodes,"
            "ratio_to_fastest\n";
  const std::vector<std::string> integrators = {"rkm", "cpodes"};
  for (const Bench& b : Benches()) {
    if (!only.empty() && b.name != only) continue;
    std::cout << "== " << b.name << "\n";
    const Run mbopt_reference = RunMbopt(b, b.mbopt_reference_tolerance, 1);
    std::vector<std::vector<Run>> curves;
    std::vector<Run> mbopt_runs;
    for (double tol : b.tolerances) mbopt_runs.push_back(RunMbopt(b, tol, repeats));
    curves.push_back(mbopt_runs);
    std::vector<Run> explicit_runs;
    for (double tol : b.tolerances) {
      explicit_runs.push_back(RunMbopt(b, tol, repeats, ForwardDynamicsOptions::Method::kExplicitRungeKutta));
    }
    // Simbody's reference: Runge-Kutta-Merson's (see kCpodesTightest);
    // CPodes' runs are measured against it too.
    const Run simbody_reference = RunSimbody(b, "rkm", b.simbody_reference_tolerance, 1);
    for (const std::string& integrator : integrators) {
      std::vector<Run> runs;
      for (double tol : b.simbody_tolerances) {
        if (integrator == "cpodes" && tol < kCpodesTightest) continue;
        runs.push_back(RunSimbody(b, integrator, tol, repeats));
      }
      curves.push_back(runs);
    }
    curves.push_back(explicit_runs);  // last: curves[1], curves[2] stay Simbody's
    std::printf("references: mbopt rtol %.0e (%s), Simbody rkm accuracy %.0e (%s); they differ by %.3g rad\n",
                b.mbopt_reference_tolerance, mbopt_reference.ok ? "ok" : mbopt_reference.failure.c_str(),
                b.simbody_reference_tolerance, simbody_reference.ok ? "ok" : simbody_reference.failure.c_str(),
                LargestDifference(mbopt_reference.values, simbody_reference.values));
    if (b.name == "andrews") {
      for (const Run* r : {&mbopt_reference, &simbody_reference}) {
        if (!r->ok) continue;
        double worst = 0.0;
        for (int k = 0; k < 7; ++k) worst = std::max(worst, std::abs(r->values.back()[static_cast<size_t>(k)] - kAndrewsPublished[k]));
        std::printf("%s reference against the published solution at 0.03 s: %.3g rad\n", r->code.c_str(), worst);
      }
    }
    for (std::vector<Run>& curve : curves) {
      const Run& reference = curve.front().code == "mbopt" ? mbopt_reference : simbody_reference;
      for (Run& r : curve) {
        if (r.ok) r.error_rad = LargestDifference(r.values, reference.values);
        std::string failure = r.failure;
        std::replace(failure.begin(), failure.end(), ',', ';');
        std::replace(failure.begin(), failure.end(), '\n', ' ');
        csv << b.name << "," << r.code << "," << r.integrator << "," << r.tolerance << "," << r.error_rad << ","
            << r.cpu_s << "," << r.steps << "," << r.counters.nonlinear_iterations << ","
            << r.counters.jacobian_evaluations << ","
            << r.counters.residual_evaluations + r.counters.jacobian_residual_evaluations << ","
            << r.counters.error_test_failures << "," << r.counters.convergence_failures << "," << failure << "\n";
        std::printf("  %-7s %-6s tol %.0e: %s error %.3g rad, CPU %.4g s, %ld steps\n", r.code.c_str(),
                    r.integrator.c_str(), r.tolerance, r.ok ? "" : ("FAILED " + r.failure).c_str(), r.error_rad,
                    r.cpu_s, r.steps);
      }
    }
    // mbopt's time over Simbody's at each of mbopt's errors (against each
    // integrator and the faster of the two); the target is 1/3 or less.
    auto ratio_row = [&](const Run& r) {
      if (!r.ok) return;
      const std::optional<double> rkm = TimeAtError(curves[1], r.error_rad);
      const std::optional<double> cpodes = TimeAtError(curves[2], r.error_rad);
      std::optional<double> fastest = rkm;
      if (cpodes && (!fastest || *cpodes < *fastest)) fastest = cpodes;
      auto ratio = [&](const std::optional<double>& simbody_s) { return simbody_s ? r.cpu_s / *simbody_s : NAN; };
      std::printf(
          "  ratio mbopt %s / Simbody at error %.3g rad (mbopt tol %.0e): rkm %.3g, cpodes %.3g, fastest %.3g\n",
          r.integrator.c_str(), r.error_rad, r.tolerance, ratio(rkm), ratio(cpodes), ratio(fastest));
      ratios << b.name << "," << r.integrator << "," << r.tolerance << "," << r.error_rad << "," << r.cpu_s << ","
             << ratio(rkm) << "," << ratio(cpodes) << "," << ratio(fastest) << "\n";
    };
    for (const Run& r : curves.front()) ratio_row(r);
    for (const Run& r : curves.back()) ratio_row(r);
    std::fflush(stdout);
  }
  return 0;
}
