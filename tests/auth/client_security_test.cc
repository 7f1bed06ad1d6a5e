// The client's settings: options before the environment, files read, and
// clear refusals for what cannot work.
#include "common/secure_channel/client_security.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/private_file.h"

namespace mbopt::secure_channel {
namespace {

using ::testing::HasSubstr;

class ClientSecurityTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ClearSecurityEnvironment();
    dir_ = std::filesystem::temp_directory_path() / ("mbopt_client_security_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    ClearSecurityEnvironment();
    std::filesystem::remove_all(dir_);
  }
  // Readable by its owner only, as init-tls and add-token make secrets.
  std::string Write(const std::string& name, const std::string& content,
                    std::filesystem::perms mode = std::filesystem::perms::owner_read |
                                                  std::filesystem::perms::owner_write) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << content;
    std::filesystem::permissions(path, mode);
    return path;
  }
  std::filesystem::path dir_;
};

TEST_F(ClientSecurityTest, NothingGivenIsPlaintextWithoutToken) {
  absl::StatusOr<ClientSecurity> security = LoadClientSecurity({});
  ASSERT_TRUE(security.ok()) << security.status();
  EXPECT_FALSE(security->tls);
  EXPECT_EQ(security->token, "");
}

TEST_F(ClientSecurityTest, OptionsComeBeforeTheEnvironmentAndTokensAreTrimmed) {
  const std::string ca = Write("ca.pem", "CA PEM");
  const std::string token = Write("t", "  mbopt_abc\n");
  ::setenv("MBOPT_TLS_CA", "/nonexistent/ca.pem", 1);
  ::setenv("MBOPT_TOKEN", "mbopt_from_env", 1);
  ClientSecurityFlags flags;
  ASSERT_TRUE(SetSecurityFlag("--tls-ca", ca, &flags));
  ASSERT_TRUE(SetSecurityFlag("--token-file", token, &flags));
  EXPECT_FALSE(SetSecurityFlag("--token", "x", &flags));
  absl::StatusOr<ClientSecurity> security = LoadClientSecurity(flags);
  ASSERT_TRUE(security.ok()) << security.status();
  EXPECT_TRUE(security->tls);
  EXPECT_EQ(security->ca_pem, "CA PEM");
  EXPECT_EQ(security->token, "mbopt_abc");

  // Without options, the environment: MBOPT_TOKEN_FILE before MBOPT_TOKEN.
  ::setenv("MBOPT_TLS_CA", ca.c_str(), 1);
  security = LoadClientSecurity({});
  ASSERT_TRUE(security.ok()) << security.status();
  EXPECT_TRUE(security->tls);
  EXPECT_EQ(security->token, "mbopt_from_env");
  ::setenv("MBOPT_TOKEN_FILE", token.c_str(), 1);
  EXPECT_EQ(LoadClientSecurity({})->token, "mbopt_abc");
}

TEST_F(ClientSecurityTest, WhatCannotWorkIsRefusedNamingTheSetting) {
  auto message = [](const ClientSecurityFlags& flags) {
    return std::string(LoadClientSecurity(flags).status().message());
  };
  // Flags from option and value pairs, as a command line gives them.
  auto flags = [](std::initializer_list<std::pair<const char*, std::string>> options) {
    ClientSecurityFlags out;
    for (const auto& [option, value] : options) EXPECT_TRUE(SetSecurityFlag(option, value, &out)) << option;
    return out;
  };
  EXPECT_THAT(message(flags({{"--tls-ca", "/nonexistent/ca.pem"}})),
              HasSubstr("--tls-ca: cannot read /nonexistent/ca.pem"));
  EXPECT_THAT(message(flags({{"--tls-ca", Write("ca.pem", "x")}, {"--tls-cert", Write("c.pem", "x")}})),
              HasSubstr("--tls-cert is set but no key"));
  EXPECT_THAT(message(flags({{"--tls-cert", Write("c.pem", "x")}, {"--tls-key", Write("c.key", "x")}})),
              HasSubstr("only used over TLS"));
  EXPECT_THAT(message(flags({{"--tls-server-name", "node1"}})), HasSubstr("--tls-server-name is set but not --tls-ca"));
  EXPECT_THAT(message(flags({{"--token-file", Write("empty", "\n")}})), HasSubstr("the file is empty"));
  EXPECT_THAT(message(flags({{"--token-file", Write("two", "a b\n")}})), HasSubstr("space or control character"));
  ::setenv("MBOPT_TOKEN_FILE", "/nonexistent/token", 1);
  EXPECT_THAT(message({}), HasSubstr("MBOPT_TOKEN_FILE: cannot read /nonexistent/token"));
}

