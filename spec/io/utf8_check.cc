#include "spec/io/utf8_check.h"

#include <functional>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "spec/limits.h"

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

// Calls `check` for every string of `message` (recursively) with where it
// is, its field's name and its index (-1 unless repeated).
void ForEachString(const google::protobuf::Message& message, const Where& where,
                   const std::function<void(const Where&, const std::string&, int, const std::string&)>& check) {
  const google::protobuf::Reflection* reflection = message.GetReflection();
  std::vector<const FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);
  for (const FieldDescriptor* field : fields) {
    const std::string& name = field->name();
    if (field->type() == FieldDescriptor::TYPE_STRING) {
      if (field->is_repeated()) {
        for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
          check(where, name, i, reflection->GetRepeatedString(message, field, i));
        }
      } else {
        check(where, name, -1, reflection->GetString(message, field));
      }
    } else if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      if (field->is_map()) continue;  // the schemas have no maps
      if (field->is_repeated()) {
        for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
          ForEachString(reflection->GetRepeatedMessage(message, field, i), where.Child(name, i), check);
        }
      } else {
        ForEachString(reflection->GetMessage(message, field), where.Child(name), check);
      }
    }
  }
}

}  // namespace

void CheckUtf8Strings(const google::protobuf::Message& message, const Where& where, Errors* errors) {
  ForEachString(message, where, [errors](const Where& w, const std::string& field, int index, const std::string& text) {
    if (!IsUtf8(text)) errors->Add(w, field, index, kNotUtf8);
  });
}

void CheckStringLengths(const google::protobuf::Message& message, const Where& where, Errors* errors) {
  ForEachString(message, where, [errors](const Where& w, const std::string& field, int index, const std::string& text) {
    const bool is_name = field == "name";
    const std::size_t limit = static_cast<std::size_t>(is_name ? kMaxNameBytes : kMaxStringBytes);
    if (text.size() > limit) {
      errors->Add(w, field, index,
                  absl::StrFormat("%s of %d bytes, more than the limit of %d", is_name ? "a name" : "text",
                                  text.size(), limit));
    }
  });
}

}  // namespace mbopt::spec::io
