#include "tests/report/markup_checker.h"

#include <algorithm>
#include <cctype>
#include <set>
#include <string>
#include <vector>

namespace mbopt::report::testing {
namespace {

const std::set<std::string>& VoidElements() {
  static const std::set<std::string> kVoid = {"meta", "br", "hr", "img", "input", "link", "wbr"};
  return kVoid;
}

bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_' || c == ':';
}

std::string At(std::size_t pos, const std::string& what) {
  return "offset " + std::to_string(pos) + ": " + what;
}

// A character reference starting at markup[pos] == '&'.
bool ValidReference(std::string_view markup, std::size_t pos) {
  const std::size_t end = markup.find(';', pos);
  if (end == std::string_view::npos || end - pos > 12 || end == pos + 1) return false;
  std::string_view body = markup.substr(pos + 1, end - pos - 1);
  if (body[0] == '#') {
    body.remove_prefix(1);
    if (!body.empty() && (body[0] == 'x' || body[0] == 'X')) {
      body.remove_prefix(1);
      return !body.empty() && std::all_of(body.begin(), body.end(), [](char c) {
        return std::isxdigit(static_cast<unsigned char>(c)) != 0;
      });
    }
    return !body.empty() && std::all_of(body.begin(), body.end(), [](char c) {
      return std::isdigit(static_cast<unsigned char>(c)) != 0;
    });
  }
  return std::all_of(body.begin(), body.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; });
}

struct Tag {
  std::string name;
  bool closing = false;
  bool self_closing = false;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::size_t end = 0;  // offset after '>'
};

// Parses the tag at markup[pos] == '<'; returns an error or "".
std::string ParseTag(std::string_view markup, std::size_t pos, Tag& tag) {
  std::size_t i = pos + 1;
  if (i < markup.size() && markup[i] == '/') {
    tag.closing = true;
    ++i;
  }
  const std::size_t name_start = i;
  while (i < markup.size() && IsNameChar(markup[i])) ++i;
  if (i == name_start) return At(pos, "'<' that does not start a tag");
  tag.name = std::string(markup.substr(name_start, i - name_start));
  for (;;) {
    while (i < markup.size() && std::isspace(static_cast<unsigned char>(markup[i])) != 0) ++i;
    if (i >= markup.size()) return At(pos, "unterminated tag <" + tag.name);
    if (markup[i] == '>') {
      tag.end = i + 1;
      return "";
    }
    if (markup[i] == '/' && i + 1 < markup.size() && markup[i + 1] == '>') {
      if (tag.closing) return At(i, "closing tag ends in '/>'");
      tag.self_closing = true;
      tag.end = i + 2;
      return "";
    }
    if (tag.closing) return At(i, "attribute in a closing tag");
    const std::size_t attr_start = i;
    while (i < markup.size() && IsNameChar(markup[i])) ++i;
    if (i == attr_start) return At(i, std::string("unexpected character '") + markup[i] + "' in tag <" + tag.name);
    std::string attr(markup.substr(attr_start, i - attr_start));
    if (i >= markup.size() || markup[i] != '=') return At(i, "attribute " + attr + " without a value");
    ++i;
    if (i >= markup.size() || markup[i] != '"') return At(i, "attribute " + attr + " value not in double quotes");
    const std::size_t value_end = markup.find('"', i + 1);
    if (value_end == std::string_view::npos) return At(i, "unterminated attribute value");
    std::string value(markup.substr(i + 1, value_end - i - 1));
    if (value.find('<') != std::string::npos) return At(i, "'<' in attribute " + attr);
    for (std::size_t k = value.find('&'); k != std::string::npos; k = value.find('&', k + 1)) {
      if (!ValidReference(value, k)) return At(i + 1 + k, "bare '&' in attribute " + attr);
    }
    tag.attributes.emplace_back(attr, value);
    i = value_end + 1;
    if (i < markup.size() && !std::isspace(static_cast<unsigned char>(markup[i])) && markup[i] != '>' &&
        markup[i] != '/') {
      return At(i, "no space after attribute " + attr);
    }
  }
}

}  // namespace

std::string CheckMarkup(std::string_view markup, bool xml_strict) {
  std::vector<std::string> open;
  std::size_t i = 0;
  while (i < markup.size()) {
    const char c = markup[i];
    if (c == '&') {
      if (!ValidReference(markup, i)) return At(i, "bare '&' in text");
      ++i;
      continue;
    }
    if (c == '>') return At(i, "stray '>' in text");
    if (c != '<') {
      ++i;
      continue;
    }
    if (markup.substr(i, 9) == "<!DOCTYPE") {
      const std::size_t end = markup.find('>', i);
      if (end == std::string_view::npos) return At(i, "unterminated doctype");
      i = end + 1;
      continue;
    }
    if (markup.substr(i, 4) == "<!--") {
      const std::size_t end = markup.find("-->", i);
      if (end == std::string_view::npos) return At(i, "unterminated comment");
      i = end + 3;
      continue;
    }
    Tag tag;
    if (std::string error = ParseTag(markup, i, tag); !error.empty()) return error;
    i = tag.end;
    if (tag.closing) {
      if (open.empty()) return At(i, "</" + tag.name + "> closes nothing");
      if (open.back() != tag.name) return At(i, "</" + tag.name + "> closes <" + open.back() + ">");
      open.pop_back();
      continue;
    }
    if (tag.self_closing) continue;
    if (!xml_strict && VoidElements().count(tag.name) > 0) continue;
    if (tag.name == "style" || tag.name == "script") {
      const std::string close = "</" + tag.name + ">";
      const std::size_t end = markup.find(close, i);
      if (end == std::string_view::npos) return At(i, "unterminated <" + tag.name + ">");
      i = end + close.size();
      continue;
    }
    open.push_back(tag.name);
  }
  if (!open.empty()) return "end of input: <" + open.back() + "> not closed";
  return "";
}

std::vector<std::string> SvgFragments(std::string_view html) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while ((pos = html.find("<svg", pos)) != std::string_view::npos) {
    const std::size_t end = html.find("</svg>", pos);
    if (end == std::string_view::npos) {
      out.emplace_back(html.substr(pos));
      break;
    }
    out.emplace_back(html.substr(pos, end + 6 - pos));
    pos = end + 6;
  }
  return out;
}

std::vector<std::string> NumericAttributeValues(std::string_view svg) {
  static const std::set<std::string> kNumeric = {"x",  "y",  "x1", "y1",    "x2",     "y2",     "cx",
                                                 "cy", "r",  "points", "width", "height", "viewBox"};
  std::vector<std::string> out;
  for (std::size_t i = svg.find('<'); i != std::string_view::npos; i = svg.find('<', i + 1)) {
    if (i + 1 < svg.size() && (svg[i + 1] == '/' || svg[i + 1] == '!')) continue;
    Tag tag;
    if (!ParseTag(svg, i, tag).empty()) continue;
    for (const auto& [name, value] : tag.attributes) {
      if (kNumeric.count(name) > 0) out.push_back(value);
    }
  }
  return out;
}

int CountOccurrences(std::string_view haystack, std::string_view needle) {
  int n = 0;
  for (std::size_t p = haystack.find(needle); p != std::string_view::npos; p = haystack.find(needle, p + 1)) ++n;
  return n;
}

}  // namespace mbopt::report::testing
