// Names a scene declares pass one check (spec/io/declared_name.h): each kind
// of name is refused when missing, reserved or declared twice, with the
// message that names its kind. Shown on the co-rotational four-bar example,
// whose bodies are flexible links.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "spec/io/study_io.h"

namespace mbopt::spec::io {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kScenePath[] = "examples/fourbar/fourbar_corotational.scene.textproto";

std::string Example() {
  std::ifstream in(kScenePath);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_FALSE(text.str().empty()) << kScenePath;
  return text.str();
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: \"" << from << "\" not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The errors of the scene text, one per line ("" if it loads).
std::string Errors(const std::string& text) {
  absl::StatusOr<Scene> scene = ParseSceneText(text, "fourbar.scene.textproto");
  return scene.ok() ? "" : std::string(scene.status().message());
}

TEST(DeclaredNames, TheExampleDeclaresEachNameOnce) { EXPECT_EQ(Errors(Example()), ""); }

TEST(DeclaredNames, ADuplicateIsNamedWithItsKind) {
  std::string text = Replace(Example(), "name: \"A\" kind", "name: \"O2\" kind");
  text = Replace(text, "name: \"stress_coupler\"", "name: \"stress_crank\"");
  text = Replace(text, "name: \"A2\"", "name: \"A1\"");
  const std::string errors = Errors(text);
  EXPECT_THAT(errors, HasSubstr("multibody.joints[1].name: duplicate joint name \"O2\""));
  EXPECT_THAT(errors, HasSubstr("outputs[1].name: duplicate output name \"stress_crank\""));
  EXPECT_THAT(errors, HasSubstr("parameters[1].name: duplicate parameter name \"A1\""));
}

TEST(DeclaredNames, FlexibleLinksShareTheBodiesNamesAndAvoidReservedOnes) {
  std::string text = Replace(Example(), "name: \"coupler\"", "name: \"crank\"");
  text = Replace(text, "name: \"rocker\"", "name: \"ground\"");
  const std::string errors = Errors(text);
  EXPECT_THAT(errors, HasSubstr("multibody.flexible_links[1].name: duplicate body or link name \"crank\""));
  EXPECT_THAT(errors, HasSubstr("multibody.flexible_links[2].name: a flexible link needs a name other than "
                                "\"ground\" and \"input\""));
  // "ground" is refused as reserved, not as a duplicate: it was declared once.
  EXPECT_THAT(errors, Not(HasSubstr("duplicate body or link name \"ground\"")));
}

TEST(DeclaredNames, AMissingNameSaysWhatNeedsOne) {
  const std::string errors = Errors(Replace(Example(), "name: \"O4\" kind", "name: \"\" kind"));
  EXPECT_THAT(errors, AllOf(HasSubstr("multibody.joints[3].name: a joint needs a name"),
                            Not(HasSubstr("duplicate joint name"))));
}

}  // namespace
}  // namespace mbopt::spec::io
