// A design set: the study asks for analyses at a list of designs instead of
// an optimization (docs/study.md, "Sweeps and samples"). Either a sweep of
// one or two design variables (a line, or a grid of every pair), the others
// held at their initial values, or a Latin hypercube sample of every
// variable within its bounds. The points are a pure function of the study,
// the same on every platform: the server makes them once per job and a
// resume makes them again bit for bit.
#pragma once

#include <cstdint>
#include <vector>

namespace mbopt::spec {

struct Study;

struct SweepAxis {
  int variable = -1;  // index into Study::variables
  double from = 0;    // scaled, like the variable's bounds
  double to = 0;      // scaled; from == to only with points == 1
  int points = 0;     // >= 1
};

struct LatinHypercubeSample {
  int count = 0;            // points, >= 1
  std::uint64_t seed = 0;   // of std::mt19937_64
};

struct DesignSet {
  enum class Form { kNone, kSweep, kLatinHypercube } form = Form::kNone;
  std::vector<SweepAxis> axes;  // kSweep: one (a line) or two (a grid)
  LatinHypercubeSample latin_hypercube;

  bool empty() const { return form == Form::kNone; }
  // How many designs: the product of the axes' points, or the sample's count.
  std::int64_t size() const;
};

// The value of point `i` of `points` evenly spaced from `from` to `to`, both
// ends exact.
double AxisValue(const SweepAxis& axis, int i);

// The scaled designs of the study's design set, in their order (a grid's
// first axis varies slowest). Empty for a study without one. The set must be
// valid (spec/io checks it: variables, points, bounds).
std::vector<std::vector<double>> DesignSetPoints(const Study& study);

// A Latin hypercube of `count` points in `dimensions` dimensions on [0, 1):
// in every dimension each of the `count` equal strata holds exactly one
// point. Drawn from std::mt19937_64 with integer arithmetic only (no
// standard distribution, whose output the standard leaves to the library),
// so the points are the same on every platform. [point][dimension].
std::vector<std::vector<double>> LatinHypercubeUnit(int count, int dimensions, std::uint64_t seed);

}  // namespace mbopt::spec
