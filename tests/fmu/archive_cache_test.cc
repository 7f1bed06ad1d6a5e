// FMUs a study carries: unpacked once per content into the worker's cache
// and opened from there by every later analysis, the cache private to its
// user, and an archive that cannot be unpacked named by its path.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <zip.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "spec/io/fmu_archive_contents.h"
#include "spec/io/study_io.h"
#include "tests/fmu/closed_forms.h"
#include "tests/testing/temp_dir.h"
#include "worker/fmu/archive_cache.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/scene_analysis.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;
using testing::TestFmu;

std::string ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

std::vector<std::string> Names(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

class FmuArchiveCache : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_ = dir_.path() / "cache";
    bytes_ = ReadBytes(TestFmu("damped_oscillator"));
    auto contents = spec::io::ReadFmuArchiveContents(bytes_);
    ASSERT_TRUE(contents.ok()) << contents.status();
    sha256_ = contents->sha256;
  }
  ::mbopt::testing::TempDir dir_;
  std::filesystem::path cache_;
  std::string bytes_, sha256_;
};

TEST_F(FmuArchiveCache, UnpacksEachContentOnceAndKeepsItWhenTheFmuGoes) {
  auto first = UnpackedArchiveFolder(bytes_, sha256_, "oscillator.fmu", cache_);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(*first, cache_ / sha256_);
  struct stat st {};
  ASSERT_EQ(stat(cache_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u) << "the cache is its user's alone";
  // A mark in the folder survives the second call: nothing was unpacked again.
  std::ofstream(*first / "mark") << "1";
  {
    auto fmu = Fmu::OpenUnpacked("oscillator.fmu", *first, Interface::kModelExchange);
    ASSERT_TRUE(fmu.ok()) << fmu.status();
    EXPECT_EQ(fmu->archive_path(), "oscillator.fmu");
  }
  auto second = UnpackedArchiveFolder(bytes_, sha256_, "oscillator.fmu", cache_);
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_EQ(*second, *first);
  EXPECT_TRUE(std::filesystem::exists(*second / "mark"));
  EXPECT_TRUE(std::filesystem::exists(*second / "modelDescription.xml"));
  // Nothing else is left in the cache: no incoming file, no half folder.
  EXPECT_EQ(Names(cache_), std::vector<std::string>{sha256_});
}

// The instances two loads of one cached folder make: the count each saw.
std::vector<double> InstancesSeenByTwoLoads(const std::filesystem::path& archive, const std::filesystem::path& cache) {
  const std::string bytes = ReadBytes(archive);
  auto contents = spec::io::ReadFmuArchiveContents(bytes);
  EXPECT_TRUE(contents.ok()) << contents.status();
  auto folder = UnpackedArchiveFolder(bytes, contents->sha256, archive.string(), cache);
  EXPECT_TRUE(folder.ok()) << folder.status();
  // Both loaded at once, as on a worker's two slots.
  auto first = Fmu::OpenUnpacked(archive, *folder, Interface::kModelExchange);
  auto second = Fmu::OpenUnpacked(archive, *folder, Interface::kModelExchange);
  EXPECT_TRUE(first.ok()) << first.status();
  EXPECT_TRUE(second.ok()) << second.status();
  RunOptions options;
  options.outputs = {"instances_seen"};
  options.output_times_s = {0.0, 1.0};
  std::vector<double> seen;
  for (const Fmu* fmu : {&*first, &*second}) {
    auto result = Simulate(*fmu, options);
    EXPECT_TRUE(result.ok()) << result.status();
    EXPECT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
    seen.push_back(result->values.at(0).at(1));
  }
  return seen;
}

TEST_F(FmuArchiveCache, AnFmuInstantiatedOnlyOncePerProcessGetsALibraryOfItsOwnOnEachLoad) {
  EXPECT_EQ(InstancesSeenByTwoLoads(TestFmu("instance_counter"), cache_), (std::vector<double>{1.0, 1.0}));
  // The private copies are gone once loaded: the folder is as unpacked.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(cache_)) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr(".instance-"))) << entry.path();
  }
  // Without the declaration both loads share one library, and its globals.
  EXPECT_EQ(InstancesSeenByTwoLoads(TestFmu("instance_counter_shared"), cache_), (std::vector<double>{1.0, 2.0}));
}

