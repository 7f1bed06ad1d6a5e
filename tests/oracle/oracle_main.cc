// The Simbody oracle as a program of its own: Simbody 3.7 exports an old
// SUNDIALS' N_Vector symbols (from its CPodes) that would take the place of
// the engine's in one process, so the comparison test runs this and reads
// its output. C++17 (see simbody_oracle.h).
//
//   mbopt_simbody_oracle [--integrator=rkm|cpodes] [--cpu=REPEATS]
//                        MECHANISM ACCURACY END_S INTERVALS [REPEATS]
//
// MECHANISM is double_pendulum, four_bar, slider_crank, ten_body_chain,
// rod_chain (ten rods) or andrews (the default parameters of
// simbody_oracle.h). Prints one line per instant:
// the time and the mechanism's values, with 17 significant digits; exit
// status 1 and the reason on stderr when Simbody fails. With REPEATS (the
// ten-body chain only) it prints instead the median wall time in seconds of
// REPEATS integrations, for the speed benchmark (bench/multibody). With
// --cpu=REPEATS it integrates REPEATS times and first prints a line
// "# CPU_MEDIAN_S STEPS" (the integration alone), then the values of the
// last run: the work-precision benchmark reads both.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "tests/oracle/simbody_oracle.h"

namespace {

mbopt::oracle::OracleRun Simulate(const std::string& mechanism, const std::vector<double>& times, double accuracy) {
  if (mechanism == "ten_body_chain") return mbopt::oracle::SimulateTenBodyChain({}, times, accuracy, nullptr);
  if (mechanism == "double_pendulum") return mbopt::oracle::SimulateDoublePendulum({}, times, accuracy);
  if (mechanism == "four_bar") return mbopt::oracle::SimulateFourBar({}, times, accuracy);
  if (mechanism == "slider_crank") return mbopt::oracle::SimulateSliderCrank({}, times, accuracy);
  if (mechanism == "rod_chain") return mbopt::oracle::SimulateRodChain(10, times, accuracy);
  if (mechanism == "andrews") return mbopt::oracle::SimulateAndrews(times, accuracy);
  return mbopt::oracle::OracleRun{false, "unknown mechanism '" + mechanism + "'", {}};
}

}  // namespace

int main(int argc, char** argv) {
  int cpu_repeats = 0;
  while (argc > 1 && std::strncmp(argv[1], "--", 2) == 0) {
    const std::string option = argv[1];
    const bool integrator = option.rfind("--integrator=", 0) == 0 && mbopt::oracle::UseIntegrator(option.substr(13));
    const bool cpu = option.rfind("--cpu=", 0) == 0 && std::atoi(option.c_str() + 6) > 0;
    if (cpu) cpu_repeats = std::atoi(option.c_str() + 6);
    if (!integrator && !cpu) {
      std::fprintf(stderr, "unknown option '%s' (expected --integrator=rkm|cpodes or --cpu=REPEATS > 0)\n",
                   option.c_str());
      return 2;
    }
    --argc;
    ++argv;
  }
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: %s [--integrator=rkm|cpodes] [--cpu=REPEATS] MECHANISM ACCURACY END_S INTERVALS [REPEATS]\n",
                 argv[0]);
    return 2;
  }
  const std::string mechanism = argv[1];
  const double accuracy = std::atof(argv[2]), end_s = std::atof(argv[3]);
  const int intervals = std::atoi(argv[4]);
  std::vector<double> times;
  for (int i = 0; i <= intervals; ++i) times.push_back(end_s * i / intervals);
  mbopt::oracle::OracleRun run;
  if (argc == 6) {
    if (mechanism != "ten_body_chain") {
      std::fprintf(stderr, "timing is for ten_body_chain only\n");
      return 2;
    }
    std::vector<double> seconds;
    for (int r = 0; r < std::atoi(argv[5]); ++r) {
      double wall = 0.0;
      run = mbopt::oracle::SimulateTenBodyChain({}, times, accuracy, &wall);
      if (!run.ok) {
        std::fprintf(stderr, "Simbody failed: %s\n", run.error.c_str());
        return 1;
      }
      seconds.push_back(wall);
    }
    std::sort(seconds.begin(), seconds.end());
    std::printf("%.9g\n", seconds.empty() ? 0.0 : seconds[seconds.size() / 2]);
    return 0;
  }
  std::vector<double> cpu_seconds;
  for (int r = 0; r < std::max(cpu_repeats, 1); ++r) {
    run = Simulate(mechanism, times, accuracy);
    if (!run.ok) break;
    cpu_seconds.push_back(run.cpu_seconds);
  }
  if (!run.ok) {
    std::fprintf(stderr, "Simbody failed: %s\n", run.error.c_str());
    return 1;
  }
  if (cpu_repeats > 0) {
    std::sort(cpu_seconds.begin(), cpu_seconds.end());
    std::printf("# %.9g %ld\n", cpu_seconds[cpu_seconds.size() / 2], run.steps);
  }
  for (size_t i = 0; i < times.size(); ++i) {
    std::printf("%.17g", times[i]);
    for (double v : run.values[i]) std::printf(" %.17g", v);
    std::printf("\n");
  }
  return 0;
}
