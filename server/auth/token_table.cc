#include "server/auth/token_table.h"

#include <vector>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "common/read_file.h"
#include "server/auth/token.h"

namespace mbopt::auth {
namespace {

bool IsHexDigest(std::string_view text) {
  if (text.size() != 64) return false;
  for (char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return true;
}

}  // namespace

bool TokenTable::ValidName(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name) {
    if (!absl::ascii_isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '@' && c != '-') {
      return false;
    }
  }
  return true;
}

absl::StatusOr<TokenTable> TokenTable::Parse(std::string_view text_view, const std::string& source_name) {
  TokenTable table;
  int line_number = 0;
  const absl::string_view text(text_view.data(), text_view.size());
  for (absl::string_view line : absl::StrSplit(text, '\n')) {
    ++line_number;
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || line.front() == '#') continue;
    const std::vector<absl::string_view> fields = absl::StrSplit(line, absl::ByAnyChar(" \t"), absl::SkipEmpty());
    auto error = [&](const std::string& what) {
      return absl::InvalidArgumentError(absl::StrCat(source_name, ":", line_number, ": ", what));
    };
    if (fields.size() != 3) {
      return error(absl::StrCat("expected three fields, ROLE NAME SHA256 (e.g. `user alice 9a1b...`), got ",
                                fields.size()));
    }
    const std::optional<Role> role = ParseRole(std::string_view(fields[0].data(), fields[0].size()));
    if (!role) return error(absl::StrCat("role is worker, user or admin, got '", fields[0], "'"));
    if (!ValidName(std::string_view(fields[1].data(), fields[1].size()))) {
      return error(absl::StrCat("name is 1 to 64 of the characters A-Z a-z 0-9 . _ @ -, got '", fields[1], "'"));
    }
    if (!IsHexDigest(std::string_view(fields[2].data(), fields[2].size()))) {
      return error("the third field is the SHA-256 of the token, 64 lowercase hex digits (the token itself "
                   "never goes in this file)");
    }
    if (!table.by_hash_.emplace(std::string(fields[2]), Principal{*role, std::string(fields[1])}).second) {
      return error("the same token is listed twice");
    }
  }
  return table;
}

absl::StatusOr<TokenTable> TokenTable::Load(const std::string& path) {
  absl::StatusOr<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return absl::NotFoundError(absl::StrCat("cannot read the token table ", path));
  return Parse(*text, path);
}

bool TokenTable::HasHolder(const Principal& principal) const {
  for (const auto& [hash, holder] : by_hash_) {
    if (holder.role == principal.role && holder.name == principal.name) return true;
  }
  return false;
}

std::optional<Principal> TokenTable::Find(std::string_view token) const {
  const auto it = by_hash_.find(HashToken(token));
  if (it == by_hash_.end()) return std::nullopt;
  return it->second;
}

std::string TokenTable::Line(const Principal& principal, std::string_view token) {
  return absl::StrCat(RoleName(principal.role), " ", principal.name, " ", HashToken(token), "\n");
}

}  // namespace mbopt::auth
