// A driver's input template: text with {name} placeholders that the runner
// fills with the design's parameter values. A placeholder is '{', a name
// (a letter or '_', then letters, digits, '_'), '}'; "{{" stands for a
// literal '{'; any other brace is kept as it is, so templates of formats that
// use braces themselves (JSON, C) need no escaping except before a name.
#pragma once

#include <map>
#include <set>
#include <string>

#include "absl/status/statusor.h"

namespace mbopt::external {

// The placeholder names the template uses, each with the 1-based line of its
// first use.
std::map<std::string, int> TemplatePlaceholders(const std::string& text);

// A number as the runner writes it into inputs: %.17g, which reads back to
// the same double. Non-finite values are refused before they get here.
std::string FormatParameterValue(double value);

// The template with every placeholder replaced by its value (formatted with
// FormatParameterValue). InvalidArgument naming `source` and the line of a
// placeholder without a value.
absl::StatusOr<std::string> FillTemplate(const std::string& text, const std::string& source,
                                         const std::map<std::string, double>& values);

}  // namespace mbopt::external
