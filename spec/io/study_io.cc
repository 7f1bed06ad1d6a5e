#include "spec/io/study_io.h"

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/util/json_util.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "common/status_macros.h"
#include "spec/io/fmu_archive_contents.h"
#include "spec/io/locator.h"
#include "spec/io/scene_convert.h"
#include "spec/io/study_convert.h"
#include "spec/io/utf8_check.h"
#include "spec/io/parse_hints.h"
#include "spec/limits.h"

namespace mbopt::spec::io {
namespace {

// ParseSceneText, with a relative FMU path taken from `fmu_folder` if set.
absl::StatusOr<Scene> ParseSceneTextFrom(const std::string& text, const std::string& source_name,
                                         const std::optional<std::filesystem::path>& fmu_folder);

using google::protobuf::TextFormat;

class CollectErrors : public google::protobuf::io::ErrorCollector {
 public:
  explicit CollectErrors(std::string file) : file_(std::move(file)) {}
  void AddError(int line, google::protobuf::io::ColumnNumber column,
                const std::string& message) override {
    messages_.push_back(Format(line, column, WithParseHint(message)));
  }
  void AddWarning(int line, google::protobuf::io::ColumnNumber column,
                  const std::string& message) override {
    messages_.push_back(Format(line, column, absl::StrCat("warning: ", message)));
  }
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  std::string Format(int line, int column, const std::string& message) const {
    if (line < 0) return absl::StrCat(file_, ": ", message);
    return absl::StrCat(file_, ":", line + 1, ":", column + 1, ": ", message);
  }
  std::string file_;
  std::vector<std::string> messages_;
};

absl::StatusOr<std::string> ReadFile(const std::string& path) {
  // A device or a FIFO (/dev/zero, a pipe) would be read forever, and a huge
  // file would be parsed into memory first: refuse both before reading.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) return absl::NotFoundError(absl::StrCat(path, ": cannot open file"));
  if (!std::filesystem::is_regular_file(status)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": not a regular file"));
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (!ec && size > static_cast<std::uintmax_t>(kMaxInputFileBytes)) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: %.1f MB, larger than the %d MB limit for study and scene files",
                                                      path, static_cast<double>(size) / (1 << 20),
                                                      static_cast<int>(kMaxInputFileBytes >> 20)));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open file"));
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) return absl::DataLossError(absl::StrCat(path, ": read error"));
  return content.str();
}

bool IsJson(const std::string& path) { return std::filesystem::path(path).extension() == ".json"; }

// Parses `text` (from `name`: JSON when it ends in ".json", else text
// format) into `message`; `tree` receives field locations (text only).
absl::Status ParseText(const std::string& text, const std::string& name, google::protobuf::Message* message,
                       TextFormat::ParseInfoTree* tree) {
  if (IsJson(name)) {
    google::protobuf::util::JsonParseOptions options;
    const auto status = google::protobuf::util::JsonStringToMessage(text, message, options);
    if (!status.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": not a valid ",
                                                     message->GetDescriptor()->name(),
                                                     " in JSON: ", WithParseHint(status.message().as_string())));
    }
    return absl::OkStatus();
  }
  CollectErrors collector(name);
  TextFormat::Parser parser;
  parser.RecordErrorsTo(&collector);
  parser.WriteLocationsTo(tree);
  if (!parser.ParseFromString(text, message) || !collector.messages().empty()) {
    std::string all = absl::StrJoin(collector.messages(), "\n");
    if (all.empty()) all = absl::StrCat(name, ": could not parse");
    return absl::InvalidArgumentError(all);
  }
  return absl::OkStatus();
}

absl::Status ParseFile(const std::string& path, google::protobuf::Message* message,
                       TextFormat::ParseInfoTree* tree) {
  MBOPT_ASSIGN_OR_RETURN(const std::string text, ReadFile(path));
  return ParseText(text, path, message, tree);
}

// A study file and its scene, parsed, with locations for both.
struct ParsedStudy {
  v1::Study study;
  TextFormat::ParseInfoTree study_tree;
  v1::Scene scene;  // from scene_file, or a copy of the inline one
  TextFormat::ParseInfoTree scene_file_tree;
  std::string scene_file;  // resolved path, empty if inline
};

