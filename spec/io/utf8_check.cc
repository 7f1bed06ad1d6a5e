#include "spec/io/utf8_check.h"

#include <string>
#include <vector>

namespace mbopt::spec::io {
namespace {

using google::protobuf::FieldDescriptor;

// RFC 3629: no overlong forms, no surrogates, nothing above U+10FFFF.
bool IsUtf8(const std::string& text) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  std::size_t i = 0;
  while (i < n) {
    const unsigned char c = s[i];
    if (c < 0x80) {
      ++i;
      continue;
    }
    int more = 0;
    unsigned char low = 0x80, high = 0xBF;
    if (c >= 0xC2 && c <= 0xDF) {
      more = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      more = 2;
      if (c == 0xE0) low = 0xA0;
      if (c == 0xED) high = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      more = 3;
      if (c == 0xF0) low = 0x90;
      if (c == 0xF4) high = 0x8F;
    } else {
      return false;
    }
    if (i + static_cast<std::size_t>(more) >= n) return false;  // cut short
    if (s[i + 1] < low || s[i + 1] > high) return false;
    for (int k = 2; k <= more; ++k) {
      if (s[i + static_cast<std::size_t>(k)] < 0x80 || s[i + static_cast<std::size_t>(k)] > 0xBF) return false;
    }
    i += static_cast<std::size_t>(more) + 1;
  }
  return true;
}

constexpr char kNotUtf8[] = "text is not valid UTF-8";

}  // namespace

void CheckUtf8Strings(const google::protobuf::Message& message, const Where& where, Errors* errors) {
  const google::protobuf::Reflection* reflection = message.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);
  for (const FieldDescriptor* field : fields) {
    const std::string& name = field->name();
    if (field->type() == FieldDescriptor::TYPE_STRING) {
      if (field->is_repeated()) {
        for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
          if (!IsUtf8(reflection->GetRepeatedString(message, field, i))) errors->Add(where, name, i, kNotUtf8);
        }
      } else if (!IsUtf8(reflection->GetString(message, field))) {
        errors->Add(where, name, kNotUtf8);
      }
    } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      if (field->is_map()) continue;  // the schemas have no maps
      if (field->is_repeated()) {
        for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
          CheckUtf8Strings(reflection->GetRepeatedMessage(message, field, i), where.Child(name, i), errors);
        }
      } else {
        CheckUtf8Strings(reflection->GetMessage(message, field), where.Child(name), errors);
      }
    }
  }
}

}  // namespace mbopt::spec::io
