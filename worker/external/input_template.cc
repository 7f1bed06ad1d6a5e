#include "worker/external/input_template.h"

#include <charconv>

#include "absl/strings/str_cat.h"

namespace mbopt::external {
namespace {

bool IsNameStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool IsNameChar(char c) { return IsNameStart(c) || (c >= '0' && c <= '9'); }

// Walks the template once: `literal` receives text to copy, `placeholder`
// each name with its line.
template <typename Literal, typename Placeholder>
void Walk(const std::string& text, Literal literal, Placeholder placeholder) {
  int line = 1;
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c == '{' && i + 1 < text.size() && text[i + 1] == '{') {
      literal(std::string_view("{"));
      i += 2;
      continue;
    }
    if (c == '{' && i + 1 < text.size() && IsNameStart(text[i + 1])) {
      std::size_t end = i + 1;
      while (end < text.size() && IsNameChar(text[end])) ++end;
      if (end < text.size() && text[end] == '}') {
        placeholder(text.substr(i + 1, end - i - 1), line);
        i = end + 1;
        continue;
      }
    }
    if (c == '\n') ++line;
    literal(std::string_view(&text[i], 1));
    ++i;
  }
}

}  // namespace

std::map<std::string, int> TemplatePlaceholders(const std::string& text) {
  std::map<std::string, int> names;
  Walk(text, [](std::string_view) {}, [&](const std::string& name, int line) { names.emplace(name, line); });
  return names;
}

std::string FormatParameterValue(double value) {
  // %.17g as printf writes it in the C locale, whatever the process' locale.
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::general, 17);
  return std::string(buffer, result.ptr);
}

absl::StatusOr<std::string> FillTemplate(const std::string& text, const std::string& source,
                                         const std::map<std::string, double>& values) {
  std::string out;
  out.reserve(text.size());
  std::string missing;
  Walk(
      text, [&](std::string_view piece) { out.append(piece); },
      [&](const std::string& name, int line) {
        const auto it = values.find(name);
        if (it == values.end()) {
          if (missing.empty()) missing = absl::StrCat(source, ":", line, ": placeholder {", name, "} has no value");
          return;
        }
        out += FormatParameterValue(it->second);
      });
  if (!missing.empty()) return absl::InvalidArgumentError(missing);
  return out;
}

}  // namespace mbopt::external
