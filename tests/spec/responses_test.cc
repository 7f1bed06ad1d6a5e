// Named responses, load cases and the min-max objective over several terms:
// what a study file makes of them (shapes, errors naming file, line and field), their
// values and their derivatives on hand-made series whose answers can be
// written down.
#include "spec/responses.h"

#include <filesystem>
#include <fstream>
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "spec/study_gradients.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::spec {
namespace {

using ::testing::HasSubstr;

constexpr double kExact = 1e-15;

// The oscillator: outputs x and acc on 11 instants from 0 to 1 s;
// parameters k = 100 N/m and mass = 2 kg.
const char* const kScene = ::mbopt::testing::kOscillatorScene;

const char kStudy[] = R"pb(name: "responses"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
responses { name: "energy" expr: "0.5 * k * x^2" }
responses { name: "design_sum" expr: "k + 10 * mass" unit: "N/m" }
responses { name: "ramp" expr: "x + 0.001 * t" unit: "m" }
responses { name: "twice" expr: "2 * energy" }
objective {
  minimize_max_over {
    terms { output: "acc" reduction: REDUCTION_MAX_ABS unit: "m/s^2" }
    terms { output: "energy" reduction: REDUCTION_RMS weight: 4 }
  }
}
constraints { name: "budget" output: "design_sum" reduction: REDUCTION_FINAL limit: 150 unit: "N/m" }
constraints { name: "ramp" output: "ramp" reduction: REDUCTION_MAX limit: 5 unit: "mm" }
)pb";

class Responses : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = std::filesystem::path(::testing::TempDir()) / ("responses_" + test);
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "oscillator.scene.textproto") << kScene;
  }
  absl::StatusOr<Study> Load(const std::string& study) {
    const std::string path = (dir_ / "oscillator.study.textproto").string();
    std::ofstream(path) << study;
    return io::LoadStudyFile(path);
  }
  std::string LoadError(const std::string& study) {
    absl::StatusOr<Study> loaded = Load(study);
    EXPECT_FALSE(loaded.ok());
    return loaded.ok() ? "" : std::string(loaded.status().message());
  }
  // kStudy loaded and laid out, with the responses of Outputs() at the
  // parameters' defaults (k = 100, mass = 2) appended to `signals`.
  struct Evaluated {
    Study study;
    StudyLayout layout;
    std::vector<Series> outputs, storage;
    std::vector<const Series*> signals;
    std::vector<double> parameters;
  };
  std::unique_ptr<Evaluated> Evaluate();
  std::filesystem::path dir_;
};

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: \"" << from << "\" not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// x(t_i) = 0.001 i, acc(t_i) = 10 - i.
std::vector<Series> Outputs() {
  Series x(1), acc(1);
  for (int i = 0; i <= 10; ++i) {
    x[0].push_back(0.001 * i);
    acc[0].push_back(10.0 - i);
  }
  return {x, acc};
}

std::unique_ptr<Responses::Evaluated> Responses::Evaluate() {
  absl::StatusOr<Study> study = Load(kStudy);
  EXPECT_TRUE(study.ok()) << study.status();
  if (!study.ok()) return nullptr;
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*study);
  EXPECT_TRUE(layout.ok()) << layout.status();
  if (!layout.ok()) return nullptr;
  auto e = std::make_unique<Evaluated>();
  e->study = *std::move(study);
  e->layout = *std::move(layout);
  e->outputs = Outputs();
  e->signals = {&e->outputs[0], &e->outputs[1]};
  e->parameters = e->study.scene.DefaultParameterValues();
  AppendResponses(e->study, e->layout, e->parameters, &e->storage, &e->signals);
  return e;
}

