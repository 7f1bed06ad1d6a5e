// `mbopt-worker eval`: output, --set semantics and exit codes.
#include "worker/main/eval_command.h"

#include "mbopt/v1/series.pb.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/spec/oscillator_scene.h"

namespace mbopt::worker {
namespace {

using ::testing::HasSubstr;

constexpr char kVehicle[] = "examples/vehicle/vehicle.study.textproto";

struct EvalRun {
  int code;
  std::string out, err;
};

EvalRun Eval(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int code = RunEval(args, out, err);
  return {code, out.str(), err.str()};
}

TEST(EvalCommand, TextReportShowsObjectiveWorstRowOutputsAndCounters) {
  const EvalRun r = Eval({kVehicle});
  EXPECT_EQ(r.code, kExitOk) << r.err;
  EXPECT_THAT(r.out, HasSubstr("formulation  dynamic"));
  EXPECT_THAT(r.out, HasSubstr("objective    8.448"));
  EXPECT_THAT(r.out, HasSubstr("m/s^2"));
  EXPECT_THAT(r.out, HasSubstr("worst row    s1@t=1.800s upper"));
  EXPECT_THAT(r.out, HasSubstr("seat_acceleration"));
  EXPECT_THAT(r.out, HasSubstr("counters     steps"));
}

// An external scene runs through the driver --drivers declares (the
// example's python3 simulator); the per-analysis folder and the default
// work directory are gone afterwards. Without drivers the analysis fails
// saying why.
TEST(EvalCommand, ExternalStudyRunsThroughTheDeclaredDriverAndLeavesNoFolders) {
  constexpr char kStudy[] = "examples/external/quarter_car.study.textproto";
  const EvalRun r = Eval({kStudy, "--drivers", "examples/external/quarter_car.drivers.textproto"});
  EXPECT_EQ(r.code, kExitOk) << r.err;
  EXPECT_THAT(r.out, HasSubstr("formulation  external"));
  EXPECT_THAT(r.out, HasSubstr("peak_acceleration"));
  const std::filesystem::path default_work =
      std::filesystem::temp_directory_path() / ("mbopt-runs-" + std::to_string(::getpid()));
  EXPECT_FALSE(std::filesystem::exists(default_work)) << default_work;

  const EvalRun without = Eval({kStudy});
  EXPECT_EQ(without.code, kExitAnalysisFailed);
  EXPECT_THAT(without.out, HasSubstr("runs no analysis drivers"));
  const EvalRun keep_alone = Eval({kStudy, "--keep-runs"});
  EXPECT_EQ(keep_alone.code, kExitBadInput);
  EXPECT_THAT(keep_alone.err, HasSubstr("--work-dir and --keep-runs need --drivers FILE"));
}

TEST(EvalCommand, JsonIsOneObjectWithTheRequiredKeys) {
  const EvalRun r = Eval({kVehicle, "--json"});
  EXPECT_EQ(r.code, kExitOk) << r.err;
  ASSERT_FALSE(r.out.empty());
  EXPECT_EQ(r.out.front(), '{');
  EXPECT_EQ(r.out.substr(r.out.size() - 2), "}\n");
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1);
  for (const char* key :
       {"\"objective\": ", "\"max_violation\": ", "\"status\": \"ok\"", "\"counters\": {",
        "\"formulation\": \"dynamic\"", "\"worst_constraint\": {"}) {
    EXPECT_THAT(r.out, HasSubstr(key));
  }
}

TEST(EvalCommand, SetAcceptsScaledVariablesAndParametersInTheirUnits) {
  // The report's optimum, with c2 = 2 x5 = 77.06 lbf s/in given as a parameter.
  const EvalRun r = Eval({kVehicle, "--set", "x1=5", "--set", "x2=10", "--set", "x3=10", "--set",
                          "x4=41.54", "--set", "c2=77.06", "--set=x6=40"});
  EXPECT_EQ(r.code, kExitOk) << r.err;
  EXPECT_THAT(r.out, HasSubstr("x5=38.53"));
  EXPECT_THAT(r.out, HasSubstr("objective    6.3957"));  // 251.80 in/s^2 = 6.3957 m/s^2
}

TEST(EvalCommand, BadInputIsExitCodeTwoWithAMessage) {
  EvalRun r = Eval({kVehicle, "--set", "x9=1"});
  EXPECT_EQ(r.code, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("\"x9\" is neither a design variable"));
  r = Eval({kVehicle, "--set", "x1=soft"});
  EXPECT_EQ(r.code, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("not a finite number"));
  r = Eval({});
  EXPECT_EQ(r.code, kExitBadInput);
  r = Eval({"no/such.study.textproto"});
  EXPECT_EQ(r.code, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("no/such.study.textproto"));
  r = Eval({kVehicle, "--frobnicate"});
  EXPECT_EQ(r.code, kExitBadInput);
}

// A parameter written as an expression follows the ones it reads; setting
// it alone would be ignored by every number computed from it, so it is
// refused.
TEST(EvalCommand, SetRefusesAParameterWrittenAsAnExpression) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "eval_derived_parameter";
  std::filesystem::create_directories(dir);
  std::string scene = ::mbopt::testing::kOscillatorScene;
  const std::string mass = "parameters { name: \"mass\" value: 2 unit: \"kg\" }\n";
  scene.insert(scene.find(mass) + mass.size(), "parameters { name: \"double_k\" expr: \"2 * k\" }\n");
  std::ofstream(dir / "oscillator.scene.textproto") << scene;
  const std::string study = (dir / "oscillator.study.textproto").string();
  std::ofstream(study) << R"pb(name: "derived"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
objective { minimize_max_of: "acc" reduction: REDUCTION_MAX_ABS }
)pb";
  const EvalRun r = Eval({study, "--set", "double_k=5"});
  EXPECT_EQ(r.code, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("parameter \"double_k\" is an expression of other parameters"));
  EXPECT_EQ(Eval({study, "--set", "k=50"}).code, kExitOk);
}

