#include "common/version/version.h"


namespace mbopt::version {

namespace {
// Written by cmake/BuildCommit.cmake at every build, rewritten only when the
// commit changes, so an unchanged tree recompiles nothing.
#include "mbopt_build_commit.inc"
}  // namespace

std::string_view Release() { return MBOPT_RELEASE; }

std::string_view Commit() { return kBuildCommit; }

std::string VersionText(std::string_view program,
                        std::initializer_list<std::pair<std::string_view, std::string>> extra) {
  std::string text(program);
  text.append(" ").append(Release()).append(" (commit ").append(Commit()).append(")\n");
  text.append("  wire schema and study files: ").append(kSchemaPackage).append("\n");
  for (const auto& [name, value] : extra) text.append("  ").append(name).append(": ").append(value).append("\n");
  return text;
}

}  // namespace mbopt::version
