#include "worker/external/drivers_file.h"

#include <gtest/gtest.h>

#include "tests/testing/temp_dir.h"

namespace mbopt::external {
namespace {

using ::mbopt::testing::TempDir;

bool Mentions(const absl::Status& status, const std::string& text) {
  return std::string(status.message()).find(text) != std::string::npos;
}

// A driver in `dir` with `extra` lines added to its declaration.
std::string DriverText(const std::string& extra) {
  return "driver {\n"
         "  name: \"spring\"\n"
         "  command: \"sh\"\n"
         "  command: \"run.sh\"\n" +
         extra +
         "  results_file: \"results.json\"\n"
         "  results_format: RESULTS_FORMAT_JSON\n"
         "  timeout_s: 30\n"
         "}\n";
}

TEST(DriversFile, ReadsADriverAndResolvesItsProgramInPath) {
  TempDir dir;
  dir.Write("run.sh", "exit 0\n");
  dir.Write("model/in.tmpl", "k = {k}\n");
  const auto path = dir.Write("w.drivers.textproto",
                              DriverText("  file: \"run.sh\"\n  file: \"model\"\n  parameter: \"k\"\n"
                                         "  input_template: \"model/in.tmpl\"\n  input_file: \"in.txt\"\n"
                                         "  success_exit_code: 0\n  success_exit_code: 2\n"
                                         "  failure_marker: \"FAILED\"\n"));
  const auto drivers = LoadDriversFile(path.string());
  ASSERT_TRUE(drivers.ok()) << drivers.status();
  ASSERT_EQ(drivers->size(), 1u);
  const DriverDeclaration& d = (*drivers)[0];
  EXPECT_EQ(d.name, "spring");
  EXPECT_TRUE(std::filesystem::path(d.command[0]).is_absolute()) << d.command[0];
  EXPECT_EQ(std::filesystem::path(d.command[0]).filename(), "sh");
  EXPECT_EQ(d.command[1], "run.sh");
  EXPECT_EQ(d.base_directory, dir.path());
  EXPECT_EQ(d.files, (std::vector<std::string>{"run.sh", "model"}));
  EXPECT_EQ(d.input_template_text, "k = {k}\n");
  EXPECT_EQ(d.input_file, "in.txt");
  EXPECT_EQ(d.results_format, ResultsFormat::kJson);
  EXPECT_EQ(d.timeout_s, 30.0);
  EXPECT_EQ(d.success_exit_codes, (std::vector<int>{0, 2}));
  EXPECT_EQ(d.failure_marker, "FAILED");
}

TEST(DriversFile, RefusesDotDotAndAbsolutePathsNamingLineAndField) {
  TempDir dir;
  dir.Write("run.sh", "exit 0\n");
  const auto path = dir.Write("w.drivers.textproto",
                              DriverText("  file: \"run.sh\"\n  file: \"../secret\"\n  file: \"/etc/passwd\"\n"));
  const auto drivers = LoadDriversFile(path.string());
  ASSERT_FALSE(drivers.ok());
  EXPECT_EQ(drivers.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Mentions(drivers.status(), "w.drivers.textproto:6:3: driver[0].file[1]: \"../secret\" contains \"..\""))
      << drivers.status();
  EXPECT_TRUE(Mentions(drivers.status(), "w.drivers.textproto:7:3: driver[0].file[2]: \"/etc/passwd\" is absolute"))
      << drivers.status();
}

TEST(DriversFile, RefusesALinkLeadingOutsideTheDirectory) {
  TempDir outside;
  outside.Write("secret", "x\n");
  TempDir dir;
  std::filesystem::create_directory_symlink(outside.path(), dir.path() / "data");
  std::filesystem::create_directories(dir.path() / "inputs");
  std::filesystem::create_symlink(outside.path() / "secret", dir.path() / "inputs" / "s");
  const auto path = dir.Write("w.drivers.textproto", DriverText("  file: \"data\"\n  file: \"inputs\"\n"));
  const auto drivers = LoadDriversFile(path.string());
  ASSERT_FALSE(drivers.ok());
  EXPECT_TRUE(Mentions(drivers.status(), "driver[0].file[0]: \"data\" is a link leading outside")) << drivers.status();
  EXPECT_TRUE(Mentions(drivers.status(), "driver[0].file[1]: " + (dir.path() / "inputs" / "s").string() +
                                             " is a link leading outside"))
      << drivers.status();
}

TEST(DriversFile, RefusesAPlaceholderThatIsNoParameter) {
  TempDir dir;
  dir.Write("in.tmpl", "k = {k}\nc = {damping}\n");
  const auto path = dir.Write("w.drivers.textproto",
                              DriverText("  parameter: \"k\"\n  input_template: \"in.tmpl\"\n  input_file: \"in\"\n"));
  const auto drivers = LoadDriversFile(path.string());
  ASSERT_FALSE(drivers.ok());
  EXPECT_TRUE(Mentions(drivers.status(), (dir.path() / "in.tmpl").string() +
                                             ":2: placeholder {damping} is not a parameter of driver 'spring'; it "
                                             "declares: k"))
      << drivers.status();
}

TEST(DriversFile, ReportsEveryMissingFieldAtOnce) {
  TempDir dir;
  const auto path = dir.Write("w.drivers.textproto",
                              "driver {\n  name: \"a/b\"\n  command: \"./run.sh\"\n  timeout_s: -1\n"
                              "  success_exit_code: 300\n}\n");
  const auto drivers = LoadDriversFile(path.string());
  ASSERT_FALSE(drivers.ok());
  for (const std::string expected :
       {"driver[0].name: \"a/b\": expected", "driver[0].command[0]: \"./run.sh\" is not among the driver's files",
        "driver[0].results_file: missing", "driver[0].results_format: missing", "driver[0].timeout_s: -1: expected",
        "driver[0].success_exit_code[0]: 300: expected an exit code"}) {
    EXPECT_TRUE(Mentions(drivers.status(), expected)) << expected << "\n" << drivers.status();
  }
}

TEST(DriversFile, SyntaxErrorNamesLine) {
  TempDir dir;
  const auto path = dir.Write("w.drivers.textproto", "driver {\n  name: \"a\"\n  comand: \"x\"\n}\n");
  const auto drivers = LoadDriversFile(path.string());
  ASSERT_FALSE(drivers.ok());
  EXPECT_TRUE(Mentions(drivers.status(), "w.drivers.textproto:3:")) << drivers.status();
  EXPECT_TRUE(Mentions(drivers.status(), "comand")) << drivers.status();
}

}  // namespace
}  // namespace mbopt::external
