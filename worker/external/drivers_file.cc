#include "worker/external/drivers_file.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <set>
#include <system_error>

#include <google/protobuf/io/tokenizer.h>
#include <google/protobuf/text_format.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/read_file.h"
#include "mbopt/v1/drivers.pb.h"
#include "spec/io/locator.h"
#include "worker/external/input_template.h"
#include "worker/external/paths.h"

namespace mbopt::external {
namespace {

namespace fs = std::filesystem;
using google::protobuf::TextFormat;
using spec::io::Errors;
using spec::io::Where;

class CollectErrors : public google::protobuf::io::ErrorCollector {
 public:
  explicit CollectErrors(std::string file) : file_(std::move(file)) {}
  void AddError(int line, google::protobuf::io::ColumnNumber column, const std::string& message) override {
    messages_.push_back(absl::StrCat(file_, ":", line + 1, ":", column + 1, ": ", message));
  }
  const std::vector<std::string>& messages() const { return messages_; }

 private:
  std::string file_;
  std::vector<std::string> messages_;
};

bool IsIdentifier(const std::string& name) {
  if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
  for (const char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  }
  return true;
}

// A bare program name as execvp would find it, or "" when PATH has none.
std::string FindInPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return "";
  for (const auto& dir : absl::StrSplit(path, ':')) {
    if (dir.empty()) continue;  // the current directory is not a place to look for drivers
    const fs::path candidate = fs::path(std::string(dir)) / program;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && access(candidate.c_str(), X_OK) == 0) return candidate.string();
  }
  return "";
}

// Checks a declared path of the driver's directory (relative, no "..",
// present, inside with links resolved, and so every link below it).
void CheckDeclaredPath(const std::string& relative, const fs::path& base, const Where& where, const std::string& field,
                       int index, Errors* errors) {
  const absl::Status shape = CheckRelativePath(relative, absl::StrCat("\"", relative, "\""));
  if (!shape.ok()) {
    errors->Add(where, field, index, std::string(shape.message()));
    return;
  }
  const fs::path path = base / relative;
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec))) {
    errors->Add(where, field, index, absl::StrCat("\"", relative, "\" does not exist in ", base.string()));
    return;
  }
  if (!ResolvesInside(path, base)) {
    errors->Add(where, field, index,
                absl::StrCat("\"", relative, "\" is a link leading outside ", base.string()));
    return;
  }
  if (fs::is_directory(path, ec)) {
    for (auto it = fs::recursive_directory_iterator(path, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
      if (it->is_symlink(ec) && !ResolvesInside(it->path(), base)) {
        errors->Add(where, field, index,
                    absl::StrCat(it->path().string(), " is a link leading outside ", base.string()));
        return;
      }
    }
  }
}

// True when `relative` is one of `files` or lies below one of them.
bool IsDeclaredFile(const std::string& relative, const std::vector<std::string>& files) {
  for (const std::string& file : files) {
    if (relative == file || relative.rfind(file + "/", 0) == 0) return true;
  }
  return false;
}