// An FMU scene's relative `fmu.path` made absolute from `folder` (the scene
// file's), and the file's bytes put into `fmu.archive`, so that the study
// carries its FMU wherever it is sent (no worker needs the file); checked
// here, where a mistake is still the user's to fix (`scene_source` names
// the file in the message).
absl::Status AnchorFmuPath(const std::filesystem::path& folder, const std::string& scene_source, v1::Scene* scene) {
  if (!scene->has_fmu() || scene->fmu().path().empty()) return absl::OkStatus();
  // A study written back out with its FMU (a report analysing a job's
  // designs) already carries it: the file may be long gone.
  if (!scene->fmu().archive().empty()) return absl::OkStatus();
  std::filesystem::path fmu_path(scene->fmu().path());
  if (fmu_path.is_relative()) fmu_path = folder / fmu_path;
  fmu_path = fmu_path.lexically_normal();
  std::error_code code;
  if (!std::filesystem::is_regular_file(fmu_path, code)) {
    return absl::InvalidArgumentError(absl::StrCat(scene_source, ": fmu.path: no FMU file \"", fmu_path.string(),
                                                   "\" (", scene->fmu().path(),
                                                   " is taken from the scene file's folder)"));
  }
  scene->mutable_fmu()->set_path(fmu_path.string());
  absl::StatusOr<std::string> bytes = ReadFmuArchive(fmu_path);
  if (!bytes.ok()) return absl::InvalidArgumentError(absl::StrCat(scene_source, ": fmu.path: ", bytes.status().message()));
  scene->mutable_fmu()->set_archive(*std::move(bytes));
  return absl::OkStatus();
}

// Takes the scene of a parsed study: from its scene_file (resolved against
// the study's directory) unless `inline_only`, or inline.
absl::Status ResolveScene(const std::string& path, bool inline_only, ParsedStudy* parsed) {
  if (inline_only && parsed->study.scene_source_case() == v1::Study::kSceneFile) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": scene_file: the study must carry its scene inline here (a scene_file cannot be resolved)"));
  }
  switch (parsed->study.scene_source_case()) {
    case v1::Study::kSceneFile: {
      std::filesystem::path scene_path(parsed->study.scene_file());
      if (scene_path.is_relative()) {
        scene_path = std::filesystem::path(path).parent_path() / scene_path;
      }
      parsed->scene_file = scene_path.lexically_normal().string();
      absl::Status s = ParseFile(parsed->scene_file, &parsed->scene, &parsed->scene_file_tree);
      if (absl::IsNotFound(s)) {
        Where where(path, v1::Study::descriptor(), &parsed->study_tree);
        return absl::InvalidArgumentError(absl::StrCat(
            where.Describe("scene_file"), ": cannot open scene file \"", parsed->scene_file, "\""));
      }
      MBOPT_RETURN_IF_ERROR(s);
      return AnchorFmuPath(scene_path.parent_path(), parsed->scene_file, &parsed->scene);
    }
    case v1::Study::kScene:
      parsed->scene = parsed->study.scene();
      if (inline_only) return absl::OkStatus();
      return AnchorFmuPath(std::filesystem::path(path).parent_path(), path, &parsed->scene);
    case v1::Study::SCENE_SOURCE_NOT_SET:
      return absl::InvalidArgumentError(
          absl::StrCat(path,
                       ": scene_file or scene: missing: expected `scene_file: "
                       "\"name.scene.textproto\"` or an inline `scene { ... }`"));
  }
  return absl::OkStatus();
}

// A scene file given where a study is expected fails to parse at its first
// scene field; say what it is instead of naming that field.
absl::Status ParseStudy(const std::string& path, ParsedStudy* parsed) {
  if (absl::Status status = ParseFile(path, &parsed->study, &parsed->study_tree); !status.ok()) {
    v1::Scene scene;
    TextFormat::ParseInfoTree tree;
    if (status.code() == absl::StatusCode::kInvalidArgument && ParseFile(path, &scene, &tree).ok()) {
      return absl::InvalidArgumentError(absl::StrCat(
          path, ": this is a scene file, and a study is expected here: a study names its scene with scene_file: \"",
          std::filesystem::path(path).filename().string(),
          "\" and adds the variables, objective and limits (docs/study.md); `mbopt draw` takes the scene itself"));
    }
    return status;
  }
  return ResolveScene(path, /*inline_only=*/false, parsed);
}

absl::StatusOr<Study> ConvertParsed(const std::string& path, const ParsedStudy& parsed) {
  Errors errors;
  const Where study_where(path, v1::Study::descriptor(), &parsed.study_tree);
  const Where scene_where =
      parsed.scene_file.empty()
          ? study_where.Child("scene")
          : Where(parsed.scene_file, v1::Scene::descriptor(), &parsed.scene_file_tree);
  CheckUtf8Strings(parsed.study, study_where, &errors);  // an inline scene too
  CheckStringLengths(parsed.study, study_where, &errors);
  if (!parsed.scene_file.empty()) {
    CheckUtf8Strings(parsed.scene, scene_where, &errors);
    CheckStringLengths(parsed.scene, scene_where, &errors);
  }
  if (!errors.empty()) return errors.ToStatus();
  Scene scene = ConvertScene(parsed.scene, scene_where, &errors);
  if (!errors.empty()) return errors.ToStatus();
  Study study = ConvertStudy(parsed.study, std::move(scene), study_where, &errors);
  MBOPT_RETURN_IF_ERROR(errors.ToStatus());
  return study;
}

}  // namespace