TEST_F(Responses, ShapesFollowWhatEachResponseReads) {
  absl::StatusOr<Study> study = Load(kStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->num_signals(), 6);
  EXPECT_EQ(study->SignalName(2), "energy");
  EXPECT_EQ(study->FindSignal("twice"), 5);
  EXPECT_EQ(study->responses[1].dimension, Dimension::kStiffness);
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  ASSERT_EQ(layout->outputs.size(), 6u);
  EXPECT_FALSE(layout->outputs[2].scalar);  // reads x
  EXPECT_EQ(layout->outputs[2].instants, 11);
  EXPECT_TRUE(layout->outputs[3].scalar);  // parameters only
  EXPECT_EQ(layout->outputs[3].instants, 1);
  EXPECT_FALSE(layout->outputs[4].scalar);
  EXPECT_FALSE(layout->outputs[5].scalar);  // through energy
  // The min-max objective: 2 terms per instant for MAX_ABS, one RMS term
  // weighing 4; the budget is one row, the ramp one per instant.
  EXPECT_EQ(layout->objective_form, ObjectiveForm::kMinMax);
  EXPECT_EQ(layout->num_objective_terms(), 23);
  ASSERT_EQ(layout->objective_term_factors.size(), 23u);
  EXPECT_EQ(layout->objective_term_factors[0], 1.0);
  EXPECT_EQ(layout->objective_term_factors[22], 4.0);
  EXPECT_EQ(layout->num_constraints(), 1 + 11);
  EXPECT_EQ(layout->rows[0].name, "budget upper");
  EXPECT_NEAR(layout->rows[1].limit_si, 5e-3, kExact);
}

TEST_F(Responses, ValuesAreTheExpressionsAtEveryInstant) {
  std::unique_ptr<Evaluated> e = Evaluate();
  ASSERT_NE(e, nullptr);
  const std::vector<const Series*>& signals = e->signals;
  ASSERT_EQ(signals.size(), 6u);
  for (int i = 0; i <= 10; ++i) {
    const double x = 0.001 * i;
    EXPECT_NEAR((*signals[2])[0][i], 0.5 * 100 * x * x, kExact) << i;
    EXPECT_NEAR((*signals[4])[0][i], x + 0.001 * (0.1 * i), kExact) << i;
    EXPECT_NEAR((*signals[5])[0][i], 2 * 0.5 * 100 * x * x, kExact) << i;
  }
  EXPECT_EQ((*signals[3])[0].size(), 1u);
  EXPECT_DOUBLE_EQ((*signals[3])[0][0], 120.0);

  absl::StatusOr<StudyValues> values = ComputeStudyValues(e->study, e->layout, signals);
  ASSERT_TRUE(values.ok()) << values.status();
  // max(|acc|) = 10 at t = 0; 4 x RMS(energy) is smaller.
  EXPECT_DOUBLE_EQ(values->objective, 10.0);
  EXPECT_DOUBLE_EQ(values->constraint_values[0], 120.0);
  EXPECT_NEAR(values->constraint_values[11], 0.011, kExact);  // ramp at t = 1
}

TEST_F(Responses, DerivativesFollowTheChainRuleThroughOutputsAndParameters) {
  std::unique_ptr<Evaluated> e = Evaluate();
  ASSERT_NE(e, nullptr);
  const Study* study = &e->study;
  const StudyLayout* layout = &e->layout;
  const std::vector<const Series*>& signals = e->signals;
  const std::vector<double>& parameters = e->parameters;
  // d x / d k = -1e-5 i, d acc / d k = 0.5.
  Series dx(1), dacc(1);
  for (int i = 0; i <= 10; ++i) {
    dx[0].push_back(-1e-5 * i);
    dacc[0].push_back(0.5);
  }
  std::vector<std::vector<const Series*>> derivatives = {{&dx, &dacc}};
  std::vector<std::vector<Series>> derivative_storage;
  AppendResponseDerivatives(*study, *layout, parameters, signals, &derivative_storage, &derivatives);
  ASSERT_EQ(derivatives[0].size(), 6u);
  for (int i = 0; i <= 10; ++i) {
    const double x = 0.001 * i, d = -1e-5 * i;
    // energy = k x^2 / 2: x^2 / 2 + k x dx.
    EXPECT_NEAR((*derivatives[0][2])[0][i], 0.5 * x * x + 100 * x * d, kExact) << i;
    EXPECT_NEAR((*derivatives[0][4])[0][i], d, kExact) << i;
    EXPECT_NEAR((*derivatives[0][5])[0][i], 2 * (0.5 * x * x + 100 * x * d), kExact) << i;
  }
  EXPECT_DOUBLE_EQ((*derivatives[0][3])[0][0], 1.0);  // d (k + 10 mass) / d k

  // Through the layout: the budget row's gradient in x1 is scale 10 x 1; the
  // largest objective term (|acc| at t = 0) moves with 10 x 0.5.
  absl::StatusOr<StudyGradients> gradients = ComputeStudyGradients(*study, *layout, signals, derivatives);
  ASSERT_TRUE(gradients.ok()) << gradients.status();
  EXPECT_DOUBLE_EQ(gradients->constraint_rows[0][0], 10.0);
  EXPECT_DOUBLE_EQ(gradients->objective_terms[0][0], 5.0);
  // The RMS term weighs 4: its gradient is 4 x the RMS's.
  std::vector<double> weights;
  RefValue(layout->objective_terms[22], (*signals[2])[0], layout->instants_s, &weights);
  double d_rms = 0.0;
  for (size_t k = 0; k < weights.size(); ++k) d_rms += weights[k] * (*derivatives[0][2])[0][k];
  EXPECT_NEAR(gradients->objective_terms[22][0], 4.0 * 10.0 * d_rms, 1e-12 * std::abs(40.0 * d_rms));
}

