// A small streaming JSON writer for the CLI's machine-readable output. It
// keeps track of commas and nesting; doubles are written with 17 significant
// digits so that a value read back is bit-identical, and non-finite doubles
// (which JSON cannot represent) are written as null.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mbopt::client {

class JsonWriter {
 public:
  // `indent` spaces per level; 0 writes everything on one line.
  explicit JsonWriter(int indent = 2) : indent_(indent) {}

  void BeginObject();
  void EndObject();
  void BeginArray();
  void EndArray();
  // Inside an object: the key of the next value.
  void Key(std::string_view key);

  void String(std::string_view value);
  void Number(double value);
  void Integer(long long value);
  void Bool(bool value);
  void Null();

  // Convenience for key + value inside an object.
  void Field(std::string_view key, std::string_view value) { Key(key); String(value); }
  void Field(std::string_view key, const char* value) { Key(key); String(value); }
  void Field(std::string_view key, double value) { Key(key); Number(value); }
  void Field(std::string_view key, int value) { Key(key); Integer(value); }
  void Field(std::string_view key, long value) { Key(key); Integer(value); }
  void Field(std::string_view key, long long value) { Key(key); Integer(value); }
  void Field(std::string_view key, bool value) { Key(key); Bool(value); }
  void NumberArray(std::string_view key, const std::vector<double>& values);

  // The document so far (complete once every Begin has its End).
  const std::string& str() const { return out_; }

  static std::string Quote(std::string_view s);
  static std::string FormatDouble(double value);  // "%.17g" or "null"

 private:
  void BeforeValue();
  void NewLine();

  struct Level {
    bool is_object = false;
    bool empty = true;
  };
  int indent_;
  std::string out_;
  std::vector<Level> stack_;
  bool after_key_ = false;
};

}  // namespace mbopt::client
