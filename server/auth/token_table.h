// The server's table of tokens: for each, its role, its holder's name and
// the SHA-256 of the token (never the token). Read from a text file, one
// token per line:
//
//   # role  name   sha256 of the token
//   worker  cluster 5f0c...64 hex digits
//   user    alice   9a1b...
//   admin   ops     c3d4...
//
// Blank lines and lines starting with '#' are skipped. `mbopt-server
// init-tls` writes such a file and `mbopt-server add-token` appends to it.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"
#include "server/auth/principal.h"

namespace mbopt::auth {

class TokenTable {
 public:
  // InvalidArgument naming the file, the line and what was expected.
  static absl::StatusOr<TokenTable> Parse(std::string_view text, const std::string& source_name);
  // NotFound / PermissionDenied naming the path when it cannot be read.
  static absl::StatusOr<TokenTable> Load(const std::string& path);

  // The holder of `token`, or nothing for a token not in the table.
  std::optional<Principal> Find(std::string_view token) const;
  std::size_t size() const { return by_hash_.size(); }
  // Whether a token of the table belongs to `principal` (its role and name):
  // a worker registered under a holder whose every token was removed is
  // dropped when the table is read again (per-worker tokens).
  bool HasHolder(const Principal& principal) const;

  // The line of the file that admits `token` for `principal`.
  static std::string Line(const Principal& principal, std::string_view token);
  // Whether `name` may be a token holder's name: 1 to 64 of [A-Za-z0-9._@-].
  static bool ValidName(std::string_view name);

 private:
  std::map<std::string, Principal, std::less<>> by_hash_;
};

}  // namespace mbopt::auth
