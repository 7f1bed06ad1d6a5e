// examples/andrews with an integrator block at rtol 1e-8, atol 1e-10, on
// the default path (IDAS) and on the explicit one, for the tests that hold
// the two paths to each other.
#pragma once

#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/testing/file_text.h"

namespace mbopt::multibody::testing {

struct ScenesOnBothPaths {
  spec::Scene idas;
  spec::Scene explicit_path;
};

// Fails the calling test when the example cannot be read or parsed.
inline std::optional<ScenesOnBothPaths> AndrewsOnBothPaths() {
  const std::string text = mbopt::testing::FileText("examples/andrews/andrews.scene.textproto");
  EXPECT_FALSE(text.empty());
  EXPECT_EQ(text.find("integrator {"), std::string::npos) << "the example now sets its own integrator";
  const std::string tolerances = " relative_tolerance: 1e-8 absolute_tolerance: 1e-10 }\n";
  absl::StatusOr<spec::Scene> bdf = spec::io::ParseSceneText(text + "integrator {" + tolerances, "andrews.textproto");
  absl::StatusOr<spec::Scene> erk = spec::io::ParseSceneText(
      text + "integrator { method: EXPLICIT_RUNGE_KUTTA" + tolerances, "andrews.textproto");
  EXPECT_TRUE(bdf.ok()) << bdf.status();
  EXPECT_TRUE(erk.ok()) << erk.status();
  if (text.empty() || !bdf.ok() || !erk.ok()) return std::nullopt;
  return ScenesOnBothPaths{*std::move(bdf), *std::move(erk)};
}

}  // namespace mbopt::multibody::testing
