// Simulator sensitivities of the vehicle study (examples/vehicle) against
// central finite differences of the same study values.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "mbopt/v1/study.pb.h"
#include "server/jobs/problem_from_study.h"
#include "tests/testing/local_run/local_run.h"
#include "spec/io/study_io.h"

namespace mbopt::local_run {
namespace {

constexpr char kVehicleStudy[] = "examples/vehicle/vehicle.study.textproto";
constexpr char kFourbarStudy[] = "examples/fourbar/fourbar_rigid.study.textproto";

// Central differences with this relative step on a tightly integrated model:
// truncation error ~ h^2, integration noise ~ tolerance / h, both far below
// the agreement asked for.
constexpr double kRelativeStep = 1e-5;
constexpr double kTightRelativeTolerance = 1e-11;
constexpr double kTightAbsoluteTolerance = 1e-14;
// Agreement, relative to the largest |derivative| of the same column:
// measured 1.9e-7, with CVODES' sensitivity module and with the augmented
// system alike; this leaves a factor of 5 for other platforms.
constexpr double kAgreement = 1e-6;

spec::Study TightVehicle() {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(kVehicleStudy);
  EXPECT_TRUE(study.ok()) << study.status();
  if (!study.ok()) return {};
  study->scene.integrator.relative_tolerance = kTightRelativeTolerance;
  study->scene.integrator.absolute_tolerance = kTightAbsoluteTolerance;
  study->scene.integrator.max_steps = 1'000'000;
  return *study;
}

Eigen::VectorXd Initial(const spec::Study& study) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(study.variables.size()));
  for (size_t k = 0; k < study.variables.size(); ++k) {
    x[static_cast<Eigen::Index>(k)] = study.variables[k].initial;
  }
  return x;
}

Eigen::VectorXd Stacked(const engine::StudyEvaluation& e) {
  const auto& v = *e.values;
  Eigen::VectorXd out(static_cast<Eigen::Index>(v.objective_terms.size() + v.constraint_values.size()));
  Eigen::Index i = 0;
  for (double t : v.objective_terms) out[i++] = t;
  for (double g : v.constraint_values) out[i++] = g;
  return out;
}

void ExpectGradientsMatchCentralDifferences(const spec::Study& study) {
  ASSERT_FALSE(study.variables.empty());
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const Eigen::VectorXd x0 = Initial(study);
  absl::StatusOr<engine::StudyEvaluation> with = EvaluateDesign(study, *layout, x0, true);
  ASSERT_TRUE(with.ok()) << with.status();
  ASSERT_TRUE(with->ok()) << with->failure.reason;
  ASSERT_TRUE(with->gradients.has_value()) << with->gradients_unavailable;
  const std::vector<std::vector<double>>& terms = with->gradients->objective_terms;
  const std::vector<std::vector<double>>& rows = with->gradients->constraint_rows;
  ASSERT_EQ(terms.size(), with->values->objective_terms.size());
  ASSERT_EQ(rows.size(), with->values->constraint_values.size());
  Eigen::MatrixXd simulator(static_cast<Eigen::Index>(terms.size() + rows.size()), x0.size());
  Eigen::Index r = 0;
  for (const auto* block : {&terms, &rows}) {
    for (const std::vector<double>& row : *block) {
      ASSERT_EQ(static_cast<Eigen::Index>(row.size()), x0.size());
      for (Eigen::Index c = 0; c < x0.size(); ++c) simulator(r, c) = row[static_cast<size_t>(c)];
      ++r;
    }
  }

  double worst = 0.0;
  for (Eigen::Index i = 0; i < x0.size(); ++i) {
    const double h = kRelativeStep * std::max(std::abs(x0[i]), 1.0);
    Eigen::VectorXd plus = x0, minus = x0;
    plus[i] += h;
    minus[i] -= h;
    absl::StatusOr<engine::StudyEvaluation> ep = EvaluateDesign(study, *layout, plus);
    absl::StatusOr<engine::StudyEvaluation> em = EvaluateDesign(study, *layout, minus);
    ASSERT_TRUE(ep.ok() && em.ok());
    ASSERT_TRUE(ep->ok() && em->ok());
    const Eigen::VectorXd fd = (Stacked(*ep) - Stacked(*em)) / (2 * h);
    const double magnitude = fd.cwiseAbs().maxCoeff();
    ASSERT_GT(magnitude, 0.0) << "variable " << i;
    const double disagreement = (simulator.col(i) - fd).cwiseAbs().maxCoeff() / magnitude;
    worst = std::max(worst, disagreement);
    EXPECT_LT(disagreement, kAgreement) << "variable " << study.variables[static_cast<size_t>(i)].name;
  }
  std::cout << "worst relative disagreement simulator vs central differences: " << worst << "\n";
}

