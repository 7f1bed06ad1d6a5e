#include "worker/external/results.h"

#include <cmath>

#include <gtest/gtest.h>

namespace mbopt::external {
namespace {

bool Mentions(const absl::Status& status, const std::string& text) {
  return std::string(status.message()).find(text) != std::string::npos;
}

TEST(JsonResults, ReadsValuesSeriesAndTime) {
  const auto results = ParseJsonResults(
      R"({"values": {"peak_m": 0.25, "n": 3}, "series": {"x_m": [0, 0.5, 1e-3]}, "time": [0, 0.1, 0.2]})",
      "results.json");
  ASSERT_TRUE(results.ok()) << results.status();
  EXPECT_EQ(results->values.at("peak_m"), 0.25);
  EXPECT_EQ(results->values.at("n"), 3.0);
  EXPECT_EQ(results->series.at("x_m"), (std::vector<double>{0, 0.5, 1e-3}));
  EXPECT_EQ(results->time_s, (std::vector<double>{0, 0.1, 0.2}));
  EXPECT_EQ(results->FirstNonFinite(), "");
}

TEST(JsonResults, SyntaxErrorNamesFileLineAndColumn) {
  // Column 21 of line 2 is the '}' where a key was expected.
  const auto results = ParseJsonResults("{\n  \"values\": {\"a\": 1,}\n}\n", "results.json");
  ASSERT_FALSE(results.ok());
  EXPECT_EQ(results.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Mentions(results.status(), "results.json:2:21: not valid JSON")) << results.status();
}

TEST(JsonResults, WrongTypeNamesTheField) {
  const auto results = ParseJsonResults(R"({"series": {"y": [1, "two"]}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "r.json: series.y[1]: expected a number, got string")) << results.status();
}

TEST(JsonResults, UnknownKeyIsRefused) {
  const auto results = ParseJsonResults(R"({"value": {"a": 1}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "unknown key \"value\"")) << results.status();
}

TEST(JsonResults, AKeyGivenTwiceIsRefused) {
  const auto results = ParseJsonResults(R"({"values": {"a": 1, "b": 2, "a": 3}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "r.json: key \"a\" is given twice in one object")) << results.status();
  // The same name in two objects is no duplicate.
  EXPECT_TRUE(ParseJsonResults(R"({"values": {"a": 1}, "series": {"a": [1]}})", "r.json").ok());
}

TEST(JsonResults, SeriesMustMatchTime) {
  const auto results = ParseJsonResults(R"({"series": {"y": [1, 2]}, "time": [0, 1, 2]})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "series.y has 2 numbers; expected one per time, 3")) << results.status();
}

TEST(DakotaResults, ReadsValueNameLines) {
  const auto results = ParseDakotaResults("  1.5e+00 mass\n\n-2 f_2\r\n+3 g\n", "results.out");
  ASSERT_TRUE(results.ok()) << results.status();
  EXPECT_EQ(results->values.at("mass"), 1.5);
  EXPECT_EQ(results->values.at("f_2"), -2.0);
  EXPECT_EQ(results->values.at("g"), 3.0);
}

TEST(DakotaResults, ErrorsNameFileAndLine) {
  auto results = ParseDakotaResults("1 a\n1,5 b\n", "results.out");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:2: \"1,5\" is not a number")) << results.status();

  results = ParseDakotaResults("1 a\n2\n", "results.out");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:2: expected \"value name\"")) << results.status();

  results = ParseDakotaResults("1 a\n2 a\n", "results.out");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:2: \"a\" is given twice (first on line 1)")) << results.status();
}

TEST(JsonResults, ReadsGradientsOfValuesAndSeries) {
  const auto results = ParseJsonResults(
      R"({"values": {"f": 2}, "series": {"y": [0, 1]},
          "gradients": {"values": {"f": {"a": 0.5, "b": -1e-3}}, "series": {"y": {"a": [0, 2]}}}})",
      "results.json");
  ASSERT_TRUE(results.ok()) << results.status();
  EXPECT_EQ(results->value_gradients.at("f").at("a"), 0.5);
  EXPECT_EQ(results->value_gradients.at("f").at("b"), -1e-3);
  EXPECT_EQ(results->series_gradients.at("y").at("a"), (std::vector<double>{0, 2}));
  EXPECT_EQ(results->FirstNonFinite(), "");
}

