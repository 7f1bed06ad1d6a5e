// The Simbody oracle as a program of its own: Simbody 3.7 exports an old
// SUNDIALS' N_Vector symbols (from its CPodes) that would take the place of
// the engine's in one process, so the comparison test runs this and reads
// its output. C++17 (see simbody_oracle.h).
//
//   mbopt_simbody_oracle MECHANISM ACCURACY END_S INTERVALS
//
// MECHANISM is double_pendulum, four_bar or slider_crank (the default
// parameters of simbody_oracle.h). Prints one line per instant: the time and
// the mechanism's values, with 17 significant digits; exit status 1 and the
// reason on stderr when Simbody fails.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tests/oracle/simbody_oracle.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s MECHANISM ACCURACY END_S INTERVALS\n", argv[0]);
    return 2;
  }
  const std::string mechanism = argv[1];
  const double accuracy = std::atof(argv[2]), end_s = std::atof(argv[3]);
  const int intervals = std::atoi(argv[4]);
  std::vector<double> times;
  for (int i = 0; i <= intervals; ++i) times.push_back(end_s * i / intervals);
  mbopt::oracle::OracleRun run;
  if (mechanism == "double_pendulum") {
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
