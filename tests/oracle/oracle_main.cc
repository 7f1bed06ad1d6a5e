// The Simbody oracle as a program of its own: Simbody 3.7 exports an old
// SUNDIALS' N_Vector symbols (from its CPodes) that would take the place of
// the engine's in one process, so the comparison test runs this and reads
// its output. C++17 (see simbody_oracle.h).
//
//   mbopt_simbody_oracle MECHANISM ACCURACY END_S INTERVALS [REPEATS]
//
// MECHANISM is double_pendulum, four_bar, slider_crank or ten_body_chain
// (the default parameters of simbody_oracle.h). Prints one line per instant:
// the time and the mechanism's values, with 17 significant digits; exit
// status 1 and the reason on stderr when Simbody fails. With REPEATS (the
// ten-body chain only) it prints instead the median wall time in seconds of
// REPEATS integrations, for the speed benchmark (bench/multibody).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tests/oracle/simbody_oracle.h"

int main(int argc, char** argv) {
  if (argc != 5 && argc != 6) {
    std::fprintf(stderr, "usage: %s MECHANISM ACCURACY END_S INTERVALS [REPEATS]\n", argv[0]);
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
  if (mechanism == "ten_body_chain") {
    run = mbopt::oracle::SimulateTenBodyChain({}, times, accuracy, nullptr);
  } else if (mechanism == "double_pendulum") {
    run = mbopt::oracle::SimulateDoublePendulum({}, times, accuracy);
  } else if (mechanism == "four_bar") {
    run = mbopt::oracle::SimulateFourBar({}, times, accuracy);
  } else if (mechanism == "slider_crank") {
    run = mbopt::oracle::SimulateSliderCrank({}, times, accuracy);
  } else {
    std::fprintf(stderr, "unknown mechanism '%s'\n", mechanism.c_str());
    return 2;
  }
  if (!run.ok) {
    std::fprintf(stderr, "Simbody failed: %s\n", run.error.c_str());
    return 1;
  }
  for (size_t i = 0; i < times.size(); ++i) {
    std::printf("%.17g", times[i]);
    for (double v : run.values[i]) std::printf(" %.17g", v);
    std::printf("\n");
  }
  return 0;
}
