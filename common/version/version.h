// What a program is: its release, the commit it was built from, and the
// versions of the formats it speaks, for `--version` on the three programs
// (and for bug reports: the commit says exactly which code ran).
#pragma once

#include <string>
#include <initializer_list>
#include <string_view>
#include <utility>

namespace mbopt::version {

// The release (CMake's project version).
std::string_view Release();
// The commit the program was built from (`git describe --always --dirty`
// at build time), or "unknown" outside a git checkout.
std::string_view Commit();
// The wire schema (gRPC services and messages) and the text format of
// study and scene files: the Protobuf package.
inline constexpr std::string_view kSchemaPackage = "mbopt.v1";

// "PROGRAM RELEASE (commit COMMIT)", then one "  NAME: VALUE" line per
// entry of `extra` (e.g. a program's own database schema), then the schemas.
std::string VersionText(std::string_view program,
                        std::initializer_list<std::pair<std::string_view, std::string>> extra = {});

}  // namespace mbopt::version
