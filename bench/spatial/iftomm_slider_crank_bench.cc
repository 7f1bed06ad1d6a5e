// The IFToMM spatial rigid slider-crank (issue 31, docs/benchmarks.md),
// reported as the IFToMM library of computational benchmark problems asks:
// for each integrator and tolerance, the CPU time of the 5 s simulation,
// the error of the slider's position x(t) and the benchmark's own accuracy
// measure, the largest change of the total energy (which is constant: no
// friction, no damping). The mechanism is the problem's data
// (tests/spatial/spatial_mechanisms.h, SpatialSliderCrank; the same as
// examples/spatial/iftomm_slider_crank.scene.textproto).
//
// The library's reference trajectories were not available here, so the
// reference is Simbody (Runge-Kutta-Merson, accuracy 1e-12) over the same
// 5 s; mbopt's own run at 1e-12 is compared with it to show how far that
// reference can be trusted. Errors and energy changes are taken at 501
// instants (every 10 ms). A run's cost is the median CPU time of the
// integration alone over the repeats (output at the instants included).
//
// mbopt runs in this process: IDAS (rtol = atol = tolerance) and the
// explicit path (Verner 6(5) with projection). Simbody runs as the program
// mbopt_simbody_spatial_oracle (tests/spatial) with Runge-Kutta-Merson and
// CPodes' BDF, accuracy = tolerance. For each mbopt run, the ratio of its
// CPU time to Simbody's at the same slider error, read off Simbody's curves
// (the faster of the two) by linear interpolation in log-log, as
// bench_spatial_workprec does.
//
//   build/bench/spatial/bench_spatial_slider_crank [--repeats=5] [--out=iftomm_slider_crank.csv]
//
// Writes one CSV row per run and prints a table.
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

constexpr double kEnd_s = 5.0;  // the benchmark's duration
constexpr int kIntervals = 500;
constexpr double kReferenceTolerance = 1e-12;
// As bench_spatial_workprec: CPodes is not run tighter.
constexpr double kCpodesTightest = 1e-8;
constexpr int kSlider = 2;  // body index (crank, rod, slider)

struct Run {
  std::string code, integrator;
  double tolerance = 0.0;
  bool ok = false;
  std::string failure;
  std::vector<double> slider_x_m, energy_j;  // per instant
  double cpu_s = 0.0;
  long steps = 0;
  double error_m = NAN;    // largest |x - x_reference| over the instants
  double drift_j = NAN;    // largest |E(t) - E(0)| over the instants
};

std::vector<double> Times() {
  std::vector<double> t;
  for (int i = 0; i <= kIntervals; ++i) t.push_back(kEnd_s * i / kIntervals);
  return t;
}

double Drift(const std::vector<double>& energy_j) {
  double drift = 0.0;
  for (double e : energy_j) drift = std::max(drift, std::abs(e - energy_j.front()));
  return drift;
}

// `integrator`: "idas" or "erk" (the explicit path).
Run RunMbopt(const spatial::SpatialSystem& system, const std::string& integrator, double tolerance, int repeats) {
  Run run;
  run.code = "mbopt";
  run.integrator = integrator;
  run.tolerance = tolerance;
  const spatial::SpatialAssembly assembled = spatial::AssembleSpatial(system, 0.0);
  if (!assembled.failure.ok()) {
    run.failure = assembled.failure.reason;
    return run;
  }
  multibody::ForwardDynamicsOptions options;
  options.relative_tolerance = tolerance;
  options.absolute_tolerance = tolerance;  // lengths of 0.1 m, rates of 10 rad/s
  options.max_steps = 10000000;
  if (integrator == "erk") options.method = multibody::ForwardDynamicsOptions::Method::kExplicitRungeKutta;
  std::vector<double> cpu;
  multibody::ForwardDynamicsCounters counters;
  for (int r = 0; r < repeats; ++r) {
    run.slider_x_m.clear();
    run.energy_j.clear();
    counters = multibody::ForwardDynamicsCounters{};
    const double start = CpuSeconds();
    const spec::AnalysisFailure f = multibody::IntegrateForward(
        system, 0.0, assembled.q, assembled.v, Times(), options,
        [&](const multibody::MotionSample& s) {
          run.slider_x_m.push_back(s.q[7 * kSlider]);
          run.energy_j.push_back(system.KineticEnergy(s.q, s.v) + system.PotentialEnergy(s.q));
          return spec::AnalysisFailure::Ok();
        },
        &counters);
    cpu.push_back(CpuSeconds() - start);
    if (!f.ok()) {
      run.failure = f.reason;
      return run;
    }
  }
  run.ok = true;
  run.cpu_s = Median(cpu);
  run.steps = static_cast<long>(counters.steps);
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
                              " --cpu=" + std::to_string(repeats) + " --energy slider_crank " + accuracy + " " +
                              std::to_string(kEnd_s) + " " + std::to_string(kIntervals) + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    run.failure = "cannot start " + command;
    return run;
  }
  char line[16384];
  std::string unparsed;
  constexpr size_t kValues = 3 * 12 + 1;  // three bodies' poses, the energy
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    if (line[0] == '#') {
      std::istringstream in(line + 1);
      in >> run.cpu_s >> run.steps;
      continue;
    }
    std::istringstream in(line);
    double t = 0.0, v = 0.0;
    std::vector<double> values;
    if (in >> t) {
      while (in >> v) values.push_back(v);
    }
    if (values.size() != kValues) {
      unparsed += line;
      continue;
    }
    run.slider_x_m.push_back(values[12 * kSlider]);
    run.energy_j.push_back(values.back());
  }
  run.ok = pclose(pipe) == 0 && static_cast<int>(run.slider_x_m.size()) == kIntervals + 1;
  if (!run.ok) run.failure = unparsed.empty() ? command + " failed" : unparsed;
  return run;
}

