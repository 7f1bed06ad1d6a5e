// Expressions for numbers: grammar, evaluation and errors.
#include "spec/expression.h"

#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace mbopt::spec {
namespace {

using ::testing::HasSubstr;

// Parameters a = 2, b = 3, wheelbase = 2.5, speed = 10 (SI).
const std::vector<std::string> kNames = {"a", "b", "wheelbase", "speed"};
const std::vector<double> kValues = {2.0, 3.0, 2.5, 10.0};

Expression::Names Names() {
  Expression::Names names;
  names.all = kNames;
  names.find = [](const std::string& name) -> std::optional<int> {
    for (size_t i = 0; i < kNames.size(); ++i) {
      if (kNames[i] == name) return static_cast<int>(i);
    }
    return std::nullopt;
  };
  return names;
}

double Eval(const std::string& text) {
  absl::StatusOr<std::shared_ptr<const Expression>> e = Expression::Parse(text, Names());
  EXPECT_TRUE(e.ok()) << text << ": " << e.status();
  return e.ok() ? (*e)->Evaluate(kValues) : NAN;
}

// Exact in binary floating point, or one rounding: 1e-15 relative.
constexpr double kRoundOff = 1e-15;

TEST(Expression, PrecedenceAndAssociativity) {
  EXPECT_EQ(Eval("1 + 2 * 3"), 7.0);
  EXPECT_EQ(Eval("(1 + 2) * 3"), 9.0);
  EXPECT_EQ(Eval("8 / 4 / 2"), 1.0);          // left-associative
  EXPECT_EQ(Eval("2 ^ 3 ^ 2"), 512.0);        // right-associative
  EXPECT_EQ(Eval("-2 ^ 2"), -4.0);            // the power binds tighter than unary minus
  EXPECT_EQ(Eval("2 * -3"), -6.0);
  EXPECT_EQ(Eval("a - b - 1"), -2.0);
  EXPECT_EQ(Eval("1e-3 * 1000"), 1.0);
}

TEST(Expression, ParametersFunctionsAndPi) {
  EXPECT_NEAR(Eval("wheelbase / speed"), 0.25, kRoundOff);
  EXPECT_NEAR(Eval("sqrt(a^2 + b^2)"), std::sqrt(13.0), kRoundOff);
  EXPECT_NEAR(Eval("atan2(b, a)"), std::atan2(3.0, 2.0), kRoundOff);
  EXPECT_NEAR(Eval("sin(pi / 6)"), 0.5, kRoundOff);
  EXPECT_EQ(Eval("max(a, b) - min(a, b)"), 1.0);
  EXPECT_EQ(Eval("pow(a, b)"), 8.0);
  EXPECT_NEAR(Eval("abs(-a) * cos(0) + exp(log(b))"), 5.0, 4 * kRoundOff);
  absl::StatusOr<std::shared_ptr<const Expression>> e = Expression::Parse("speed * a / speed", Names());
  ASSERT_TRUE(e.ok());
  EXPECT_EQ((*e)->parameters(), (std::vector<int>{0, 3}));
}

TEST(Expression, ErrorsNameTheColumnAndWhatWasExpected) {
  auto error = [](const std::string& text) {
    absl::StatusOr<std::shared_ptr<const Expression>> e = Expression::Parse(text, Names());
    EXPECT_FALSE(e.ok()) << text;
    return e.ok() ? std::string() : std::string(e.status().message());
  };
  EXPECT_THAT(error("1 +"), HasSubstr("column 4"));
  EXPECT_THAT(error("(a + b"), HasSubstr("expected ')'"));
  EXPECT_THAT(error("a b"), HasSubstr("column 3"));
  EXPECT_THAT(error("wheelbse / speed"), HasSubstr("unknown parameter \"wheelbse\" (did you mean wheelbase?)"));
  EXPECT_THAT(error("foo(a)"), HasSubstr("a function"));
  EXPECT_THAT(error("atan2(a)"), HasSubstr("atan2 takes 2 arguments"));
  EXPECT_THAT(error(""), HasSubstr("column 1"));
}

}  // namespace
}  // namespace mbopt::spec

