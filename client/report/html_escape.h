// Escaping of user-given text (study, variable and constraint names can hold
// < & " ') for HTML text, attribute values and inline SVG alike.
#pragma once

#include <string>
#include <string_view>

namespace mbopt::report {

// Replaces & < > " ' by character references. Control characters other than
// tab, newline and carriage return (not allowed in HTML/XML text) become
// U+FFFD; bytes of UTF-8 sequences pass unchanged.
std::string EscapeHtml(std::string_view text);

}  // namespace mbopt::report
