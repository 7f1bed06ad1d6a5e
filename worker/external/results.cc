#include "worker/external/results.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <string_view>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"

namespace mbopt::external {
namespace {

using nlohmann::json;

// The 1-based line and column of byte `offset` (0-based) of `text`.
std::string LineColumn(const std::string& text, std::size_t offset) {
  offset = std::min(offset, text.size());
  int line = 1;
  std::size_t line_start = 0;
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return absl::StrCat(line, ":", offset - line_start + 1);
}

const char* TypeName(const json& value) { return value.type_name(); }

absl::Status ReadNumber(const json& value, const std::string& source, const std::string& field, double* out) {
  if (!value.is_number()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": ", field, ": expected a number, got ", TypeName(value)));
  }
  *out = value.get<double>();
  return absl::OkStatus();
}

absl::Status ReadNumbers(const json& value, const std::string& source, const std::string& field,
                         std::vector<double>* out) {
  if (!value.is_array()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": ", field, ": expected an array of numbers, got ", TypeName(value)));
  }
  out->reserve(value.size());
  for (std::size_t i = 0; i < value.size(); ++i) {
    double x = 0.0;
    const absl::Status status = ReadNumber(value[i], source, absl::StrCat(field, "[", i, "]"), &x);
    if (!status.ok()) return status;
    out->push_back(x);
  }
  return absl::OkStatus();
}

}  // namespace

std::string ExternalResults::FirstNonFinite() const {
  for (const auto& [name, value] : values) {
    if (!std::isfinite(value)) return absl::StrCat("values.", name);
  }
  for (const auto& [name, numbers] : series) {
    for (std::size_t i = 0; i < numbers.size(); ++i) {
      if (!std::isfinite(numbers[i])) return absl::StrCat("series.", name, "[", i, "]");
    }
  }
  for (std::size_t i = 0; i < time_s.size(); ++i) {
    if (!std::isfinite(time_s[i])) return absl::StrCat("time[", i, "]");
  }
  return "";
}

absl::StatusOr<ExternalResults> ParseJsonResults(const std::string& text, const std::string& source) {
  json document;
  // A key given twice in one object would silently keep the last value:
  // found while parsing, reported once the syntax is known to be right.
  std::vector<std::set<std::string>> keys_of_open_objects;
  std::string duplicate;
  const json::parser_callback_t find_duplicates = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) {
      keys_of_open_objects.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      keys_of_open_objects.pop_back();
    } else if (event == json::parse_event_t::key && !keys_of_open_objects.empty() &&
               !keys_of_open_objects.back().insert(parsed.get<std::string>()).second && duplicate.empty()) {
      duplicate = parsed.get<std::string>();
    }
    return true;
  };
  // nlohmann reports syntax errors only as exceptions; they end here.
  try {
    document = json::parse(text, find_duplicates);
  } catch (const json::parse_error& error) {
    // error.byte is the 1-based offset of the character that failed.
    const std::size_t offset = error.byte > 0 ? error.byte - 1 : 0;
    std::string what = error.what();
    // Drop nlohmann's "[json.exception.parse_error.101] parse error at line 1, column 2: " prefix: the
    // position is ours.
    const std::size_t colon = what.find(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    return absl::InvalidArgumentError(
        absl::StrCat(source, ":", LineColumn(text, offset), ": not valid JSON: ", what));
  }
  if (!duplicate.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ": key \"", duplicate, "\" is given twice in one object"));
  }
  if (!document.is_object()) {
    return absl::InvalidArgumentError(
        absl::StrCat(source, ":1: expected a JSON object with \"values\", \"series\" and \"time\", got ",
                     TypeName(document)));
  }
  ExternalResults results;
  for (const auto& [key, value] : document.items()) {
    if (key == "values") {
      if (!value.is_object()) {
        return absl::InvalidArgumentError(
            absl::StrCat(source, ": values: expected an object of numbers, got ", TypeName(value)));
      }
      for (const auto& [name, number] : value.items()) {
        double x = 0.0;
        const absl::Status status = ReadNumber(number, source, absl::StrCat("values.", name), &x);
        if (!status.ok()) return status;
        results.values[name] = x;
      }
    } else if (key == "series") {
      if (!value.is_object()) {
        return absl::InvalidArgumentError(
            absl::StrCat(source, ": series: expected an object of arrays, got ", TypeName(value)));
      }
      for (const auto& [name, numbers] : value.items()) {
        const absl::Status status = ReadNumbers(numbers, source, absl::StrCat("series.", name),
                                                &results.series[name]);
        if (!status.ok()) return status;
      }
    } else if (key == "time") {
      const absl::Status status = ReadNumbers(value, source, "time", &results.time_s);
      if (!status.ok()) return status;
    } else {
      return absl::InvalidArgumentError(absl::StrCat(
          source, ": unknown key \"", key, "\"; expected \"values\", \"series\" or \"time\""));
    }
  }
  if (!results.time_s.empty()) {
    for (const auto& [name, numbers] : results.series) {
      if (numbers.size() != results.time_s.size()) {
        return absl::InvalidArgumentError(absl::StrCat(source, ": series.", name, " has ", numbers.size(),
                                                       " numbers; expected one per time, ",
                                                       results.time_s.size()));
      }
    }
  }
  return results;
}

absl::StatusOr<ExternalResults> ParseDakotaResults(const std::string& text, const std::string& source) {
  ExternalResults results;
  std::map<std::string, int> line_of;
  int line = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    ++line;
    std::string_view row(text.data() + start, end - start);
    start = end + 1;
    if (!row.empty() && row.back() == '\r') row.remove_suffix(1);
    // Split on spaces and tabs.
    std::vector<std::string_view> tokens;
    std::size_t i = 0;
    while (i < row.size()) {
      while (i < row.size() && (row[i] == ' ' || row[i] == '\t')) ++i;
      std::size_t j = i;
      while (j < row.size() && row[j] != ' ' && row[j] != '\t') ++j;
      if (j > i) tokens.push_back(row.substr(i, j - i));
      i = j;
    }
    if (tokens.empty()) continue;
    const std::string where = absl::StrCat(source, ":", line, ": ");
    if (tokens[0].front() == '[') {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "gradients and Hessians are not read; expected \"value name\""));
    }
    if (tokens.size() != 2) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "expected \"value name\" (two fields), got ", tokens.size(), " field(s)"));
    }
    double value = 0.0;
    std::string_view number = tokens[0];
    // from_chars takes no leading '+'; Dakota's writers may.
    if (number.size() > 1 && number.front() == '+') number.remove_prefix(1);
    const auto parsed = std::from_chars(number.data(), number.data() + number.size(), value);
    if (parsed.ec == std::errc::result_out_of_range) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "\"", std::string(tokens[0]), "\" is out of the range of a double"));
    }
    if (parsed.ec != std::errc() || parsed.ptr != number.data() + number.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "\"", std::string(tokens[0]), "\" is not a number; expected \"value name\""));
    }
    const std::string name(tokens[1]);
    const auto [it, inserted] = line_of.emplace(name, line);
    if (!inserted) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "\"", name, "\" is given twice (first on line ", it->second, ")"));
    }
    results.values[name] = value;
  }
  return results;
}

absl::StatusOr<ExternalResults> ParseResults(ResultsFormat format, const std::string& text,
                                             const std::string& source) {
  switch (format) {
    case ResultsFormat::kJson:
      return ParseJsonResults(text, source);
    case ResultsFormat::kDakota:
      return ParseDakotaResults(text, source);
  }
  return absl::InternalError("unknown results format");
}

}  // namespace mbopt::external
