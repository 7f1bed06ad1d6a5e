// What to write instead, for the parser's messages about fields and values
// the schema does not have but a user reaches for: a joint `type` on a
// linkage, a REDUCTION_EQUAL. The schema has what they want elsewhere (a
// multibody scene, `equals:`), and the message says where.
#pragma once

#include <string>

namespace mbopt::spec::io {

// The parser's message with a sentence appended when it is one of those
// mistakes; otherwise the message unchanged.
std::string WithParseHint(const std::string& message);

}  // namespace mbopt::spec::io
