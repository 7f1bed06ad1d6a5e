#include "client/json_writer.h"

#include <cmath>
#include <cstdio>

#include "common/check.h"

namespace mbopt::client {

std::string JsonWriter::Quote(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  out += '"';
  return out;
}

std::string JsonWriter::FormatDouble(double value) {
  if (!std::isfinite(value)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

void JsonWriter::NewLine() {
  if (indent_ <= 0) return;
  out_ += '\n';
  out_.append(stack_.size() * static_cast<size_t>(indent_), ' ');
}

void JsonWriter::BeforeValue() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (stack_.empty()) return;
  MBOPT_CHECK(!stack_.back().is_object, "a value inside an object needs a Key first");
  if (!stack_.back().empty) out_ += ',';
  stack_.back().empty = false;
  NewLine();
}

void JsonWriter::Key(std::string_view key) {
  MBOPT_CHECK(!stack_.empty() && stack_.back().is_object && !after_key_,
              "Key outside an object");
  if (!stack_.back().empty) out_ += ',';
  stack_.back().empty = false;
  NewLine();
  out_ += Quote(key);
  out_ += indent_ > 0 ? ": " : ":";
  after_key_ = true;
}

void JsonWriter::BeginObject() {
  BeforeValue();
  out_ += '{';
  stack_.push_back({true, true});
}

void JsonWriter::BeginArray() {
  BeforeValue();
  out_ += '[';
  stack_.push_back({false, true});
}

void JsonWriter::EndObject() {
  MBOPT_CHECK(!stack_.empty() && stack_.back().is_object && !after_key_, "unbalanced EndObject");
  bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) NewLine();
  out_ += '}';
}

void JsonWriter::EndArray() {
  MBOPT_CHECK(!stack_.empty() && !stack_.back().is_object, "unbalanced EndArray");
  bool empty = stack_.back().empty;
  stack_.pop_back();
  if (!empty) NewLine();
  out_ += ']';
}

void JsonWriter::String(std::string_view value) {
  BeforeValue();
  out_ += Quote(value);
}

void JsonWriter::Number(double value) {
  BeforeValue();
  out_ += FormatDouble(value);
}

void JsonWriter::Integer(long long value) {
  BeforeValue();
  out_ += std::to_string(value);
}

void JsonWriter::Bool(bool value) {
  BeforeValue();
  out_ += value ? "true" : "false";
}

void JsonWriter::Null() {
  BeforeValue();
  out_ += "null";
}

void JsonWriter::NumberArray(std::string_view key, const std::vector<double>& values) {
  Key(key);
  // Short numeric arrays stay on one line: easier to read and to diff.
  BeforeValue();
  out_ += '[';
  for (size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out_ += indent_ > 0 ? ", " : ",";
    out_ += FormatDouble(values[i]);
  }
  out_ += ']';
}

}  // namespace mbopt::client