TEST(EvalCommand, FailedAnalysisIsExitCodeOneWithTheReason) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "eval_failed";
  std::filesystem::create_directories(dir);
  std::ifstream in("examples/vehicle/vehicle.scene.textproto");
  std::stringstream scene;
  scene << in.rdbuf();
  std::string text = scene.str();
  const std::string from = "integrator { relative_tolerance";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "integrator { max_steps: 5 relative_tolerance");
  std::ofstream(dir / "vehicle.scene.textproto") << text;
  std::ifstream study_in(kVehicle);
  std::stringstream study;
  study << study_in.rdbuf();
  std::ofstream(dir / "vehicle.study.textproto") << study.str();
  const EvalRun r = Eval({(dir / "vehicle.study.textproto").string(), "--json"});
  EXPECT_EQ(r.code, kExitAnalysisFailed);
  EXPECT_THAT(r.out, HasSubstr("\"status\": \"failed\""));
  EXPECT_THAT(r.out, HasSubstr("step budget"));
  EXPECT_THAT(r.out, HasSubstr("\"objective\": null"));
}

}  // namespace
}  // namespace mbopt::worker

namespace mbopt::worker {
namespace {

v1::AnalysisSeries ReadSeries(const std::string& path) {
  v1::AnalysisSeries series;
  std::ifstream file(path, std::ios::binary);
  EXPECT_TRUE(file && series.ParseFromIstream(&file)) << path;
  return series;
}

// --series-out: every output of every load case, then every response, in
// signal order with the grid's instants; a response is its expression of
// the outputs at every instant; a failed analysis writes its reason.
TEST(EvalCommand, SeriesOutHoldsEveryOutputAndResponse) {
  const std::string path = (std::filesystem::path(::testing::TempDir()) / "eval_series.pb").string();
  EvalRun r = Eval({"examples/vehicle/vehicle_worst_case.study.textproto", "--series-out", path});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  v1::AnalysisSeries series = ReadSeries(path);
  EXPECT_TRUE(series.failure().empty());
  ASSERT_EQ(series.signals_size(), 8);
  EXPECT_EQ(series.times_s_size(), 101);
  EXPECT_EQ(series.signals(0).name(), "seat_acceleration");
  EXPECT_EQ(series.signals(6).name(), "pitch_travel");
  const auto& s2 = series.signals(2).series(0).values_si();
  const auto& s3 = series.signals(3).series(0).values_si();
  const auto& pitch = series.signals(6).series(0).values_si();
  ASSERT_EQ(pitch.size(), 101);
  for (int i = 0; i < pitch.size(); ++i) EXPECT_EQ(pitch[i], s2[i] - s3[i]) << i;
  ASSERT_EQ(series.signals(7).series(0).values_si_size(), 1);  // k2 + k3: one value
  // The printed summary lists the responses after the outputs.
  EXPECT_THAT(r.out, HasSubstr("pitch_travel"));
  EXPECT_THAT(r.out, HasSubstr("axle_springs"));
  EXPECT_NEAR(series.signals(7).series(0).values_si(0), 600 * 175.126835, 1e-3);  // 600 lbf/in in N/m

  r = Eval({"examples/vehicle/vehicle_two_roads.study.textproto", "--series-out", path});
  ASSERT_EQ(r.code, kExitOk) << r.err;
  series = ReadSeries(path);
  ASSERT_EQ(series.signals_size(), 12);
  EXPECT_EQ(series.signals(6).name(), "fast.seat_acceleration");
  EXPECT_THAT(r.out, HasSubstr("fast.s1"));

  r = Eval({"examples/vehicle/vehicle_two_roads.study.textproto", "--set", "m1=-1", "--series-out", path});
  EXPECT_EQ(r.code, kExitAnalysisFailed);
  series = ReadSeries(path);
  EXPECT_THAT(series.failure(), HasSubstr("load case report: "));
  EXPECT_EQ(series.signals_size(), 0);
}

}  // namespace
}  // namespace mbopt::worker