// The largest difference over the instants (NaN when the shapes differ).
double LargestDifference(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size() || a.empty()) return NAN;
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  std::string out = "iftomm_slider_crank.csv";
  if (!bench::ParseRepeatsAndOut(argc, argv, &repeats, &out)) return 2;
  std::ofstream csv(out);
  if (!csv) {
    std::cerr << "cannot write " << out << "\n";
    return 1;
  }
  csv << "code,integrator,tolerance,slider_x_error_m,energy_drift_j,cpu_s,steps,failure\n";

  const spatial::Model model = spatial::ModelOf(oracle::SpatialSliderCrank());
  const spatial::SpatialSystem system(model);
  const Run reference = RunSimbody("rkm", kReferenceTolerance, 1);
  const Run mbopt_tight = RunMbopt(system, "erk", kReferenceTolerance, 1);
  const Run mbopt_tight_idas = RunMbopt(system, "idas", kReferenceTolerance, 1);
  if (!reference.ok) {
    std::cerr << "the reference failed: " << reference.failure << "\n";
    return 1;
  }
  std::printf("reference: Simbody rkm at %.0e over %.0f s, energy %.10f J, its change %.3g J\n", kReferenceTolerance,
              kEnd_s, reference.energy_j.front(), Drift(reference.energy_j));
  std::printf("mbopt at %.0e against it: slider x %.3g m (erk), %.3g m (idas); energy change %.3g J, %.3g J\n",
              kReferenceTolerance, LargestDifference(mbopt_tight.slider_x_m, reference.slider_x_m),
              LargestDifference(mbopt_tight_idas.slider_x_m, reference.slider_x_m),
              mbopt_tight.ok ? Drift(mbopt_tight.energy_j) : NAN,
              mbopt_tight_idas.ok ? Drift(mbopt_tight_idas.energy_j) : NAN);

  const std::vector<double> tolerances = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10};
  std::vector<Run> runs;
  for (const std::string integrator : {"idas", "erk"}) {
    for (double tol : tolerances) runs.push_back(RunMbopt(system, integrator, tol, repeats));
  }
  for (double tol : tolerances) runs.push_back(RunSimbody("rkm", tol, repeats));
  for (double tol : tolerances) {
    if (tol >= kCpodesTightest) runs.push_back(RunSimbody("cpodes", tol, repeats));
  }
  std::vector<bench::CurvePoint> simbody_rkm, simbody_cpodes;
  for (Run& r : runs) {
    if (r.ok) {
      r.error_m = LargestDifference(r.slider_x_m, reference.slider_x_m);
      r.drift_j = Drift(r.energy_j);
    }
    if (r.code == "simbody") (r.integrator == "rkm" ? simbody_rkm : simbody_cpodes).push_back({r.ok, r.error_m, r.cpu_s});
  }
  std::printf("| code | integrator | tolerance | slider x error (m) | energy change (J) | CPU (s) | steps | "
              "CPU / Simbody's at this error (faster integrator) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (Run& r : runs) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    std::replace(failure.begin(), failure.end(), '\n', ' ');
    csv << r.code << "," << r.integrator << "," << r.tolerance << "," << r.error_m << "," << r.drift_j << ","
        << r.cpu_s << "," << r.steps << "," << failure << "\n";
    if (r.ok) {
      std::string ratio;
      if (r.code == "mbopt") {
        std::optional<double> t = bench::CpuAtError(simbody_rkm, r.error_m);
        const std::optional<double> t_cpodes = bench::CpuAtError(simbody_cpodes, r.error_m);
        const char* which = "rkm";
        if (t_cpodes && (!t || *t_cpodes < *t)) {
          t = t_cpodes;
          which = "cpodes";
        }
        char text[64];
        std::snprintf(text, sizeof text, "%.2f (%s)", t ? r.cpu_s / *t : NAN, which);
        ratio = t ? text : "(Simbody's curves do not reach)";
      }
      std::printf("| %s | %s | %.0e | %.2g | %.2g | %.3g | %ld | %s |\n", r.code.c_str(), r.integrator.c_str(),
                  r.tolerance, r.error_m, r.drift_j, r.cpu_s, r.steps, ratio.c_str());
    } else {
      std::printf("| %s | %s | %.0e | failed: %s | | | | |\n", r.code.c_str(), r.integrator.c_str(), r.tolerance,
                  failure.c_str());
    }
  }
  return 0;
}
