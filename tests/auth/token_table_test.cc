// The server's token table: what it accepts, what it refuses and how it
// says so, and that it never holds a token itself.
#include "server/auth/token_table.h"

#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "server/auth/token.h"

namespace mbopt::auth {
namespace {

using ::testing::HasSubstr;

TEST(Token, NewTokensAreDistinctAndTheirHashIsSha256) {
  std::set<std::string> tokens;
  for (int i = 0; i < 100; ++i) {
    absl::StatusOr<std::string> token = NewToken();
    ASSERT_TRUE(token.ok()) << token.status();
    EXPECT_EQ(token->size(), 6u + 64u);
    EXPECT_EQ(token->rfind("mbopt_", 0), 0u);
    tokens.insert(*token);
  }
  EXPECT_EQ(tokens.size(), 100u);
  // FIPS 180-2's test vector.
  EXPECT_EQ(HashToken("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(TokenTable, FindsTheHolderOfEachTokenAndNoOther) {
  const std::string alice = *NewToken(), workers = *NewToken(), ops = *NewToken();
  const std::string text = "# a comment\n\n" + TokenTable::Line({Role::kUser, "alice"}, alice) +
                           TokenTable::Line({Role::kWorker, "workers"}, workers) + "  " +
                           TokenTable::Line({Role::kAdmin, "ops"}, ops);
  absl::StatusOr<TokenTable> table = TokenTable::Parse(text, "tokens");
  ASSERT_TRUE(table.ok()) << table.status();
  EXPECT_EQ(table->size(), 3u);
  ASSERT_TRUE(table->Find(alice).has_value());
  EXPECT_EQ(table->Find(alice)->role, Role::kUser);
  EXPECT_EQ(table->Find(alice)->name, "alice");
  EXPECT_EQ(table->Find(workers)->role, Role::kWorker);
  EXPECT_EQ(table->Find(ops)->role, Role::kAdmin);
  EXPECT_FALSE(table->Find(alice + "x").has_value());
  EXPECT_FALSE(table->Find("").has_value());
  // The file holds hashes, never the tokens.
  EXPECT_EQ(text.find(alice), std::string::npos);
  // A hash is not a token.
  EXPECT_FALSE(table->Find(HashToken(alice)).has_value());
}

TEST(TokenTable, BadLinesAreNamedWithFileLineAndWhatWasExpected) {
  const std::string hash(64, 'a');
  struct Case {
    std::string text;
    std::string expected;
  } cases[] = {
      {"user alice\n", "tokens:1: expected three fields"},
      {"\n# ok\nroot alice " + hash + "\n", "tokens:3: role is worker, user or admin, got 'root'"},
      {"user al/ice " + hash + "\n", "tokens:1: name is 1 to 64"},
      {"user alice mbopt_0123\n", "tokens:1: the third field is the SHA-256 of the token"},
      {"user alice " + std::string(64, 'A') + "\n", "tokens:1: the third field is the SHA-256"},
      {"user alice " + hash + "\nuser bob " + hash + "\n", "tokens:2: the same token is listed twice"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<TokenTable> table = TokenTable::Parse(c.text, "tokens");
    ASSERT_FALSE(table.ok()) << c.text;
    EXPECT_EQ(table.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(table.status().message()), HasSubstr(c.expected)) << c.text;
  }
  EXPECT_THAT(std::string(TokenTable::Load("/nonexistent/tokens").status().message()),
              HasSubstr("cannot read the token table /nonexistent/tokens"));
}

TEST(TokenTable, NamesAreShortAndPlain) {
  EXPECT_TRUE(TokenTable::ValidName("alice.smith@lab-2_b"));
  EXPECT_FALSE(TokenTable::ValidName(""));
  EXPECT_FALSE(TokenTable::ValidName(std::string(65, 'a')));
  EXPECT_FALSE(TokenTable::ValidName("a b"));
  EXPECT_FALSE(TokenTable::ValidName("a\n"));
}

}  // namespace
}  // namespace mbopt::auth
