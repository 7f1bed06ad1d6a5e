// What the spatial work-precision benches share: process CPU time, the
// median of repeats, their two command-line options, and a curve's CPU
// time at a given error read off in log-log.
#pragma once

#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace mbopt::bench {

inline double CpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// --repeats=N (N > 0) and --out=FILE.csv; false (after saying why) on
// anything else.
inline bool ParseRepeatsAndOut(int argc, char** argv, int* repeats, std::string* out) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--repeats=", 0) == 0 && std::atoi(a.c_str() + 10) > 0) {
      *repeats = std::atoi(a.c_str() + 10);
    } else if (a.rfind("--out=", 0) == 0) {
      *out = a.substr(6);
    } else {
      std::cerr << "unknown argument '" << a << "' (expected --repeats=N > 0, --out=FILE.csv)\n";
      return false;
    }
  }
  return true;
}

// One run of a curve: whether it ran, its error and its CPU time.
struct CurvePoint {
  bool ok = false;
  double error = NAN;
  double cpu_s = NAN;
};

// The time `curve` takes at `error`, by linear interpolation in
// log(error)-log(time) between two of its runs whose errors bracket it (the
// pair with the smallest time when several do); none outside its range.
inline std::optional<double> CpuAtError(const std::vector<CurvePoint>& curve, double error) {
  std::optional<double> best;
  for (const CurvePoint& a : curve) {
    for (const CurvePoint& b : curve) {
      if (!a.ok || !b.ok || !(a.error > 0.0) || !(b.error > 0.0)) continue;
      if (!(a.error >= error && b.error <= error) || a.error == b.error) continue;
      const double w = std::log(error / a.error) / std::log(b.error / a.error);
      const double t = std::exp((1 - w) * std::log(a.cpu_s) + w * std::log(b.cpu_s));
      if (!best || t < *best) best = t;
    }
  }
  return best;
}

}  // namespace mbopt::bench