TEST(SimulatorSensitivities, VehicleGradientsMatchCentralDifferences) {
  ExpectGradientsMatchCentralDifferences(TightVehicle());
}

// The chain rule through reductions over a window: ride comfort as the RMS
// seat acceleration from 0.5 s to 4 s, a mean and an integral of
// deflections, and a final value between two bounds.
TEST(SimulatorSensitivities, ReductionsOverAWindowMatchCentralDifferences) {
  spec::Study study = TightVehicle();
  ASSERT_GE(study.constraints.size(), 3u);
  study.objective.form = spec::Objective::Form::kMinimize;
  study.objective.reduction = spec::Reduction::kRms;
  study.objective.window = {0.5, 4.0};
  study.constraints[0].reduction = spec::Reduction::kMean;
  study.constraints[0].window = {1.0, std::nullopt};
  study.constraints[0].lower = -1.0;
  study.constraints[0].upper = 1.0;
  study.constraints[1].reduction = spec::Reduction::kIntegral;
  study.constraints[1].upper = 10.0;
  study.constraints[2].reduction = spec::Reduction::kFinal;
  study.constraints[2].lower = -1.0;
  study.constraints[2].upper = 1.0;
  study.constraints.resize(3);
  ExpectGradientsMatchCentralDifferences(study);
}

// The chain rule through a weighted sum of reduced outputs, one weight
// negative (a maximized term).
TEST(SimulatorSensitivities, WeightedSumMatchesCentralDifferences) {
  spec::Study study = TightVehicle();
  const int seat = study.scene.FindOutput("seat_acceleration");
  const int s1 = study.scene.FindOutput("s1");
  ASSERT_GE(seat, 0);
  ASSERT_GE(s1, 0);
  study.objective.form = spec::Objective::Form::kWeightedSum;
  spec::WeightedTerm rms;
  rms.output = seat;
  rms.reduction = spec::Reduction::kRms;
  rms.window = {0.5, std::nullopt};
  spec::WeightedTerm travel;
  travel.output = s1;
  travel.reduction = spec::Reduction::kRange;
  travel.weight = -0.5;
  travel.si_per_unit = 0.0254;  // in
  study.objective.sum_terms = {rms, travel};
  ExpectGradientsMatchCentralDifferences(study);
}

// The chain rule through named responses (of two outputs, of parameters
// only) and a min-max objective over several terms: the example
// vehicle_worst_case.study.textproto at tight tolerances.
TEST(SimulatorSensitivities, ResponsesAndMaxOverTermsMatchCentralDifferences) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_worst_case.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->responses.size(), 2u);
  study->scene.integrator.relative_tolerance = kTightRelativeTolerance;
  study->scene.integrator.absolute_tolerance = kTightAbsoluteTolerance;
  study->scene.integrator.max_steps = 1'000'000;
  ExpectGradientsMatchCentralDifferences(*study);
}

// One variable for both tyre stiffnesses (also_sets): its derivative is the
// sum of the two parameters' derivatives.
TEST(SimulatorSensitivities, VariableSettingTwoParametersMatchesCentralDifferences) {
  spec::Study study = TightVehicle();
  const int k3 = study.scene.FindParameter("k3");
  ASSERT_EQ(study.variables[2].parameter, k3);
  study.variables[1].also_sets = {k3};
  study.variables.erase(study.variables.begin() + 2);
  ExpectGradientsMatchCentralDifferences(study);
}