TEST_F(FmuArchiveCache, RefusesACacheOthersMayWriteInto) {
  std::filesystem::create_directory(cache_);
  std::filesystem::permissions(cache_, std::filesystem::perms::all);
  auto folder = UnpackedArchiveFolder(bytes_, sha256_, "oscillator.fmu", cache_);
  ASSERT_FALSE(folder.ok());
  EXPECT_EQ(folder.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(folder.status().message(), HasSubstr("only this user may use (mode 0700)"));
}

TEST_F(FmuArchiveCache, AnArchiveThatCannotBeUnpackedIsNamedByItsPathAndLeavesNothing) {
  auto folder = UnpackedArchiveFolder("not a zip", std::string(64, 'a'), "/models/broken.fmu", cache_);
  ASSERT_FALSE(folder.ok());
  EXPECT_THAT(std::string(folder.status().message()), StartsWith("/models/broken.fmu: not a readable FMU (zip) archive"));
  EXPECT_TRUE(Names(cache_).empty());
}

// What the cache saves: opening an FMU from its unpacked folder against
// unpacking it for every analysis (the figures in docs/status.md).
TEST_F(FmuArchiveCache, OpeningFromTheCacheSkipsTheUnpacking) {
  using Clock = std::chrono::steady_clock;
  auto median_ms = [](std::vector<double> ms) {
    std::sort(ms.begin(), ms.end());
    return ms[ms.size() / 2];
  };
  std::vector<double> unpacked_each_time, from_cache;
  const std::filesystem::path parent = dir_.path() / "unpacked";
  std::filesystem::create_directory(parent);
  for (int i = 0; i < 20; ++i) {
    const auto start = Clock::now();
    {
      auto fmu = Fmu::Open(TestFmu("damped_oscillator"), Interface::kModelExchange, parent);
      ASSERT_TRUE(fmu.ok()) << fmu.status();
    }
    unpacked_each_time.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  for (int i = 0; i < 20; ++i) {
    const auto start = Clock::now();
    {
      auto folder = UnpackedArchiveFolder(bytes_, sha256_, "oscillator.fmu", cache_);
      ASSERT_TRUE(folder.ok()) << folder.status();
      auto fmu = Fmu::OpenUnpacked("oscillator.fmu", *folder, Interface::kModelExchange);
      ASSERT_TRUE(fmu.ok()) << fmu.status();
    }
    from_cache.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  std::printf("opening and closing damped_oscillator.fmu (%zu bytes), median of 20: %.3f ms unpacked each time, "
              "%.3f ms from the cache (the first of which unpacked it)\n",
              bytes_.size(), median_ms(unpacked_each_time), median_ms(from_cache));
  EXPECT_TRUE(std::filesystem::is_empty(parent)) << "each unpacked copy went with its Fmu";
  EXPECT_EQ(Names(cache_), std::vector<std::string>{sha256_}) << "one unpacked copy for all twenty";
}

// A scene read from its file carries the FMU's bytes, their hash and
// platforms: a worker needs no file, and a deleted one changes nothing.
class CarriedFmu : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::create_directory(dir_.path() / "models");
    std::filesystem::copy_file(TestFmu("damped_oscillator"), dir_.path() / "models" / "oscillator.fmu");
  }
  std::string WriteScene(const std::string& fmu_path) {
    const std::filesystem::path path = dir_.path() / "s.scene.textproto";
    std::ofstream(path) << R"pb(
name: "s"
parameters { name: "stiffness" value: 9 unit: "N/m" }
fmu {
  path: ")pb" + fmu_path + R"pb("
  parameters { variable: "stiffness_n_per_m" value { param: "stiffness" } }
  parameters { variable: "damping_n_s_per_m" value { value: 0.5 } }
}
outputs { name: "position" fmu_variable { variable: "x_m" } }
time_grid { start_s: 0 end_s: 3 points: 31 }
integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-12 }
)pb";
    return path.string();
  }
  ::mbopt::testing::TempDir dir_;
};

