// Tokens and their hashes. A token is a random secret its holder keeps in a
// file; the server keeps only its SHA-256, so a copy of the server's token
// table lets no one call the server.
#pragma once

#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace mbopt::auth {

// A new token: "mbopt_" and 64 hex digits (256 random bits from the
// system's generator, through OpenSSL).
absl::StatusOr<std::string> NewToken();

// The lowercase hex SHA-256 of a token.
std::string HashToken(std::string_view token);

}  // namespace mbopt::auth
