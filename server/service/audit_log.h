// The server's audit trail: one line on stderr (the service's journal) per
// refused call, per job action (submit, cancel, resume) and per token
// reload, each saying who (the token holder's name, the peer's address) and
// what. Lines start with "mbopt-server: audit: " so they can be picked out
// of the log. Secrets (tokens, the secret part of worker ids) never go in.
#pragma once

#include <string_view>

namespace mbopt::service {

// Writes "mbopt-server: audit: <line>" as one write, so that lines of
// concurrent calls do not interleave.
void AuditLog(std::string_view line);

}  // namespace mbopt::service