namespace mbopt::spec {
namespace {

// The partials of EvaluateWithPartials against central differences of
// Evaluate, on expressions that use every operator and function: agreement
// to 1e-7 relative (the differences' own error at step 1e-6 is about 1e-10
// of these smooth functions' scale).
TEST(ExpressionPartials, AgreeWithCentralDifferences) {
  const std::vector<std::string> texts = {
      "a * b - a / b + 3",        "-a^2 + b^a",          "sqrt(a * b) + exp(a / b) - log(b)",
      "sin(a) * cos(b) + tan(a / 4)", "asin(a / 4) + acos(b / 4) + atan(a * b)",
      "atan2(a, b) + pow(a, b) + abs(a - b)", "max(a, b) + min(a * a, b)", "wheelbase / speed * a"};
  for (const std::string& text : texts) {
    absl::StatusOr<std::shared_ptr<const Expression>> e = Expression::Parse(text, Names());
    ASSERT_TRUE(e.ok()) << text << ": " << e.status();
    std::vector<double> partials;
    const double value = (*e)->EvaluateWithPartials(kValues, &partials);
    EXPECT_DOUBLE_EQ(value, (*e)->Evaluate(kValues)) << text;
    ASSERT_EQ(partials.size(), (*e)->parameters().size()) << text;
    for (size_t k = 0; k < partials.size(); ++k) {
      const size_t p = static_cast<size_t>((*e)->parameters()[k]);
      const double h = 1e-6 * std::max(1.0, std::abs(kValues[p]));
      std::vector<double> up = kValues, down = kValues;
      up[p] += h;
      down[p] -= h;
      const double difference = ((*e)->Evaluate(up) - (*e)->Evaluate(down)) / (2 * h);
      EXPECT_NEAR(partials[k], difference, 1e-7 * std::max(1.0, std::abs(difference)))
          << text << ", d/d" << kNames[p];
    }
  }
}

// A parameter that only enters where a derivative is infinite elsewhere
// (sqrt at 0 of a constant) has a partial of exactly what it contributes.
TEST(ExpressionPartials, ConstantSubexpressionsContributeNothing) {
  absl::StatusOr<std::shared_ptr<const Expression>> e = Expression::Parse("sqrt(0) + 2 * a + b^2", Names());
  ASSERT_TRUE(e.ok());
  std::vector<double> partials;
  EXPECT_DOUBLE_EQ((*e)->EvaluateWithPartials(kValues, &partials), 4.0 + 9.0);
  ASSERT_EQ(partials.size(), 2u);
  EXPECT_DOUBLE_EQ(partials[0], 2.0);
  EXPECT_DOUBLE_EQ(partials[1], 6.0);
}

// Nesting beyond what the fixed evaluation stack holds is refused when
// parsed, never a NaN at evaluation; a hostile depth is refused before the
// parser's own recursion could exhaust the machine's stack.
TEST(ExpressionLimits, DeepNestingIsRefusedAtParse) {
  std::string deep;
  for (int i = 0; i < 70; ++i) deep += "a + (";
  deep += "a";
  for (int i = 0; i < 70; ++i) deep += ")";
  absl::StatusOr<std::shared_ptr<const Expression>> e = Expression::Parse(deep, Names());
  ASSERT_FALSE(e.ok());
  EXPECT_THAT(e.status().message(), HasSubstr("nested too deeply"));
  const std::string hostile = std::string(200000, '(') + "a" + std::string(200000, ')');
  e = Expression::Parse(hostile, Names());
  ASSERT_FALSE(e.ok());
  EXPECT_THAT(e.status().message(), HasSubstr("less nesting"));
  e = Expression::Parse(std::string(200000, '-') + "a", Names());
  ASSERT_FALSE(e.ok());
}

}  // namespace
}  // namespace mbopt::spec
