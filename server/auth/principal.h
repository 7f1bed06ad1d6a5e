// Who is calling the server, as its token says. A server without tokens
// treats every caller as an admin with no name (loopback use on one's own
// machine); with tokens, each call carries one, and the role decides what it
// may call and the name which jobs are its own (docs/server.md, "Security").
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace mbopt::auth {

enum class Role {
  kWorker,  // acquires tasks and reports results; nothing else
  kUser,    // submits jobs; sees, cancels and resumes its own
  kAdmin,   // what a user may, on every job
};

struct Principal {
  Role role = Role::kAdmin;
  std::string name;  // the owner recorded on the jobs it submits
};

const char* RoleName(Role role);
std::optional<Role> ParseRole(std::string_view name);

}  // namespace mbopt::auth
