// Elastodynamic formulation: beam-element links on the rigid motion. With
// stiff links (E x 100) the elastic stresses must approach the kinetostatic
// ones (the quasi-static limit); failures are reported as data.
#include <algorithm>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/linkage/linkage_scenes.h"
#include "worker/multibody/linkage_analysis.h"

namespace mbopt {
namespace {

using linkage_testing::FourBarOptions;
using linkage_testing::FourBarScene;

const std::vector<double> kReportOptimum = {9.65e-4, 3.92e-4, 2.69e-4};

// With E x 100 the lowest link frequency is 10x higher (about 3300 rad/s
// against a crank speed of 31.4 rad/s): the dynamic amplification
// (omega / omega_1)^2 and the neglected second-order frame terms are ~1e-4,
// the axial force's P-delta moment N / P_euler ~1e-3 at most (the coupler
// reaches 10 % of its buckling load in tension at E),
// the start-up transient (5 % damping) has decayed to ~e^-50 by t = 0.3 s.
// The integrator tolerance (1e-6) and the moment recovery add less. So
// every nodal stress must agree with the rigid one to 0.2 % of the link's
// peak, and the peak itself to 0.15 % (measured: 5e-4 of the peak).
constexpr double kPointwiseFraction = 2e-3;
constexpr double kPeakFraction = 1.5e-3;

TEST(ElasticFourBar, StiffLinksApproachKinetostaticStresses) {
  const spec::AnalysisReport rigid = multibody::AnalyzeLinkageScene(FourBarScene(), kReportOptimum);
  ASSERT_TRUE(rigid.ok()) << rigid.failure.reason;
  FourBarOptions stiff;
  stiff.elements = 6;
  stiff.youngs_modulus_pa *= 100;
  stiff.rotary_inertia = false;
  stiff.damping = true;
  const spec::AnalysisReport elastic = multibody::AnalyzeLinkageScene(FourBarScene(stiff), kReportOptimum);
  ASSERT_TRUE(elastic.ok()) << elastic.failure.reason;
  EXPECT_EQ(elastic.formulation, spec::Formulation::kElastodynamic);
  EXPECT_GT(elastic.counters.time_steps, 0);
  EXPECT_GT(elastic.counters.rhs_evaluations, 0);
  for (size_t link = 0; link < 3; ++link) {
    const auto& r = rigid.outputs[link].series;
    const auto& e = elastic.outputs[link].series;
    ASSERT_EQ(e.size(), 7u);
    double peak_r = 0.0, peak_e = 0.0;
    for (size_t n = 0; n < 7; ++n) {
      for (double v : r[n]) peak_r = std::max(peak_r, std::abs(v));
      for (double v : e[n]) peak_e = std::max(peak_e, std::abs(v));
    }
    EXPECT_NEAR(peak_e, peak_r, kPeakFraction * peak_r) << "link " << link;
    for (size_t n = 0; n < 7; ++n) {
      for (size_t i = 0; i < 101; ++i) {
        EXPECT_NEAR(e[n][i], r[n][i], kPointwiseFraction * peak_r)
            << "link " << link << " node " << n << " instant " << i;
      }
    }
  }
  // Drive torque: the reaction at the clamped crank root.
  for (size_t i = 0; i < 101; ++i) {
    EXPECT_NEAR(elastic.outputs[4].series[0][i], rigid.outputs[4].series[0][i],
                kPointwiseFraction * 110.0)  // peak drive torque ~110 N m
        << "instant " << i;
  }
}

// Published: at the report's optimum all three links are at the allowable
// stress in its elastic model (section 4.3; benchmarks/fourbar_stress.md).
// Ours, with the benchmark's model (6 elements, rotary inertia, 5 %
// damping): 0.968 / 0.963 / 1.029 of the allowable. The report's own code is
// not available; its model differs from ours in details the report does not
// give (mass matrix, damping, how the axial force enters), so the check is
// 5 %. Without the axial force's geometric stiffness the coupler was 6 %
// over (1.061), which this test would catch.
constexpr double kReportAgreement = 0.05;

TEST(ElasticFourBar, ReportOptimumHasEveryLinkNearTheAllowableStress) {
  FourBarOptions report;
  report.elements = 6;
  report.rotary_inertia = true;
  report.damping = true;
  const spec::AnalysisReport elastic = multibody::AnalyzeLinkageScene(FourBarScene(report), kReportOptimum);
  ASSERT_TRUE(elastic.ok()) << elastic.failure.reason;
  for (size_t link = 0; link < 3; ++link) {
    double peak = 0.0;
    for (const auto& node : elastic.outputs[link].series) {
      for (double v : node) peak = std::max(peak, std::abs(v));
    }
    EXPECT_NEAR(peak / linkage_testing::kFourBarAllowablePa, 1.0, kReportAgreement) << "link " << link;
  }
}

// Same inputs, same outputs to the last bit: the Newton solver keeps no
// state that could leak from one analysis into the next.
TEST(ElasticFourBar, RepeatedAnalysesAreBitIdentical) {
  FourBarOptions o;
  o.elements = 6;
  o.rotary_inertia = true;
  o.damping = true;
  const spec::Scene scene = FourBarScene(o);
  const spec::AnalysisReport first = multibody::AnalyzeLinkageScene(scene, kReportOptimum);
  const spec::AnalysisReport second = multibody::AnalyzeLinkageScene(scene, kReportOptimum);
  ASSERT_TRUE(first.ok()) << first.failure.reason;
  ASSERT_TRUE(second.ok()) << second.failure.reason;
  EXPECT_EQ(first.counters.time_steps, second.counters.time_steps);
  ASSERT_EQ(first.outputs.size(), second.outputs.size());
  for (size_t k = 0; k < first.outputs.size(); ++k) {
    EXPECT_EQ(first.outputs[k].series, second.outputs[k].series) << "output " << k;
  }
}

TEST(ElasticFourBar, RigidLinkInFlexibleLinkageIsReported) {
  FourBarOptions o;
  o.elements = 6;
  spec::Scene scene = FourBarScene(o);
  std::get<spec::LinkageModel>(scene.model).links[2].flexible_elements = 0;
  const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, kReportOptimum);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(r.failure.reason, ::testing::HasSubstr("link 'rocker'"));
}

TEST(ElasticFourBar, IntegratorGivingUpIsAFailedAnalysisNamingTheTime) {
  FourBarOptions o;
  o.elements = 6;
  spec::Scene scene = FourBarScene(o);
  scene.integrator.max_steps = 50;  // far too few for 0.5 s
  const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, kReportOptimum);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kIntegrator);
  EXPECT_THAT(r.failure.reason, ::testing::HasSubstr("elastodynamic integration failed before t = 0.3 s"));
  EXPECT_TRUE(r.outputs.empty());
}