DriverDeclaration Convert(const v1::AnalysisDriver& in, const fs::path& file_directory, const Where& where,
                          Errors* errors) {
  DriverDeclaration out;
  out.name = in.name();
  if (!IsSafeName(in.name())) {
    errors->Add(where, "name", absl::StrCat("\"", in.name(), "\": expected 1 to 100 letters, digits, '_', '-', '.' ",
                                           "(not starting with '.')"));
  }

  // The base directory first: every path below depends on it.
  fs::path base = in.directory().empty() ? file_directory : fs::path(in.directory());
  if (base.is_relative()) base = file_directory / base;
  std::error_code ec;
  base = fs::canonical(base, ec);
  if (ec || !fs::is_directory(base, ec)) {
    errors->Add(where, "directory", absl::StrCat("\"", in.directory(), "\" is not a directory"));
    return out;
  }
  out.base_directory = base;

  for (int i = 0; i < in.file_size(); ++i) {
    CheckDeclaredPath(in.file(i), base, where, "file", i, errors);
    out.files.push_back(in.file(i));
  }

  if (in.command_size() == 0) {
    errors->Add(where, "command", "missing; expected the program and its arguments");
  } else {
    out.command.assign(in.command().begin(), in.command().end());
    const std::string& program = in.command(0);
    if (program.rfind("./", 0) == 0) {
      if (!IsDeclaredFile(program.substr(2), out.files)) {
        errors->Add(where, "command", 0,
                    absl::StrCat("\"", program, "\" is not among the driver's files; a \"./\" program is ",
                                 "one of them, copied into the analysis folder"));
      }
    } else if (fs::path(program).is_absolute()) {
      if (access(program.c_str(), X_OK) != 0 || !fs::is_regular_file(program, ec)) {
        errors->Add(where, "command", 0, absl::StrCat("\"", program, "\" is not an executable file"));
      }
    } else if (program.find('/') == std::string::npos && !program.empty()) {
      const std::string found = FindInPath(program);
      if (found.empty()) {
        errors->Add(where, "command", 0, absl::StrCat("\"", program, "\" is not found in PATH"));
      } else {
        out.command[0] = found;
      }
    } else {
      errors->Add(where, "command", 0,
                  absl::StrCat("\"", program, "\": expected an absolute path, a program name found in PATH, or ",
                               "\"./file\" naming one of the driver's files"));
    }
  }

  std::set<std::string> parameters;
  for (int i = 0; i < in.parameter_size(); ++i) {
    if (!IsIdentifier(in.parameter(i))) {
      errors->Add(where, "parameter", i,
                  absl::StrCat("\"", in.parameter(i), "\": expected a letter or '_', then letters, digits, '_'"));
    } else if (!parameters.insert(in.parameter(i)).second) {
      errors->Add(where, "parameter", i, absl::StrCat("\"", in.parameter(i), "\" is declared twice"));
    }
    out.parameters.push_back(in.parameter(i));
  }

  if (!in.input_template().empty()) {
    Errors path_errors;
    CheckDeclaredPath(in.input_template(), base, where, "input_template", -1, &path_errors);
    if (!path_errors.empty()) {
      errors->AddRaw(std::string(path_errors.ToStatus().message()));
    } else {
      const fs::path template_path = base / in.input_template();
      absl::StatusOr<std::string> text = ReadWholeFile(template_path.string());
      if (!text.ok()) {
        errors->Add(where, "input_template", std::string(text.status().message()));
      } else {
        out.input_template_text = *std::move(text);
        out.input_template_source = template_path.string();
        for (const auto& [name, line] : TemplatePlaceholders(out.input_template_text)) {
          if (!parameters.contains(name)) {
            errors->AddRaw(absl::StrCat(template_path.string(), ":", line, ": placeholder {", name,
                                        "} is not a parameter of driver '", in.name(), "'; it declares: ",
                                        parameters.empty() ? "none" : absl::StrJoin(parameters, ", ")));
          }
        }
      }
    }
    if (in.input_file().empty()) {
      errors->Add(where, "input_file", "missing; expected where the filled template is written");
    }
  } else if (!in.input_file().empty()) {
    errors->Add(where, "input_template", "missing; input_file is set, expected the template that fills it");
  }
  if (!in.input_file().empty()) {
    const absl::Status shape = CheckRelativePath(in.input_file(), absl::StrCat("\"", in.input_file(), "\""));
    if (!shape.ok()) errors->Add(where, "input_file", std::string(shape.message()));
    out.input_file = in.input_file();
  }

  if (in.results_file().empty()) {
    errors->Add(where, "results_file", "missing; expected the file the driver writes its results to");
  } else {
    const absl::Status shape = CheckRelativePath(in.results_file(), absl::StrCat("\"", in.results_file(), "\""));
    if (!shape.ok()) errors->Add(where, "results_file", std::string(shape.message()));
    out.results_file = in.results_file();
  }
  switch (in.results_format()) {
    case v1::RESULTS_FORMAT_JSON:
      out.results_format = ResultsFormat::kJson;
      break;
    case v1::RESULTS_FORMAT_DAKOTA:
      out.results_format = ResultsFormat::kDakota;
      break;
    default:
      errors->Add(where, "results_format", "missing; expected RESULTS_FORMAT_JSON or RESULTS_FORMAT_DAKOTA");
  }

  if (!(in.timeout_s() > 0.0) || !std::isfinite(in.timeout_s())) {
    errors->Add(where, "timeout_s", absl::StrCat(in.timeout_s(), ": expected a time limit in seconds, > 0"));
  }
  out.timeout_s = in.timeout_s();
  if (in.success_exit_code_size() > 0) {
    out.success_exit_codes.clear();
    for (int i = 0; i < in.success_exit_code_size(); ++i) {
      const int code = in.success_exit_code(i);
      if (code < 0 || code > 255) {
        errors->Add(where, "success_exit_code", i, absl::StrCat(code, ": expected an exit code, 0 to 255"));
      }
      out.success_exit_codes.push_back(code);
    }
  }
  out.failure_marker = in.failure_marker();
  return out;
}

}  // namespace

absl::StatusOr<std::vector<DriverDeclaration>> ParseDriversText(const std::string& text,
                                                                const std::string& source_name) {
  v1::AnalysisDrivers message;
  TextFormat::ParseInfoTree tree;
  CollectErrors collector(source_name);
  TextFormat::Parser parser;
  parser.RecordErrorsTo(&collector);
  parser.WriteLocationsTo(&tree);
  if (!parser.ParseFromString(text, &message) || !collector.messages().empty()) {
    std::string all = absl::StrJoin(collector.messages(), "\n");
    if (all.empty()) all = absl::StrCat(source_name, ": could not parse");
    return absl::InvalidArgumentError(all);
  }
  std::error_code ec;
  fs::path file_directory = fs::absolute(fs::path(source_name), ec).parent_path();
  const Where root(source_name, message.GetDescriptor(), &tree);
  Errors errors;
  if (message.driver_size() == 0) errors.Add(root, "driver", "no driver declared");
  std::vector<DriverDeclaration> drivers;
  std::set<std::string> names;
  for (int i = 0; i < message.driver_size(); ++i) {
    const Where where = root.Child("driver", i);
    drivers.push_back(Convert(message.driver(i), file_directory, where, &errors));
    if (!names.insert(message.driver(i).name()).second) {
      errors.Add(where, "name", absl::StrCat("\"", message.driver(i).name(), "\" is declared twice"));
    }
  }
  if (!errors.empty()) return errors.ToStatus();
  return drivers;
}

absl::StatusOr<std::vector<DriverDeclaration>> LoadDriversFile(const std::string& path) {
  absl::StatusOr<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return text.status();
  return ParseDriversText(*text, path);
}

}  // namespace mbopt::external