TEST_F(Responses, ReadsOfDifferentWidthsAreRefusedNamingTheResponse) {
  OutputShape one{1, 11, {"x"}, false}, five{5, 11, {"n0", "n1", "n2", "n3", "n4"}, false},
      four{4, 11, {"n0", "n1", "n2", "n3"}, false};
  absl::StatusOr<Study> study = Load(kStudy);
  ASSERT_TRUE(study.ok());
  // "energy" reads x (signal 0) and k: give x five series.
  absl::StatusOr<OutputShape> shape = ResponseShape(*study, 0, {five, one}, 11);
  ASSERT_TRUE(shape.ok());
  EXPECT_EQ(shape->series, 5);
  EXPECT_EQ(shape->series_labels[4], "n4");
  // "twice" reads energy (signal 2); with x at 4 series and energy at 5
  // there is no conflict in one read: build one that reads two signals.
  Study two = *study;
  Expression::Names names;
  names.find = [](const std::string& name) -> std::optional<int> {
    return name == "x" ? std::optional<int>(0) : name == "acc" ? std::optional<int>(1) : std::nullopt;
  };
  two.responses[0].expression = *Expression::Parse("x * acc", names);
  shape = ResponseShape(two, 0, {five, four}, 11);
  ASSERT_FALSE(shape.ok());
  EXPECT_THAT(shape.status().message(), HasSubstr("response \"energy\""));
}

TEST_F(Responses, BadResponsesAreNamedWithTheirLineAndField) {
  EXPECT_THAT(LoadError(Replace(kStudy, "0.5 * k * x^2", "0.5 * kk * x^2")),
              AllOf(HasSubstr("responses[0].expr"), HasSubstr("unknown output, response or parameter \"kk\""),
                    HasSubstr("did you mean x, k, t?")));
  EXPECT_THAT(LoadError(Replace(kStudy, "2 * energy", "2 * energy + later") +
                        "responses { name: \"later\" expr: \"x\" }\n"),
              HasSubstr("response \"later\" is defined later"));
  EXPECT_THAT(LoadError(Replace(kStudy, "name: \"ramp\" expr", "name: \"acc\" expr")),
              HasSubstr("\"acc\" is already an output of the scene"));
  EXPECT_THAT(LoadError(Replace(kStudy, "name: \"ramp\" expr", "name: \"mass\" expr")),
              HasSubstr("\"mass\" is already a parameter of the scene"));
  EXPECT_THAT(LoadError(Replace(kStudy, "limit: 5 unit: \"mm\"", "limit: 5 unit: \"N\"")),
              AllOf(HasSubstr("constraints[1].unit"), HasSubstr("the output is a length")));
  EXPECT_THAT(LoadError(Replace(kStudy, "unit: \"N/m\" }", "unit: \"furlong\" }")),
              HasSubstr("responses[1].unit"));
  EXPECT_THAT(LoadError(Replace(kStudy, "expr: \"x + 0.001 * t\"", "expr: \"\"")),
              HasSubstr("a response needs an expression"));
  const std::string at = ":4:";  // the line of responses[0]
  EXPECT_THAT(LoadError(Replace(kStudy, "0.5 * k * x^2", "0.5 * k * x^")), HasSubstr(at));
}