absl::StatusOr<Scene> LoadSceneFile(const std::string& path) {
  MBOPT_ASSIGN_OR_RETURN(const std::string text, ReadFile(path));
  return ParseSceneTextFrom(text, path, std::filesystem::path(path).parent_path());
}

absl::StatusOr<Study> LoadStudyFile(const std::string& path) {
  ParsedStudy parsed;
  MBOPT_RETURN_IF_ERROR(ParseStudy(path, &parsed));
  return ConvertParsed(path, parsed);
}

namespace {

absl::StatusOr<v1::Study> Inlined(const std::string& path, const ParsedStudy& parsed) {
  MBOPT_RETURN_IF_ERROR(ConvertParsed(path, parsed).status());
  v1::Study inlined = parsed.study;
  *inlined.mutable_scene() = parsed.scene;  // replaces scene_file (oneof)
  return inlined;
}

}  // namespace

absl::StatusOr<v1::Study> ReadStudyProto(const std::string& path) {
  ParsedStudy parsed;
  MBOPT_RETURN_IF_ERROR(ParseStudy(path, &parsed));
  return Inlined(path, parsed);
}

absl::StatusOr<v1::Study> ParseStudyText(const std::string& text, const std::string& source_name) {
  ParsedStudy parsed;
  MBOPT_RETURN_IF_ERROR(ParseText(text, source_name, &parsed.study, &parsed.study_tree));
  MBOPT_RETURN_IF_ERROR(ResolveScene(source_name, /*inline_only=*/true, &parsed));
  return Inlined(source_name, parsed);
}

absl::StatusOr<Scene> ParseSceneText(const std::string& text, const std::string& source_name) {
  return ParseSceneTextFrom(text, source_name, std::nullopt);
}

namespace {

absl::StatusOr<Scene> ParseSceneTextFrom(const std::string& text, const std::string& source_name,
                                         const std::optional<std::filesystem::path>& fmu_folder) {
  v1::Scene message;
  TextFormat::ParseInfoTree tree;
  MBOPT_RETURN_IF_ERROR(ParseText(text, source_name, &message, &tree));
  if (fmu_folder.has_value()) MBOPT_RETURN_IF_ERROR(AnchorFmuPath(*fmu_folder, source_name, &message));
  Errors errors;
  const Where where(source_name, v1::Scene::descriptor(), &tree);
  CheckUtf8Strings(message, where, &errors);
  CheckStringLengths(message, where, &errors);
  if (!errors.empty()) return errors.ToStatus();
  Scene scene = ConvertScene(message, where, &errors);
  MBOPT_RETURN_IF_ERROR(errors.ToStatus());
  return scene;
}

}  // namespace

absl::StatusOr<Scene> SceneFromProto(const v1::Scene& message, const std::string& source_name) {
  Errors errors;
  const Where where(source_name, v1::Scene::descriptor(), nullptr);
  CheckStringLengths(message, where, &errors);
  if (!errors.empty()) return errors.ToStatus();
  Scene scene = ConvertScene(message, where, &errors);
  MBOPT_RETURN_IF_ERROR(errors.ToStatus());
  return scene;
}

absl::StatusOr<Study> StudyFromProto(const v1::Study& message, const std::string& source_name) {
  if (message.scene_source_case() != v1::Study::kScene) {
    return absl::InvalidArgumentError(
        absl::StrCat(source_name,
                     ": scene: missing: the study must carry its scene inline (a scene_file "
                     "cannot be resolved here)"));
  }
  Errors errors;
  const Where where(source_name, v1::Study::descriptor(), nullptr);
  CheckStringLengths(message, where, &errors);  // the inline scene too
  if (!errors.empty()) return errors.ToStatus();
  Scene scene = ConvertScene(message.scene(), where.Child("scene"), &errors);
  if (!errors.empty()) return errors.ToStatus();
  Study study = ConvertStudy(message, std::move(scene), where, &errors);
  MBOPT_RETURN_IF_ERROR(errors.ToStatus());
  return study;
}

}  // namespace mbopt::spec::io
