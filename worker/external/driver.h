// An analysis driver as the worker runs it: an external simulation code
// declared by whoever runs the worker (drivers_file.h reads the declarations),
// never by a study. Plain data, validated when read; the runner (runner.h)
// trusts it.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mbopt::external {

enum class ResultsFormat {
  kJson,    // {"values": {...}, "series": {...}, "time": [...]}
  kDakota,  // one "value name" per line
};

struct DriverDeclaration {
  std::string name;
  // argv, no shell. argv[0] is absolute, or "./file" naming one of `files`
  // (run from the analysis folder).
  std::vector<std::string> command;
  // Absolute and canonical: every declared path lies inside it.
  std::filesystem::path base_directory;
  // Relative to base_directory; copied to the same relative place in the
  // analysis folder.
  std::vector<std::string> files;
  // The names a study may bind values to, and the only placeholders the
  // template may use.
  std::vector<std::string> parameters;
  // The template's text (read when the declaration was read) and where the
  // filled text is written in the analysis folder; no input file when
  // input_file is empty.
  std::string input_template_text;
  std::string input_template_source;  // for messages: the template's path
  std::string input_file;
  std::string results_file;  // relative to the analysis folder
  ResultsFormat results_format = ResultsFormat::kJson;
  double timeout_s = 0.0;
  std::vector<int> success_exit_codes = {0};
  std::string failure_marker;  // empty: none
};

}  // namespace mbopt::external