TEST(JsonResults, GradientsMustBelongToGivenNumbersAndHaveTheirShape) {
  auto results = ParseJsonResults(R"({"values": {"f": 2}, "gradients": {"values": {"g": {"a": 1}}}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "r.json: gradients.values.g: the file gives no value \"g\""))
      << results.status();
  results = ParseJsonResults(R"({"series": {"y": [1, 2]}, "gradients": {"series": {"y": {"a": [1]}}}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "gradients.series.y.a has 1 numbers; expected one per number of series.y, 2"))
      << results.status();
  results = ParseJsonResults(R"({"values": {"f": 2}, "gradients": {"value": {}}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "unknown key \"gradients.value\"")) << results.status();
  results = ParseJsonResults(R"({"values": {"f": 2}, "gradients": {"values": {"f": {"a": "x"}}}})", "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "r.json: gradients.values.f.a: expected a number, got string"))
      << results.status();
}

// JSON has no NaN or infinity, and a number beyond a double's range is an
// error of the file (it used to escape the parser as an exception).
TEST(JsonResults, ANumberBeyondADoublesRangeNamesTheFile) {
  const auto results = ParseJsonResults(R"({"values": {"f": 2}, "gradients": {"values": {"f": {"a": 1e999}}}})",
                                        "r.json");
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "r.json: not valid JSON")) << results.status();
  EXPECT_TRUE(Mentions(results.status(), "1e999")) << results.status();
}

TEST(DakotaResults, NonFiniteGradientsAreReadAndFound) {
  const auto results = ParseDakotaResults("1 f\n[ 2 nan ]\n", "results.out", {"a", "b"});
  ASSERT_TRUE(results.ok()) << results.status();
  EXPECT_EQ(results->FirstNonFinite(), "gradients.values.f.b");
}

// Dakota's results file: the values, then one gradient line per value, its
// numbers in the order of the driver's parameters.
TEST(DakotaResults, ReadsGradientLinesInTheParametersOrder) {
  const auto results = ParseDakotaResults("1.5 f\n-2 g\n[ 1 2.5 ]\n[-3e-1 +4]\n", "results.out", {"a", "b"});
  ASSERT_TRUE(results.ok()) << results.status();
  EXPECT_EQ(results->values.at("f"), 1.5);
  EXPECT_EQ(results->value_gradients.at("f").at("a"), 1.0);
  EXPECT_EQ(results->value_gradients.at("f").at("b"), 2.5);
  EXPECT_EQ(results->value_gradients.at("g").at("a"), -0.3);
  EXPECT_EQ(results->value_gradients.at("g").at("b"), 4.0);
}

TEST(DakotaResults, GradientLineErrorsNameFileAndLine) {
  auto results = ParseDakotaResults("1 a\n[ 1 2 ]\n", "results.out", {"p"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:2: the gradient of \"a\" has 2 number(s); expected one per "
                                         "parameter of the driver, in their declared order (1: p)"))
      << results.status();
  results = ParseDakotaResults("1 a\n2 b\n[ 1 ]\n", "results.out", {"p"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out: 1 gradient line(s) for 2 values")) << results.status();
  results = ParseDakotaResults("1 a\n[ 1 ]\n[ 2 ]\n", "results.out", {"p"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:3: a gradient line beyond the 1 value(s)")) << results.status();
  results = ParseDakotaResults("1 a\n[ 1 ]\n2 b\n", "results.out", {"p"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:3: a \"value name\" line after the gradient lines"))
      << results.status();
  results = ParseDakotaResults("1 a\n[ 1 x ]\n", "results.out", {"p", "q"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:2: \"x\" is not a number")) << results.status();
  results = ParseDakotaResults("1 a\n[ 1 \n", "results.out", {"p"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:2: a gradient line must end with \"]\"")) << results.status();
  results = ParseDakotaResults("1 a\n[ 1 ]\n[[ 1 ]]\n", "results.out", {"p"});
  ASSERT_FALSE(results.ok());
  EXPECT_TRUE(Mentions(results.status(), "results.out:3: Hessians")) << results.status();
}

TEST(DakotaResults, NonFiniteNumbersAreReadAndFound) {
  const auto results = ParseDakotaResults("1 a\nnan b\n", "results.out");
  ASSERT_TRUE(results.ok()) << results.status();
  EXPECT_TRUE(std::isnan(results->values.at("b")));
  EXPECT_EQ(results->FirstNonFinite(), "values.b");
}

}  // namespace
}  // namespace mbopt::external
