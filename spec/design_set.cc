#include "spec/design_set.h"

#include <cmath>
#include <random>
#include <utility>

#include "common/check.h"
#include "spec/study.h"

namespace mbopt::spec {
namespace {

// A uniform integer in [0, bound): the smallest all-ones mask above bound-1,
// and draws above the bound rejected, so every value is equally likely and
// the sequence depends only on the engine (whose output the standard fixes).
std::uint64_t UniformBelow(std::mt19937_64& engine, std::uint64_t bound) {
  MBOPT_CHECK(bound > 0, "UniformBelow needs a positive bound");
  std::uint64_t mask = bound - 1;
  for (int shift = 1; shift < 64; shift *= 2) mask |= mask >> shift;
  while (true) {
    const std::uint64_t draw = engine() & mask;
    if (draw < bound) return draw;
  }
}

// A double in [0, 1) from the engine's top 53 bits: exact in binary, so the
// same on every platform.
double UnitDraw(std::mt19937_64& engine) {
  return static_cast<double>(engine() >> 11) * 0x1.0p-53;
}

}  // namespace

std::int64_t DesignSet::size() const {
  switch (form) {
    case Form::kNone:
      return 0;
    case Form::kSweep: {
      std::int64_t n = axes.empty() ? 0 : 1;
      for (const SweepAxis& axis : axes) n *= axis.points;
      return n;
    }
    case Form::kLatinHypercube:
      return latin_hypercube.count;
  }
  return 0;
}

double AxisValue(const SweepAxis& axis, int i) {
  if (axis.points <= 1 || i == 0) return axis.from;
  if (i == axis.points - 1) return axis.to;
  const double share = static_cast<double>(i) / static_cast<double>(axis.points - 1);
  return axis.from + (axis.to - axis.from) * share;
}

std::vector<std::vector<double>> LatinHypercubeUnit(int count, int dimensions, std::uint64_t seed) {
  MBOPT_CHECK(count >= 1 && dimensions >= 0, "LatinHypercubeUnit needs a count of at least 1");
  std::mt19937_64 engine(seed);
  std::vector<std::vector<double>> points(static_cast<size_t>(count), std::vector<double>(dimensions));
  std::vector<int> strata(static_cast<size_t>(count));
  for (int d = 0; d < dimensions; ++d) {
    for (int i = 0; i < count; ++i) strata[static_cast<size_t>(i)] = i;
    // Fisher-Yates: which stratum of this dimension each point takes.
    for (int i = count - 1; i > 0; --i) {
      const auto j = static_cast<size_t>(UniformBelow(engine, static_cast<std::uint64_t>(i) + 1));
      std::swap(strata[static_cast<size_t>(i)], strata[j]);
    }
    for (int i = 0; i < count; ++i) {
      const double within = UnitDraw(engine);
      double t = (static_cast<double>(strata[static_cast<size_t>(i)]) + within) / static_cast<double>(count);
      // Rounding could carry the top of a stratum onto the next one's start.
      const double next_start = static_cast<double>(strata[static_cast<size_t>(i)] + 1) / static_cast<double>(count);
      if (t >= next_start) t = std::nextafter(next_start, 0.0);
      points[static_cast<size_t>(i)][static_cast<size_t>(d)] = t;
    }
  }
  return points;
}

std::vector<std::vector<double>> DesignSetPoints(const Study& study) {
  std::vector<std::vector<double>> points;
  const DesignSet& set = study.design_set;
  std::vector<double> initial;
  for (const DesignVariable& v : study.variables) initial.push_back(v.initial);
  switch (set.form) {
    case DesignSet::Form::kNone:
      break;
    case DesignSet::Form::kSweep: {
      MBOPT_CHECK(set.axes.size() == 1 || set.axes.size() == 2, "a sweep has one or two axes");
      const SweepAxis& outer = set.axes[0];
      const SweepAxis* inner = set.axes.size() == 2 ? &set.axes[1] : nullptr;
      for (int i = 0; i < outer.points; ++i) {
        const int inner_points = inner != nullptr ? inner->points : 1;
        for (int j = 0; j < inner_points; ++j) {
          std::vector<double> x = initial;
          x[static_cast<size_t>(outer.variable)] = AxisValue(outer, i);
          if (inner != nullptr) x[static_cast<size_t>(inner->variable)] = AxisValue(*inner, j);
          points.push_back(std::move(x));
        }
      }
      break;
    }
    case DesignSet::Form::kLatinHypercube: {
      const int dimensions = static_cast<int>(study.variables.size());
      const std::vector<std::vector<double>> unit =
          LatinHypercubeUnit(set.latin_hypercube.count, dimensions, set.latin_hypercube.seed);
      for (const std::vector<double>& u : unit) {
        std::vector<double> x(static_cast<size_t>(dimensions));
        for (int d = 0; d < dimensions; ++d) {
          const DesignVariable& v = study.variables[static_cast<size_t>(d)];
          x[static_cast<size_t>(d)] = v.lower + (v.upper - v.lower) * u[static_cast<size_t>(d)];
        }
        points.push_back(std::move(x));
      }
      break;
    }
  }
  return points;
}

}  // namespace mbopt::spec