TEST_F(ClientSecurityTest, TokenFileOrKeyOthersCanReadIsRefusedWithTheChmodThatFixesIt) {
  using std::filesystem::perms;
  const std::string token = Write("alice.token", "mbopt_abc\n", perms::owner_read | perms::owner_write |
                                                                    perms::group_read | perms::others_read);
  ClientSecurityFlags flags;
  ASSERT_TRUE(SetSecurityFlag("--token-file", token, &flags));
  absl::StatusOr<ClientSecurity> security = LoadClientSecurity(flags);
  ASSERT_FALSE(security.ok());
  EXPECT_THAT(security.status().message(), HasSubstr("--token-file: the token file " + token + " has mode 0644"));
  EXPECT_THAT(security.status().message(), HasSubstr("readable by every user of this machine"));
  EXPECT_THAT(security.status().message(), HasSubstr("chmod 600 " + token));
  // The same file, fixed.
  std::filesystem::permissions(token, perms::owner_read | perms::owner_write);
  security = LoadClientSecurity(flags);
  ASSERT_TRUE(security.ok()) << security.status();
  EXPECT_EQ(security->token, "mbopt_abc");
  // Group-readable is fine when the group is the process's own (a
  // Kubernetes secret mounted with fsGroup): this file's group is ours.
  std::filesystem::permissions(token, perms::owner_read | perms::group_read);
  EXPECT_TRUE(LoadClientSecurity(flags).ok());

  // A worker's client key, writable by others.
  flags = {};
  ASSERT_TRUE(SetSecurityFlag("--tls-ca", Write("ca.pem", "x"), &flags));
  ASSERT_TRUE(SetSecurityFlag("--tls-cert", Write("c.pem", "x"), &flags));
  const std::string key = Write("c.key", "x", perms::owner_read | perms::owner_write | perms::others_write);
  ASSERT_TRUE(SetSecurityFlag("--tls-key", key, &flags));
  EXPECT_THAT(LoadClientSecurity(flags).status().message(),
              HasSubstr("--tls-key: the client key " + key + " has mode 0602: writable by every user"));
}

TEST(SecretFileMode, GroupMayReadOnlyWhenItIsTheProcesssOwnGroup) {
  constexpr unsigned kOwnGroup = 1000, kOtherGroup = 100;
  EXPECT_EQ(UnsafeSecretModeBits(0600, kOtherGroup, kOwnGroup), 0u);
  EXPECT_EQ(UnsafeSecretModeBits(0400, kOtherGroup, kOwnGroup), 0u);
  EXPECT_EQ(UnsafeSecretModeBits(0640, kOwnGroup, kOwnGroup), 0u);
  EXPECT_EQ(UnsafeSecretModeBits(0440, kOwnGroup, kOwnGroup), 0u);
  EXPECT_EQ(UnsafeSecretModeBits(0640, kOtherGroup, kOwnGroup), 0040u);
  EXPECT_EQ(UnsafeSecretModeBits(0660, kOwnGroup, kOwnGroup), 0020u);
  EXPECT_EQ(UnsafeSecretModeBits(0604, kOwnGroup, kOwnGroup), 0004u);
  EXPECT_EQ(UnsafeSecretModeBits(0602, kOwnGroup, kOwnGroup), 0002u);
  EXPECT_EQ(UnsafeSecretModeBits(0666, kOtherGroup, kOwnGroup), 0066u);
}

}  // namespace
}  // namespace mbopt::secure_channel
