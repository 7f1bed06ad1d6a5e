// Opening FMUs: bad archives refused with what is wrong, parameters and
// outputs checked against the model description, the FMU's own messages in
// a failed run's reason, and the private folder removed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zip.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/fmu/closed_forms.h"
#include "tests/testing/temp_dir.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;
using testing::TestFmu;

class FmuArchive : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = dir_.path();
    // Unpacked FMUs go into their own folder, so that a test can see what is left.
    unpack_parent_ = folder_ / "unpacked";
    std::filesystem::create_directory(unpack_parent_);
  }

  // Writes a zip of (entry name, contents); `link_entry` is stored as a
  // symbolic link when not empty.
  std::filesystem::path WriteZip(const std::string& name, const std::vector<std::pair<std::string, std::string>>& entries,
                                 const std::string& link_entry = "") {
    const std::filesystem::path path = folder_ / name;
    int error = 0;
    zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
    EXPECT_NE(archive, nullptr);
    for (const auto& [entry, contents] : entries) {
      zip_source_t* source = zip_source_buffer(archive, contents.data(), contents.size(), 0);
      const zip_int64_t index = zip_file_add(archive, entry.c_str(), source, ZIP_FL_OVERWRITE);
      EXPECT_GE(index, 0) << zip_strerror(archive);
      if (entry == link_entry) {
        EXPECT_EQ(zip_file_set_external_attributes(archive, index, 0, ZIP_OPSYS_UNIX,
                                                   static_cast<zip_uint32_t>(S_IFLNK | 0777) << 16),
                  0);
      }
    }
    EXPECT_EQ(zip_close(archive), 0);
    return path;
  }

  static std::string ReadFile(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

  static std::string OscillatorDescription() {
    return ReadFile(std::filesystem::path(MBOPT_TEST_FMU_DIR) / "damped_oscillator" / "modelDescription.xml");
  }

  ::mbopt::testing::TempDir dir_;
  std::filesystem::path folder_;
  std::filesystem::path unpack_parent_;
};

TEST_F(FmuArchive, RefusesAnEntryThatClimbsOutOfTheFolder) {
  const auto path = WriteZip("climb.fmu", {{"modelDescription.xml", "x"}, {"resources/../../escaped.txt", "gotcha"}});
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("entry \"resources/../../escaped.txt\" would be written outside"));
  EXPECT_FALSE(std::filesystem::exists(folder_ / "escaped.txt"));
  EXPECT_FALSE(std::filesystem::exists(unpack_parent_ / "escaped.txt"));
}

TEST_F(FmuArchive, RefusesAnAbsoluteEntry) {
  const auto path = WriteZip("absolute.fmu", {{"/tmp/mbopt-fmu-absolute-entry", "gotcha"}});
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("would be written outside"));
}

TEST_F(FmuArchive, RefusesASymbolicLinkEntry) {
  const auto path = WriteZip("link.fmu", {{"modelDescription.xml", "x"}, {"resources/outside", "/etc"}},
                             "resources/outside");
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("entry \"resources/outside\" is a symbolic link"));
}

TEST_F(FmuArchive, SaysWhichEntriesThereAreWhenModelDescriptionIsMissing) {
  const auto path = WriteZip("bare.fmu", {{"binaries/linux64/m.so", "not a library"}});
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("bare.fmu: no modelDescription.xml at the archive's top level "
                                                "(entries: binaries/linux64/m.so)"));
}

TEST_F(FmuArchive, SaysWhichPlatformsThereAreWhenThisOneIsMissing) {
  const auto path = WriteZip("windows.fmu", {{"modelDescription.xml", OscillatorDescription()},
                                             {"binaries/win64/damped_oscillator.dll", "MZ"}});
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(),
              HasSubstr(std::string("no binary binaries/") + ThisPlatform() +
                        "/damped_oscillator.so for this platform (" + ThisPlatform() +
                        "); the archive has binaries for: win64"));
}