TEST_F(Responses, MaxOverTermsAreChecked) {
  EXPECT_THAT(LoadError(Replace(kStudy, "weight: 4", "weight: -4")),
              AllOf(HasSubstr("objective.minimize_max_over.terms[1].weight"), HasSubstr("more than 0")));
  EXPECT_THAT(LoadError(Replace(kStudy, "reduction: REDUCTION_RMS", "reduction: REDUCTION_MIN")),
              HasSubstr("objective.minimize_max_over.terms[1].reduction"));
  EXPECT_THAT(LoadError(Replace(kStudy, "unit: \"m/s^2\" }", "unit: \"mm\" }")),
              HasSubstr("objective.minimize_max_over.terms[0].unit"));
  EXPECT_THAT(LoadError(Replace(kStudy, "minimize_max_over {", "window { from_s: 0.5 } minimize_max_over {")),
              HasSubstr("each term has a window of its own"));
  EXPECT_THAT(LoadError(Replace(kStudy, "output: \"energy\" reduction", "output: \"nothing\" reduction")),
              AllOf(HasSubstr("unknown output \"nothing\""), HasSubstr("the study's responses: \"energy\"")));
}

const char kCases[] = R"pb(
cases { name: "soft" }
cases { name: "stiff_road" set { parameter: "mass" value: 3000 unit: "g" } }
)pb";

TEST_F(Responses, LoadCasesNameOutputsPerCaseAndSetTheirParameters) {
  std::string study = Replace(kStudy, "output: \"acc\" reduction", "output: \"stiff_road.acc\" reduction");
  study = Replace(study, "0.5 * k * x^2", "0.5 * k * (soft.x - stiff_road.x)^2");
  study = Replace(study, "x + 0.001 * t", "soft.x + 0.001 * t");
  absl::StatusOr<Study> loaded = Load(study + kCases);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_EQ(loaded->num_cases(), 2);
  EXPECT_EQ(loaded->num_case_signals(), 4);
  EXPECT_EQ(loaded->num_signals(), 8);
  EXPECT_EQ(loaded->SignalName(1), "soft.acc");
  EXPECT_EQ(loaded->SignalName(2), "stiff_road.x");
  EXPECT_EQ(loaded->SignalName(4), "energy");
  EXPECT_EQ(loaded->FindSignal("stiff_road.acc"), 3);
  const std::vector<double> design = loaded->ParameterValuesAt({12.0});
  EXPECT_EQ(loaded->CaseParameterValues(0, design), design);
  const std::vector<double> stiff = loaded->CaseParameterValues(1, design);
  EXPECT_DOUBLE_EQ(stiff[1], 3.0);  // 3000 g in kg
  EXPECT_DOUBLE_EQ(stiff[0], 120.0);
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*loaded);
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_EQ(layout->outputs.size(), 8u);
  EXPECT_EQ(layout->objective_terms[0].output, 3);
}

TEST_F(Responses, BadLoadCasesAreNamed) {
  std::string study = Replace(kStudy, "output: \"acc\" reduction", "output: \"soft.acc\" reduction");
  study = Replace(study, "0.5 * k * x^2", "0.5 * k * soft.x^2");
  study = Replace(study, "x + 0.001 * t", "soft.x + 0.001 * t");
  EXPECT_THAT(LoadError(study + Replace(kCases, "parameter: \"mass\"", "parameter: \"k\"")),
              AllOf(HasSubstr("cases[1].set[0].parameter"), HasSubstr("is set by a design variable")));
  EXPECT_THAT(LoadError(study + Replace(kCases, "parameter: \"mass\"", "parameter: \"nope\"")),
              HasSubstr("unknown scene parameter \"nope\""));
  EXPECT_THAT(LoadError(study + Replace(kCases, "unit: \"g\"", "unit: \"m\"")),
              AllOf(HasSubstr("cases[1].set[0].unit"), HasSubstr("is a length but parameter \"mass\" is a mass")));
  EXPECT_THAT(LoadError(study + Replace(kCases, "name: \"soft\"", "name: \"stiff_road\"")),
              HasSubstr("duplicate load case \"stiff_road\""));
  EXPECT_THAT(LoadError(study + Replace(kCases, "name: \"soft\"", "name: \"2soft\"")),
              HasSubstr("cases[0].name: \"2soft\" is not a name"));
  // Without a case prefix the output is unknown, and the message lists the
  // per-case names.
  EXPECT_THAT(LoadError(kStudy + std::string(kCases)),
              AllOf(HasSubstr("unknown output, response or parameter \"x\""), HasSubstr("soft.x")));
}

}  // namespace
}  // namespace mbopt::spec
