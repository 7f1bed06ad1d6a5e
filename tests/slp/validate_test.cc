// SlpOptions::Validate and ProblemSpec::Validate reject bad values and say
// which field and value is wrong.
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "server/slp/options.h"
#include "server/slp/problem.h"
#include "tests/slp/test_problems.h"

namespace mbopt::slp::testing {
namespace {

void ExpectInvalid(const absl::Status& s, const std::string& needle) {
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << s;
  EXPECT_NE(std::string(s.message()).find(needle), std::string::npos) << s.message();
}

TEST(SlpOptionsValidate, DefaultsAreValid) { EXPECT_TRUE(SlpOptions{}.Validate().ok()); }

TEST(SlpOptionsValidate, RejectsNonPositiveOrNonFiniteValues) {
  SlpOptions o;
  o.initial_move_limit = 0;
  ExpectInvalid(o.Validate(), "initial_move_limit = 0");
  o = SlpOptions{};
  o.finite_difference_relative_step = std::numeric_limits<double>::quiet_NaN();
  ExpectInvalid(o.Validate(), "finite_difference_relative_step");
  o = SlpOptions{};
  o.infeasibility_penalty = -1;
  ExpectInvalid(o.Validate(), "infeasibility_penalty = -1");
}

TEST(SlpOptionsValidate, RejectsInconsistentMoveLimits) {
  SlpOptions o;
  o.initial_move_limit = 2.0;
  ExpectInvalid(o.Validate(), "initial_move_limit = 2");
  o = SlpOptions{};
  o.min_move_limit = 0.5;
  o.max_move_limit = 0.4;
  o.initial_move_limit = 0.45;
  ExpectInvalid(o.Validate(), "min_move_limit = 0.5 exceeds max_move_limit = 0.4");
}

TEST(SlpOptionsValidate, RejectsThresholdsOutOfOrder) {
  SlpOptions o;
  o.widen_max_approximation_error = 0.3;  // above narrow (0.25)
  ExpectInvalid(o.Validate(), "widen <= narrow <= reject");
  o = SlpOptions{};
  o.narrow_max_violation = 0.2;  // above reject (0.10)
  ExpectInvalid(o.Validate(), "violation thresholds");
}

TEST(SlpOptionsValidate, RejectsPositiveScreeningThresholdAndBadCounts) {
  SlpOptions o;
  o.screening_threshold = 0.1;
  ExpectInvalid(o.Validate(), "screening_threshold = 0.1");
  o = SlpOptions{};
  o.max_cycles = 0;
  ExpectInvalid(o.Validate(), "max_cycles = 0");
  o = SlpOptions{};
  o.max_rejections_per_cycle = 0;
  ExpectInvalid(o.Validate(), "max_rejections_per_cycle");
  o = SlpOptions{};
  o.finite_difference_relative_step = 0.5;
  ExpectInvalid(o.Validate(), "finite_difference_relative_step = 0.5");
}

TEST(ProblemSpecValidate, ReferenceProblemsAreValid) {
  EXPECT_TRUE(Hs43().spec.Validate().ok());
  EXPECT_TRUE(Cb2().spec.Validate().ok());
}

TEST(ProblemSpecValidate, RejectsBoundsAndInitialValues) {
  ProblemSpec s = Hs35().spec;
  s.lower[1] = 4;
  ExpectInvalid(s.Validate(), "variable 1 'x2' needs finite bounds lower < upper; got [4, 3]");
  s = Hs35().spec;
  s.upper[0] = std::numeric_limits<double>::infinity();
  ExpectInvalid(s.Validate(), "variable 0 'x1' needs finite bounds");
  s = Hs35().spec;
  s.initial[2] = -1;
  ExpectInvalid(s.Validate(), "variable 2 'x3' initial value -1 is outside its bounds [0, 3]");
}

TEST(ProblemSpecValidate, RejectsSizeMismatches) {
  ProblemSpec s = Hs35().spec;
  s.upper.resize(2);
  ExpectInvalid(s.Validate(), "one entry per variable");
  s = Hs35().spec;
  s.variable_names.pop_back();
  ExpectInvalid(s.Validate(), "2 variable names for 3 variables");
  s = Hs35().spec;
  s.constraint_scales.resize(0);
  ExpectInvalid(s.Validate(), "one entry per constraint row");
  s = ProblemSpec{};
  ExpectInvalid(s.Validate(), "no design variables");
}

TEST(ProblemSpecValidate, RejectsBadConstraintScalesAndObjectiveForms) {
  ProblemSpec s = Hs43().spec;
  s.constraint_scales[1] = 0;
  ExpectInvalid(s.Validate(), "constraint 1 'g2' scale must be finite and > 0; got 0");
  s = Hs43().spec;
  s.constraint_limits[2] = std::numeric_limits<double>::quiet_NaN();
  ExpectInvalid(s.Validate(), "constraint 2 'g3' limit is not finite");
  s = Hs43().spec;
  s.num_objective_terms = 2;
  ExpectInvalid(s.Validate(), "scalar objective has exactly 1 term");
  s = Cb2().spec;
  s.num_objective_terms = 0;
  ExpectInvalid(s.Validate(), "num_objective_terms = 0");
}

}  // namespace
}  // namespace mbopt::slp::testing