TEST_F(FmuArchive, NamesTheDescriptionFileInItsErrors) {
  const auto path = WriteZip("broken.fmu", {{"modelDescription.xml", "<fmiModelDescription fmiVersion=\"2.0\">\n<oops"}});
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("broken.fmu!modelDescription.xml:2: not well-formed XML"));
}

TEST_F(FmuArchive, RefusesAFileThatIsNoZip) {
  const std::filesystem::path path = folder_ / "text.fmu";
  std::ofstream(path) << "just text\n";
  auto fmu = Fmu::Open(path, Interface::kModelExchange, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("text.fmu: not a readable FMU (zip) archive"));
}

TEST_F(FmuArchive, RefusesAnInterfaceTheFmuDoesNotOffer) {
  auto fmu = Fmu::Open(TestFmu("bouncing_ball"), Interface::kCoSimulation, unpack_parent_);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("the FMU offers no Co-Simulation"));
}

TEST_F(FmuArchive, RemovesItsFolderWhenTheFmuGoes) {
  {
    auto fmu = Fmu::Open(TestFmu("damped_oscillator"), Interface::kModelExchange, unpack_parent_);
    ASSERT_TRUE(fmu.ok()) << fmu.status();
    EXPECT_FALSE(std::filesystem::is_empty(unpack_parent_));
  }
  EXPECT_TRUE(std::filesystem::is_empty(unpack_parent_));
}

TEST_F(FmuArchive, UnknownParameterIsRefusedWithTheParametersThatExist) {
  auto fmu = Fmu::Open(TestFmu("damped_oscillator"), Interface::kModelExchange, unpack_parent_);
  ASSERT_TRUE(fmu.ok()) << fmu.status();
  RunOptions options;
  options.parameters = {{"stiffnes_n_per_m", 5.0}};
  options.output_times_s = {0.0, 1.0};
  auto result = Simulate(*fmu, options);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(result.status().message(),
              HasSubstr("has no variable named \"stiffnes_n_per_m\"; its Real parameters are: mass_kg, "
                        "damping_n_s_per_m, stiffness_n_per_m, x0_m"));
}

TEST_F(FmuArchive, AVariableThatIsNoParameterCannotBeSet) {
  auto fmu = Fmu::Open(TestFmu("damped_oscillator"), Interface::kModelExchange, unpack_parent_);
  ASSERT_TRUE(fmu.ok()) << fmu.status();
  RunOptions options;
  options.parameters = {{"x_m", 0.5}};
  options.output_times_s = {1.0};
  auto result = Simulate(*fmu, options);
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.status().message(), HasSubstr("(causality output) that is not a Real parameter"));
}

TEST_F(FmuArchive, UnknownOutputIsRefusedWithTheVariablesThatExist) {
  auto fmu = Fmu::Open(TestFmu("van_der_pol"), Interface::kModelExchange, unpack_parent_);
  ASSERT_TRUE(fmu.ok()) << fmu.status();
  RunOptions options;
  options.outputs = {"x2"};
  options.output_times_s = {1.0};
  auto result = Simulate(*fmu, options);
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.status().message(),
              HasSubstr("named \"x2\" to output; its Real variables are: x0, x1, der(x0), der(x1), mu"));
}

TEST_F(FmuArchive, AModelErrorCarriesTheFmusMessage) {
  auto fmu = Fmu::Open(TestFmu("damped_oscillator"), Interface::kModelExchange, unpack_parent_);
  ASSERT_TRUE(fmu.ok()) << fmu.status();
  RunOptions options;
  options.parameters = {{"mass_kg", -1.0}};
  options.outputs = {"x_m"};
  options.output_times_s = {0.0, 1.0};
  auto result = Simulate(*fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->outcome, RunOutcome::kModelError);
  EXPECT_THAT(result->reason, HasSubstr("fmi2ExitInitializationMode returned fmi2Error at t = 0 s"));
  EXPECT_THAT(result->reason, HasSubstr("mass_kg must be > 0, got -1"));
}

}  // namespace
}  // namespace mbopt::fmu
