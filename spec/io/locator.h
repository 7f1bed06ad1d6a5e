// Where a value came from, for error messages: the file, the line and column
// recorded by the text-format parser (when there is text), and the field
// path from the file's root message. Errors collects every problem of one
// file so that a person sees them all at once.
#pragma once

#include <google/protobuf/descriptor.h>
#include <google/protobuf/text_format.h>

#include <string>
#include <vector>

#include "absl/status/status.h"

namespace mbopt::spec::io {

class Where {
 public:
  // `tree` may be null (a message without text, e.g. received by a server).
  Where(std::string file, const google::protobuf::Descriptor* descriptor,
        const google::protobuf::TextFormat::ParseInfoTree* tree, std::string path = "",
        int line = -1, int column = -1);

  // The sub-message in `field` (element `index` if repeated, else -1).
  Where Child(const std::string& field, int index = -1) const;
  // "file:line:column: path.field[index]" (line and column 1-based, omitted
  // without text; the enclosing message's position if the field is absent).
  std::string Describe(const std::string& field = "", int index = -1) const;
  const std::string& file() const { return file_; }

 private:
  std::string PathTo(const std::string& field, int index) const;
  std::string file_;
  const google::protobuf::Descriptor* descriptor_;
  const google::protobuf::TextFormat::ParseInfoTree* tree_;
  std::string path_;
  int line_, column_;  // 0-based, -1 unknown
};

class Errors {
 public:
  // Records "<where.Describe(field, index)>: <what>".
  void Add(const Where& where, const std::string& field, int index, const std::string& what);
  void Add(const Where& where, const std::string& field, const std::string& what) {
    Add(where, field, -1, what);
  }
  void AddRaw(std::string message) { messages_.push_back(std::move(message)); }
  bool empty() const { return messages_.empty(); }
  // OK if empty, else InvalidArgument listing every message, one per line.
  absl::Status ToStatus() const;

 private:
  std::vector<std::string> messages_;
};

}  // namespace mbopt::spec::io