TEST_F(CarriedFmu, TheSceneCarriesItsFmuSoTheAnalysisNeedsNoFile) {
  auto scene = spec::io::LoadSceneFile(WriteScene("models/oscillator.fmu"));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const auto* model = std::get_if<spec::FmuModel>(&scene->model);
  ASSERT_NE(model, nullptr);
  ASSERT_NE(model->archive, nullptr);
  EXPECT_EQ(*model->archive, ReadBytes(dir_.path() / "models" / "oscillator.fmu"));
  EXPECT_EQ(model->archive_sha256.size(), 64u);
  EXPECT_EQ(model->platforms, std::vector<std::string>{"linux64"});
  std::filesystem::remove_all(dir_.path() / "models");
  const spec::AnalysisReport report = AnalyzeFmuScene(*scene, {16.0}, nullptr);
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  const testing::DampedOscillator exact{1.0, 0.5, 16.0, 0.1};
  EXPECT_NEAR(report.outputs[0].series[0].back(), exact.X(3.0), 1e-8);
}

TEST_F(CarriedFmu, AFileThatIsNoFmuHasNoBinariesOrIsTooLargeToCarryIsNamedWhenTheSceneIsRead) {
  std::ofstream(dir_.path() / "models" / "junk.fmu") << "not a zip";
  auto scene = spec::io::LoadSceneFile(WriteScene("models/junk.fmu"));
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("fmu.archive: the bytes of "));
  EXPECT_THAT(scene.status().message(), HasSubstr("junk.fmu: not an FMU (zip) archive"));

  // A zip with a model description and no binary: no worker could load it.
  int error = 0;
  const std::filesystem::path empty = dir_.path() / "models" / "empty.fmu";
  zip_t* archive = zip_open(empty.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(archive, nullptr);
  const std::string text = "<fmiModelDescription/>";
  ASSERT_GE(zip_file_add(archive, "modelDescription.xml", zip_source_buffer(archive, text.data(), text.size(), 0), 0), 0);
  ASSERT_GE(zip_dir_add(archive, "binaries/linux64", 0), 0);
  ASSERT_EQ(zip_close(archive), 0);
  scene = spec::io::LoadSceneFile(WriteScene("models/empty.fmu"));
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(),
              HasSubstr("empty.fmu has no binaries (no binaries/<platform>/ folder holding a file): no worker can "
                        "load it"));

  // Sparse: 64 MiB and one byte take no room on the disk.
  std::filesystem::resize_file(dir_.path() / "models" / "junk.fmu", (std::uintmax_t{64} << 20) + 1);
  scene = spec::io::LoadSceneFile(WriteScene("models/junk.fmu"));
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("s.scene.textproto: fmu.path: "));
  EXPECT_THAT(scene.status().message(), HasSubstr("67108865 bytes; an FMU a study carries may have 64 MiB at most"));
}

TEST(FmuArchiveContents, ThePlatformsAreTheBinariesFoldersThatHoldAFile) {
  auto contents = spec::io::ReadFmuArchiveContents(ReadBytes(TestFmu("damped_oscillator")));
  ASSERT_TRUE(contents.ok()) << contents.status();
  EXPECT_EQ(contents->platforms, std::vector<std::string>{"linux64"});
  // The same bytes, the same hash; other bytes, another.
  auto again = spec::io::ReadFmuArchiveContents(ReadBytes(TestFmu("damped_oscillator")));
  auto other = spec::io::ReadFmuArchiveContents(ReadBytes(TestFmu("van_der_pol")));
  ASSERT_TRUE(again.ok() && other.ok());
  EXPECT_EQ(again->sha256, contents->sha256);
  EXPECT_NE(other->sha256, contents->sha256);
  EXPECT_EQ(contents->sha256.find_first_not_of("0123456789abcdef"), std::string::npos);
}

// Workers announce FMI 2.0's name of their platform; an FMI 3.0 binary for
// the same machine counts under it too, so such an FMU's tasks find them.
TEST(FmuArchiveContents, AnFmi3BinaryForX8664LinuxAlsoCountsAsLinux64) {
  auto contents = spec::io::ReadFmuArchiveContents(ReadBytes(TestFmu("bouncing_ball_fmi3")));
  ASSERT_TRUE(contents.ok()) << contents.status();
  EXPECT_EQ(contents->platforms, (std::vector<std::string>{"linux64", "x86_64-linux"}));
}

}  // namespace
}  // namespace mbopt::fmu
