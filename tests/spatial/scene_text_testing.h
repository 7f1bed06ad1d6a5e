// Spatial scenes written as text in tests: loaded under a file label that
// loading errors name, and an analysis' series found by its output's name.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/io/study_io.h"
#include "spec/scene.h"

namespace mbopt::spatial::scene_text {

inline spec::Scene Load(const std::string& text, const char* file_label) {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(text, file_label);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : spec::Scene{};
}

inline std::string LoadError(const std::string& text, const char* file_label) {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(text, file_label);
  EXPECT_FALSE(scene.ok());
  return scene.ok() ? "" : std::string(scene.status().message());
}

inline const std::vector<double>& Series(const spec::AnalysisReport& r, const std::string& name) {
  for (const spec::OutputValues& o : r.outputs) {
    if (o.name == name) return o.series.at(0);
  }
  static const std::vector<double> none;
  ADD_FAILURE() << "no output " << name;
  return none;
}

}  // namespace mbopt::spatial::scene_text
