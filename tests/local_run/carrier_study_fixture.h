// A test fixture for studies of the one-body carrier scene
// (tests/spec/oscillator_scene.h): a folder per test holding the scene, and
// a study written there and loaded as a user's file would be.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "absl/status/statusor.h"
#include "spec/io/study_io.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::testing {

class CarrierStudyTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::path(::testing::TempDir()) /
           (std::string(test->test_suite_name()) + "_" + test->name());
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "carrier.scene.textproto") << CarrierScene();
  }
  absl::StatusOr<spec::Study> Load(const std::string& text) {
    const std::string path = (dir_ / "carrier.study.textproto").string();
    std::ofstream(path) << text;
    return spec::io::LoadStudyFile(path);
  }
  std::filesystem::path dir_;
};

}  // namespace mbopt::testing
