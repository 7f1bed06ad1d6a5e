// Deterministic mutations of a study's text, the way a hostile or careless
// user edits a file: a number pushed to an extreme, an enum value swapped
// for another, a line dropped. For the property tests that check that every
// entry point accepts and refuses the same files.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbopt::fuzz {

std::vector<std::string> MutateStudyText(const std::string& text, int count, std::uint32_t seed);

}  // namespace mbopt::fuzz
