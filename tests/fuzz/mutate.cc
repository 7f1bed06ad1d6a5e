#include "tests/fuzz/mutate.h"

#include <random>
#include <regex>

#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"

namespace mbopt::fuzz {
namespace {

struct Token {
  std::size_t begin, end;
};

std::vector<Token> Find(const std::string& text, const std::regex& pattern) {
  std::vector<Token> tokens;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), pattern); it != std::sregex_iterator(); ++it) {
    tokens.push_back({static_cast<std::size_t>(it->position(1)),
                      static_cast<std::size_t>(it->position(1) + it->length(1))});
  }
  return tokens;
}

}  // namespace

std::vector<std::string> MutateStudyText(const std::string& text, int count, std::uint32_t seed) {
  static const std::vector<std::string> kExtremes = {
      "0", "-1", "1e20", "-1e20", "1e300", "1e-300", "nan", "inf", "-inf", "2147483647", "-2147483648",
      "9223372036854775807", "10000000", "1000001", "0.5"};
  // A value after a field name: `name: 12.5`.
  const std::vector<Token> numbers = Find(text, std::regex(R"(:\s*(-?[0-9][0-9.eE+-]*))"));
  // An upper-case enum value: `kind: OUTPUT_KIND_X`.
  const std::vector<Token> enums = Find(text, std::regex(R"(:\s*([A-Z][A-Z0-9_]+)\b)"));
  std::vector<std::string> enum_names;
  for (const Token& t : enums) enum_names.push_back(text.substr(t.begin, t.end - t.begin));
  const std::vector<std::string> lines = absl::StrSplit(text, '\n');

  std::mt19937 random(seed);
  auto pick = [&random](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(random); };
  std::vector<std::string> mutants;
  while (static_cast<int>(mutants.size()) < count) {
    std::string mutant = text;
    switch (pick(3)) {
      case 0:
        if (numbers.empty()) continue;
        {
          const Token t = numbers[pick(numbers.size())];
          mutant.replace(t.begin, t.end - t.begin, kExtremes[pick(kExtremes.size())]);
        }
        break;
      case 1:
        if (enums.empty()) continue;
        {
          const Token t = enums[pick(enums.size())];
          mutant.replace(t.begin, t.end - t.begin, enum_names[pick(enum_names.size())]);
        }
        break;
      default: {
        std::vector<std::string> kept = lines;
        kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(pick(kept.size())));
        mutant = absl::StrJoin(kept, "\n");
        break;
      }
    }
    if (mutant != text) mutants.push_back(std::move(mutant));
  }
  return mutants;
}

}  // namespace mbopt::fuzz
