// A tiny well-formedness checker for the report page in tests: every opened
// tag closed in order, attribute values quoted, '&' only as a character
// reference, no stray '<'. Not a full HTML parser: it knows the few void
// elements and raw-text elements the page may use.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mbopt::report::testing {

// Checks markup. `xml_strict`: no void elements (SVG is XML). Returns an
// empty string when well formed, else the first problem with its offset.
std::string CheckMarkup(std::string_view markup, bool xml_strict);

// Every <svg ...>...</svg> element of the page, in order.
std::vector<std::string> SvgFragments(std::string_view html);

// The values of the coordinate and size attributes (x, y, x1, ..., cx, cy,
// r, width, height, points, viewBox) of every tag in `svg`.
std::vector<std::string> NumericAttributeValues(std::string_view svg);

// How often `needle` occurs in `haystack`, overlapping occurrences included.
int CountOccurrences(std::string_view haystack, std::string_view needle);

}  // namespace mbopt::report::testing
