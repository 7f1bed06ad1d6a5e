#include "worker/external/results.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>
#include <string_view>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

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

absl::Status ExpectObject(const json& value, const std::string& source, const std::string& field,
                          const char* of_what) {
  if (value.is_object()) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat(source, ": ", field, ": expected an object of ", of_what, ", got ", TypeName(value)));
}

// "gradients": {"values": {name: {parameter: number}}, "series": {name:
// {parameter: [numbers]}}}.
absl::Status ReadGradients(const json& value, const std::string& source, ExternalResults* results) {
  if (absl::Status s = ExpectObject(value, source, "gradients", "\"values\" and \"series\""); !s.ok()) return s;
  for (const auto& [key, of_kind] : value.items()) {
    const std::string field = absl::StrCat("gradients.", key);
    if (key != "values" && key != "series") {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": unknown key \"", field, "\"; expected \"values\" or \"series\""));
    }
    if (absl::Status s = ExpectObject(of_kind, source, field, "gradients by name"); !s.ok()) return s;
    for (const auto& [name, by_parameter] : of_kind.items()) {
      const std::string of_name = absl::StrCat(field, ".", name);
      if (absl::Status s = ExpectObject(by_parameter, source, of_name, "derivatives by parameter"); !s.ok()) {
        return s;
      }
      for (const auto& [parameter, derivative] : by_parameter.items()) {
        const std::string where = absl::StrCat(of_name, ".", parameter);
        absl::Status status;
        if (key == "values") {
          status = ReadNumber(derivative, source, where, &results->value_gradients[name][parameter]);
        } else {
          status = ReadNumbers(derivative, source, where, &results->series_gradients[name][parameter]);
        }
        if (!status.ok()) return status;
      }
    }
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
  for (const auto& [name, by_parameter] : value_gradients) {
    for (const auto& [parameter, value] : by_parameter) {
      if (!std::isfinite(value)) return absl::StrCat("gradients.values.", name, ".", parameter);
    }
  }
  for (const auto& [name, by_parameter] : series_gradients) {
    for (const auto& [parameter, numbers] : by_parameter) {
      for (std::size_t i = 0; i < numbers.size(); ++i) {
        if (!std::isfinite(numbers[i])) return absl::StrCat("gradients.series.", name, ".", parameter, "[", i, "]");
      }
    }
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
  } catch (const json::exception& error) {
    // A number out of a double's range (out_of_range.406), which names the
    // number but not where it is.
    std::string what = error.what();
    const std::size_t bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    return absl::InvalidArgumentError(absl::StrCat(source, ": not valid JSON: ", what));
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
    } else if (key == "gradients") {
      if (absl::Status status = ReadGradients(value, source, &results); !status.ok()) return status;
    } else {
      return absl::InvalidArgumentError(absl::StrCat(
          source, ": unknown key \"", key, "\"; expected \"values\", \"series\", \"time\" or \"gradients\""));
    }
  }
  // A gradient belongs to a number the file gives, and has its shape.
  for (const auto& [name, by_parameter] : results.value_gradients) {
    if (results.values.count(name) == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": gradients.values.", name, ": the file gives no value \"", name, "\""));
    }
  }
  for (const auto& [name, by_parameter] : results.series_gradients) {
    const auto series = results.series.find(name);
    if (series == results.series.end()) {
      return absl::InvalidArgumentError(
          absl::StrCat(source, ": gradients.series.", name, ": the file gives no series \"", name, "\""));
    }
    for (const auto& [parameter, numbers] : by_parameter) {
      if (numbers.size() != series->second.size()) {
        return absl::InvalidArgumentError(absl::StrCat(source, ": gradients.series.", name, ".", parameter, " has ",
                                                       numbers.size(), " numbers; expected one per number of series.",
                                                       name, ", ", series->second.size()));
      }
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

namespace {

std::vector<std::string_view> SplitOnBlanks(std::string_view row) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < row.size()) {
    while (i < row.size() && (row[i] == ' ' || row[i] == '\t')) ++i;
    std::size_t j = i;
    while (j < row.size() && row[j] != ' ' && row[j] != '\t') ++j;
    if (j > i) tokens.push_back(row.substr(i, j - i));
    i = j;
  }
  return tokens;
}

// `where` begins the message ("file:line: "); `expected` ends it.
absl::Status ParseDakotaNumber(std::string_view token, const std::string& where, const char* expected,
                               double* value) {
  std::string_view number = token;
  // from_chars takes no leading '+'; Dakota's writers may.
  if (number.size() > 1 && number.front() == '+') number.remove_prefix(1);
  const auto parsed = std::from_chars(number.data(), number.data() + number.size(), *value);
  if (parsed.ec == std::errc::result_out_of_range) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, "\"", std::string(token), "\" is out of the range of a double"));
  }
  if (parsed.ec != std::errc() || parsed.ptr != number.data() + number.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, "\"", std::string(token), "\" is not a number; expected ", expected));
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<ExternalResults> ParseDakotaResults(const std::string& text, const std::string& source,
                                                   const std::vector<std::string>& parameters) {
  ExternalResults results;
  std::map<std::string, int> line_of;
  std::vector<std::string> names_in_order;  // the gradient lines follow this order
  std::size_t gradient_lines = 0;
  int line = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    ++line;
    std::string_view row(text.data() + start, end - start);
    start = end + 1;
    if (!row.empty() && row.back() == '\r') row.remove_suffix(1);
    std::vector<std::string_view> tokens = SplitOnBlanks(row);
    if (tokens.empty()) continue;
    const std::string where = absl::StrCat(source, ":", line, ": ");
    if (tokens[0].front() == '[') {
      if (tokens[0].size() > 1 && tokens[0][1] == '[') {
        return absl::InvalidArgumentError(absl::StrCat(where, "Hessians (\"[[ ... ]]\") are not read"));
      }
      if (gradient_lines == names_in_order.size()) {
        return absl::InvalidArgumentError(absl::StrCat(where, "a gradient line beyond the ", names_in_order.size(),
                                                       " value(s) above it: one \"[ ... ]\" per value, in their order"));
      }
      // "[ 1 2 ]" and "[1 2]" alike: the brackets may touch the numbers.
      std::string_view inside = row.substr(row.find('[') + 1);
      const std::size_t close = inside.rfind(']');
      if (close == std::string_view::npos || !SplitOnBlanks(inside.substr(close + 1)).empty()) {
        return absl::InvalidArgumentError(absl::StrCat(where, "a gradient line must end with \"]\""));
      }
      inside = inside.substr(0, close);
      const std::vector<std::string_view> numbers = SplitOnBlanks(inside);
      const std::string& name = names_in_order[gradient_lines];
      if (numbers.size() != parameters.size()) {
        return absl::InvalidArgumentError(absl::StrCat(
            where, "the gradient of \"", name, "\" has ", numbers.size(),
            " number(s); expected one per parameter of the driver, in their declared order (", parameters.size(),
            parameters.empty() ? "" : ": " + absl::StrJoin(parameters, ", "), ")"));
      }
      std::map<std::string, double>& gradient = results.value_gradients[name];
      for (std::size_t k = 0; k < numbers.size(); ++k) {
        double derivative = 0.0;
        if (absl::Status s = ParseDakotaNumber(numbers[k], where, "a number in \"[ ... ]\"", &derivative); !s.ok()) {
          return s;
        }
        gradient[parameters[k]] = derivative;
      }
      ++gradient_lines;
      continue;
    }
    if (gradient_lines > 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "a \"value name\" line after the gradient lines: the values come first"));
    }
    if (tokens.size() != 2) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "expected \"value name\" (two fields), got ", tokens.size(), " field(s)"));
    }
    double value = 0.0;
    if (absl::Status s = ParseDakotaNumber(tokens[0], where, "\"value name\"", &value); !s.ok()) return s;
    const std::string name(tokens[1]);
    const auto [it, inserted] = line_of.emplace(name, line);
    if (!inserted) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "\"", name, "\" is given twice (first on line ", it->second, ")"));
    }
    results.values[name] = value;
    names_in_order.push_back(name);
  }
  if (gradient_lines > 0 && gradient_lines < names_in_order.size()) {
    return absl::InvalidArgumentError(absl::StrCat(source, ": ", gradient_lines, " gradient line(s) for ",
                                                   names_in_order.size(),
                                                   " values: give one \"[ ... ]\" per value, or none; \"",
                                                   names_in_order[gradient_lines], "\" has none"));
  }
  return results;
}

absl::StatusOr<ExternalResults> ParseResults(ResultsFormat format, const std::string& text,
                                             const std::string& source, const std::vector<std::string>& parameters) {
  switch (format) {
    case ResultsFormat::kJson:
      return ParseJsonResults(text, source);
    case ResultsFormat::kDakota:
      return ParseDakotaResults(text, source, parameters);
  }
  return absl::InternalError("unknown results format");
}

}  // namespace mbopt::external