// A seat's absolute displacement and velocity (body_displacement,
// body_velocity) under constraints: their sensitivities are those of the
// coordinates and their rates.
TEST(SimulatorSensitivities, BodyDisplacementAndVelocityMatchCentralDifferences) {
  spec::Study study = TightVehicle();
  const auto& lumped = std::get<spec::LumpedModel>(study.scene.model);
  int seat = -1;
  for (size_t b = 0; b < lumped.bodies.size(); ++b) {
    if (lumped.bodies[b].name == "seat") seat = static_cast<int>(b);
  }
  ASSERT_GE(seat, 0);
  spec::BodyAccelerationOutput motion;
  motion.body = seat;
  motion.quantity = spec::BodyAccelerationOutput::Quantity::kDisplacement;
  study.scene.outputs.push_back({"seat_y", motion});
  motion.quantity = spec::BodyAccelerationOutput::Quantity::kVelocity;
  study.scene.outputs.push_back({"seat_v", motion});
  const int outputs = static_cast<int>(study.scene.outputs.size());
  spec::Constraint y;
  y.name = "seat_y";
  y.output = outputs - 2;
  y.reduction = spec::Reduction::kMaxAbs;
  y.limit = 0.05;
  spec::Constraint v = y;
  v.name = "seat_v";
  v.output = outputs - 1;
  v.limit = 1.0;
  study.constraints.push_back(y);
  study.constraints.push_back(v);
  ExpectGradientsMatchCentralDifferences(study);
}

// Two load cases: each case's sensitivities, in signal order.
TEST(SimulatorSensitivities, LoadCasesMatchCentralDifferences) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_two_roads.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  study->scene.integrator.relative_tolerance = kTightRelativeTolerance;
  study->scene.integrator.absolute_tolerance = kTightAbsoluteTolerance;
  study->scene.integrator.max_steps = 1'000'000;
  ExpectGradientsMatchCentralDifferences(*study);
}

TEST(SimulatorSensitivities, GradientsComeWithTheValuesOfAPlainAnalysis) {
  // The values of the sensitivity analysis are the plain analysis' values
  // up to the integration tolerance.
  const spec::Study study = TightVehicle();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const Eigen::VectorXd x0 = Initial(study);
  absl::StatusOr<engine::StudyEvaluation> with = EvaluateDesign(study, *layout, x0, true);
  absl::StatusOr<engine::StudyEvaluation> plain = EvaluateDesign(study, *layout, x0);
  ASSERT_TRUE(with.ok() && plain.ok());
  ASSERT_TRUE(with->ok() && plain->ok());
  const Eigen::VectorXd a = Stacked(*with), b = Stacked(*plain);
  constexpr double kValueAgreement = 1e-6;  // relative to max |value|; tolerances are 1e-11
  EXPECT_LT((a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(), kValueAgreement);
}

TEST(SimulatorSensitivities, LinkageStudyIsRejectedAtLoad) {
  absl::StatusOr<v1::Study> proto = spec::io::ReadStudyProto(kFourbarStudy);
  ASSERT_TRUE(proto.ok()) << proto.status();
  proto->mutable_optimizer()->set_sensitivity(v1::SENSITIVITY_METHOD_SIMULATOR);
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(*proto, kFourbarStudy);
  ASSERT_EQ(study.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(study.status().message().find("sensitivity"), std::string::npos) << study.status();
  EXPECT_NE(study.status().message().find("not available for this formulation"), std::string::npos);
}

TEST(SimulatorSensitivities, OptionsAskAnalysesForGradients) {
  absl::StatusOr<v1::Study> proto = spec::io::ReadStudyProto(kVehicleStudy);
  ASSERT_TRUE(proto.ok()) << proto.status();
  proto->mutable_optimizer()->set_sensitivity(v1::SENSITIVITY_METHOD_SIMULATOR);
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(*proto, kVehicleStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->optimizer.simulator_sensitivities);
  const absl::StatusOr<slp::SlpOptions> options = jobs::SlpOptionsFromStudy(*study);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_TRUE(options->analyses_provide_gradients);
}

}  // namespace
}  // namespace mbopt::local_run
