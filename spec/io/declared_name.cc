#include "spec/io/declared_name.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace mbopt::spec::io {

void CheckDeclaredName(const Where& w, const std::string& name, bool is_new, const DeclaredName& rule,
                       Errors* errors) {
  const bool reserved =
      std::any_of(rule.reserved.begin(), rule.reserved.end(), [&](const char* r) { return name == r; });
  if (name.empty() || reserved) errors->Add(w, "name", rule.missing);
  if (!is_new) errors->Add(w, "name", absl::StrCat("duplicate ", rule.duplicate, " \"", name, "\""));
}

}  // namespace mbopt::spec::io
