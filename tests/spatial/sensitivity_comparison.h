// Simulator sensitivities of a spatial scene against central differences
// of whole analyses (AnalyzeSpatialScene at p_k +- step), output by output,
// each relative to its largest derivative.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "spec/scene.h"
#include "tests/spatial/scene_text_testing.h"
#include "worker/spatial/spatial_scene_analysis.h"

namespace mbopt::spatial::sensitivity_testing {

// Relative step of the central differences. Analyses integrated at rtol
// 1e-10 give differences with noise about rtol / step = 1e-6 and
// truncation about step^2 = 1e-8: fine enough to judge the sensitivities.
inline constexpr double kRelativeStep = 1e-4;

// Below this a derivative counts as zero (outputs are O(1) in SI here).
inline constexpr double kNoDependence = 1e-8;

// Per output, the largest |simulator - central difference| over the
// instants relative to the largest |central difference|; and the same for
// the peak (the largest value over the instants), whose derivative is the
// output's derivative at the peak's instant.
struct Agreement {
  double worst_series = 0.0;
  double worst_peak = 0.0;
};

inline std::vector<double> Values(const spec::Scene& scene) { return scene.DefaultParameterValues(); }

inline int IndexOf(const spec::Scene& scene, const std::string& name) {
  for (size_t i = 0; i < scene.parameters.size(); ++i) {
    if (scene.parameters[i].name == name) return static_cast<int>(i);
  }
  ADD_FAILURE() << "no parameter " << name;
  return 0;
}

inline size_t ArgMax(const std::vector<double>& v) {
  return static_cast<size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}

// `reactions`: outputs whose agreement goes to `reaction_agreement`
// instead (one set of analyses for both).
inline Agreement Compare(const spec::Scene& scene, const std::vector<std::string>& parameters,
                  const std::vector<std::string>& outputs, const std::vector<std::string>& reactions = {},
                  Agreement* reaction_agreement = nullptr) {
  const std::vector<double> p = Values(scene);
  std::vector<int> indices;
  for (const std::string& name : parameters) indices.push_back(IndexOf(scene, name));
  const SpatialSensitivityResult result = AnalyzeSpatialSceneWithSensitivities(scene, p, indices);
  EXPECT_TRUE(result.report.ok()) << result.report.failure.reason;
  EXPECT_EQ(result.unavailable, "");
  if (!result.report.ok() || result.output_derivatives.size() != indices.size()) return {INFINITY, INFINITY};
  // The values are the plain analysis', to the integration tolerance (the
  // sensitivities in the error test change the steps).
  const spec::AnalysisReport plain = AnalyzeSpatialScene(scene, p);
  EXPECT_TRUE(plain.ok()) << plain.failure.reason;
  for (const std::string& name : outputs) {
    const std::vector<double>& a = scene_text::Series(result.report, name);
    const std::vector<double>& b = scene_text::Series(plain, name);
    EXPECT_EQ(a.size(), b.size());
    if (a.size() != b.size()) return {INFINITY, INFINITY};
    for (size_t t = 0; t < a.size(); ++t) EXPECT_NEAR(a[t], b[t], 1e4 * scene.integrator.relative_tolerance * (1.0 + std::abs(b[t]))) << name;
  }
  Agreement overall;
  for (size_t i = 0; i < indices.size(); ++i) {
    const size_t k = static_cast<size_t>(indices[i]);
    const double h = kRelativeStep * std::abs(p[k]);
    std::vector<double> plus = p, minus = p;
    plus[k] += h;
    minus[k] -= h;
    const spec::AnalysisReport up = AnalyzeSpatialScene(scene, plus), down = AnalyzeSpatialScene(scene, minus);
    EXPECT_TRUE(up.ok() && down.ok()) << up.failure.reason << down.failure.reason;
    if (!up.ok() || !down.ok()) return {INFINITY, INFINITY};
    for (const std::string& name : outputs) {
      size_t o = 0;
      while (o < scene.outputs.size() && scene.outputs[o].name != name) ++o;
      EXPECT_LT(o, scene.outputs.size()) << name;
      if (o == scene.outputs.size()) return {INFINITY, INFINITY};
      const std::vector<double>& d = result.output_derivatives[i][o];
      const std::vector<double>&u = scene_text::Series(up, name), &w = scene_text::Series(down, name);
      EXPECT_EQ(d.size(), u.size());
      double scale = 0.0, difference = 0.0;
      for (size_t t = 0; t < d.size() && t < u.size(); ++t) {
        const double fd = (u[t] - w[t]) / (2 * h);
        scale = std::max(scale, std::abs(fd));
        difference = std::max(difference, std::abs(d[t] - fd));
      }
      if (scale < kNoDependence) {
        // The output does not depend on the parameter (a position of a
        // driven mechanism on a mass): the simulator must say so too.
        EXPECT_LT(difference, kNoDependence) << parameters[i] << " -> " << name;
        std::cout << parameters[i] << " -> " << name << ": independent (difference " << difference << ")\n";
        continue;
      }
      const bool reaction = std::find(reactions.begin(), reactions.end(), name) != reactions.end();
      Agreement& agreement = reaction ? *reaction_agreement : overall;
      agreement.worst_series = std::max(agreement.worst_series, difference / scale);
      const std::vector<double>& values = scene_text::Series(result.report, name);
      const double peak_fd = (u[ArgMax(u)] - w[ArgMax(w)]) / (2 * h);
      const double peak = d[ArgMax(values)];
      const double peak_difference = std::abs(peak - peak_fd) / scale;
      agreement.worst_peak = std::max(agreement.worst_peak, peak_difference);
      std::cout << parameters[i] << " -> " << name << ": max |d| " << scale << ", difference " << difference
                << " (" << difference / scale << " relative); peak " << peak << " vs " << peak_fd << " ("
                << peak_difference << " relative)\n";
    }
  }
  return overall;
}

}  // namespace mbopt::spatial::sensitivity_testing
