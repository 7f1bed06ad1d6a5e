// How the CLI shows a design: the optimizer's scaled variable and the scene
// parameter it sets are different numbers in different units, so a line must
// name both (x1 = 5 sets k1 = 50 lbf/in), and the JSON keeps the documented
// name -> physical value map beside the scaled values.
#include <string>

#include <gtest/gtest.h>

#include "client/job_format.h"

namespace mbopt {
namespace {

v1::GetJobResponse VehicleLikeJob() {
  v1::GetJobResponse job;
  auto* s = job.mutable_summary();
  s->set_job_id("j1");
  s->set_state(v1::JOB_STATE_CONVERGED);
  s->add_design_names("x1");
  s->add_design(50.0);  // k1 = 10 x1 lbf/in at x1 = 5
  s->add_design_units("lbf/in");
  auto* v = job.mutable_study()->add_variables();
  v->set_name("x1");
  v->set_parameter("k1");
  v->set_scale(10.0);
  return job;
}

TEST(DesignDisplay, SummaryShowsTheScaledVariableAndThePhysicalParameter) {
  const v1::GetJobResponse job = VehicleLikeJob();
  const std::string text = client::SummaryText(job.summary(), &job.study());
  EXPECT_NE(text.find("x1 = 5  (k1 = 50 lbf/in)"), std::string::npos) << text;
  EXPECT_NE(client::ResultsTable(job).find("x1 = 5  (k1 = 50 lbf/in)"), std::string::npos);
}

TEST(DesignDisplay, WithoutTheStudyTheValueIsNotPassedOffAsTheVariable) {
  const v1::GetJobResponse job = VehicleLikeJob();
  const std::string text = client::SummaryText(job.summary());
  EXPECT_NE(text.find("x1 sets its parameter to 50 lbf/in"), std::string::npos) << text;
  EXPECT_EQ(text.find("x1 = 50"), std::string::npos) << text;
}

// The members of the JSON object under "key": its text up to the closing brace.
std::string Members(const std::string& json, const std::string& key) {
  const auto begin = json.find("\"" + key + "\": {");
  if (begin == std::string::npos) return "";
  return json.substr(begin, json.find('}', begin) - begin);
}

TEST(DesignDisplay, JsonKeepsPhysicalDesignAndAddsScaledValuesAndParameters) {
  const std::string json = client::ResultsJson(VehicleLikeJob());
  EXPECT_NE(Members(json, "design").find("\"x1\": 50\n"), std::string::npos) << json;
  EXPECT_NE(Members(json, "design_scaled").find("\"x1\": 5\n"), std::string::npos) << json;
  EXPECT_NE(Members(json, "design_parameters").find("\"x1\": \"k1\""), std::string::npos) << json;
}

TEST(DesignDisplay, ZeroScaleMeansOne) {
  v1::GetJobResponse job = VehicleLikeJob();
  job.mutable_study()->mutable_variables(0)->set_scale(0.0);
  const std::string text = client::SummaryText(job.summary(), &job.study());
  EXPECT_NE(text.find("x1 = 50  (k1 = 50 lbf/in)"), std::string::npos) << text;
}

}  // namespace
}  // namespace mbopt
