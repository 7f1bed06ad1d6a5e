#include "spec/io/locator.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace mbopt::spec::io {

using google::protobuf::FieldDescriptor;

Where::Where(std::string file, const google::protobuf::Descriptor* descriptor,
             const google::protobuf::TextFormat::ParseInfoTree* tree, std::string path, int line,
             int column)
    : file_(std::move(file)),
      descriptor_(descriptor),
      tree_(tree),
      path_(std::move(path)),
      line_(line),
      column_(column) {}

std::string Where::PathTo(const std::string& field, int index) const {
  std::string path = path_;
  if (!field.empty()) {
    if (!path.empty()) path += ".";
    path += field;
    if (index >= 0) absl::StrAppend(&path, "[", index, "]");
  }
  return path;
}

Where Where::Child(const std::string& field, int index) const {
  const FieldDescriptor* fd =
      descriptor_ != nullptr ? descriptor_->FindFieldByName(field) : nullptr;
  const google::protobuf::Descriptor* child = fd != nullptr ? fd->message_type() : nullptr;
  const google::protobuf::TextFormat::ParseInfoTree* tree = nullptr;
  int line = line_, column = column_;
  if (fd != nullptr && tree_ != nullptr && (index >= 0) == fd->is_repeated()) {
    tree = tree_->GetTreeForNested(fd, index);
    const auto loc = tree_->GetLocation(fd, index);
    if (loc.line >= 0) {
      line = loc.line;
      column = loc.column;
    }
  }
  return Where(file_, child, tree, PathTo(field, index), line, column);
}

std::string Where::Describe(const std::string& field, int index) const {
  int line = line_, column = column_;
  const FieldDescriptor* fd =
      descriptor_ != nullptr && !field.empty() ? descriptor_->FindFieldByName(field) : nullptr;
  if (fd != nullptr && tree_ != nullptr) {
    // A repeated field without an index points at its first element.
    const int at = fd->is_repeated() ? (index >= 0 ? index : 0) : -1;
    const auto loc = tree_->GetLocation(fd, at);
    if (loc.line >= 0) {
      line = loc.line;
      column = loc.column;
    }
  }
  std::string out = file_;
  if (line >= 0) absl::StrAppend(&out, ":", line + 1, ":", column + 1);
  const std::string path = PathTo(field, index);
  absl::StrAppend(&out, ": ", path.empty() ? "(top level)" : path);
  return out;
}

void Errors::Add(const Where& where, const std::string& field, int index, const std::string& what) {
  messages_.push_back(absl::StrCat(where.Describe(field, index), ": ", what));
}

absl::Status Errors::ToStatus() const {
  if (messages_.empty()) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrJoin(messages_, "\n"));
}

}  // namespace mbopt::spec::io