// A coupler of 0.2 cm^2 (8 % of the report's) is compressed past its Euler
// load by the mechanism's own inertia within 3 ms: with the geometric
// stiffness the linear response then grows without bound, which must end as
// a failed analysis that names the link, not as NaN stresses.
TEST(ElasticFourBar, LinkBucklingIsAFailedAnalysisNamingTheLink) {
  FourBarOptions o;
  o.elements = 6;
  o.rotary_inertia = true;
  o.damping = true;
  const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(FourBarScene(o), {1e-4, 2e-5, 2e-5});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kModelValidity);
  EXPECT_THAT(r.failure.reason, ::testing::HasSubstr("link 'coupler'"));
  EXPECT_THAT(r.failure.reason, ::testing::HasSubstr("Euler buckling load"));
  EXPECT_TRUE(r.outputs.empty());
}

TEST(ElasticFourBar, KinematicOutputsOfFlexibleLinkageNeedNoIntegration) {
  FourBarOptions o;
  o.elements = 6;
  spec::Scene scene = FourBarScene(o);
  scene.outputs = {linkage_testing::JointOutput("B_y", 2, spec::Axis::kY)};
  const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, kReportOptimum);
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  EXPECT_EQ(r.counters.time_steps, 0);
}

}  // namespace
}  // namespace mbopt
