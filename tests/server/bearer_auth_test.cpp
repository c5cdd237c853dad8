// The files behind authentication, on their own: the server's token file and header check
// (BearerAuthenticator), and the client library's ReadBearerToken and MakeTlsCredentials.
#include "bearer_auth.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/client/connection.h"
#include "support/test_certificates.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kToken[] = "s3cr3t-Token_with.punct~uation+/=";
constexpr char kOther[] = "another-token-0000000000";

BearerAuthenticator Make(const std::string& text) {
  absl::StatusOr<BearerAuthenticator> auth = BearerAuthenticator::FromText(text, "tokens.txt");
  EXPECT_TRUE(auth.ok()) << auth.status();
  return *std::move(auth);
}

TEST(BearerAuthenticator, ReadsOneTokenPerLineSkippingCommentsAndBlanks) {
  const BearerAuthenticator auth =
      Make(std::string("# header\n\n") + kToken + "\r\n\t" + kOther + "  \n  # " + "x\n");
  EXPECT_EQ(auth.token_count(), 2u);
  EXPECT_TRUE(auth.CheckHeader(std::string("Bearer ") + kToken).ok());
  EXPECT_TRUE(auth.CheckHeader(std::string("Bearer ") + kOther).ok());
  // A commented-out line is not a token.
  EXPECT_FALSE(auth.CheckHeader("Bearer # header").ok());
}

TEST(BearerAuthenticator, SchemeIsCaseInsensitiveAndSpacesAreTolerated) {
  const BearerAuthenticator auth = Make(kToken);
  for (const std::string& header :
       {std::string("bearer ") + kToken, std::string("BeArEr ") + kToken,
        std::string("Bearer\t") + kToken, std::string("  Bearer   ") + kToken + "  "}) {
    EXPECT_TRUE(auth.CheckHeader(header).ok()) << header;
  }
}

TEST(BearerAuthenticator, RefusesEverythingElseWithoutEchoingIt) {
  const BearerAuthenticator auth = Make(kToken);
  const std::string token = kToken;
  struct Case {
    std::string header;
    const char* message;
  };
  const Case cases[] = {
      {"Bearer " + token.substr(1), "invalid bearer token"},
      {"Bearer " + token + "x", "invalid bearer token"},
      {"Bearer " + token.substr(0, token.size() - 1), "invalid bearer token"},
      {"Bearer " + std::string(token.size(), 'a'), "invalid bearer token"},
      {"Bearer  ", "missing bearer token"},  // stripped to "Bearer"
      {"Bearer", "missing bearer token"},
      {"Bearer" + token, "missing bearer token"},  // no space after the scheme
      {"Basic " + token, "missing bearer token"},
      {token, "missing bearer token"},
      {"", "missing bearer token"},
  };
  for (const Case& c : cases) {
    const absl::Status status = auth.CheckHeader(c.header);
    EXPECT_EQ(status.code(), absl::StatusCode::kUnauthenticated) << c.header;
    EXPECT_THAT(status.message(), HasSubstr(c.message)) << c.header;
    EXPECT_THAT(status.message(), Not(HasSubstr(token.substr(0, 8)))) << c.header;
  }
  const absl::Status none = auth.CheckHeader(std::nullopt);
  EXPECT_EQ(none.code(), absl::StatusCode::kUnauthenticated);
  EXPECT_THAT(none.message(), HasSubstr("missing bearer token"));
}

TEST(BearerAuthenticator, MalformedFilesNameTheLineNotTheToken) {
  struct Case {
    std::string text;
    const char* where;
  };
  const Case cases[] = {
      {"", "holds no token"},
      {"# only\n#comments\n\n", "holds no token"},
      {std::string(kToken) + "\nfifteen-chars-x\n", "line 2"},  // 15 < 16
      {std::string("#\n") + "has space-in-the-middle-123\n", "line 2"},
      {std::string("caf\xc3\xa9-token-0123456789\n"), "line 1"},
      {std::string(kMaxBearerTokenLength + 1, 'z'), "line 1"},
  };
  for (const Case& c : cases) {
    absl::StatusOr<BearerAuthenticator> auth = BearerAuthenticator::FromText(c.text, "t.txt");
    EXPECT_EQ(auth.status().code(), absl::StatusCode::kInvalidArgument) << c.text;
    EXPECT_THAT(auth.status().message(), HasSubstr("t.txt")) << c.text;
    EXPECT_THAT(auth.status().message(), HasSubstr(c.where)) << c.text;
    EXPECT_THAT(auth.status().message(), Not(HasSubstr("fifteen")));
    EXPECT_THAT(auth.status().message(), Not(HasSubstr("middle")));
  }
  // Exactly the minimum length is accepted.
  EXPECT_TRUE(BearerAuthenticator::FromText(std::string(kMinBearerTokenLength, 'k'), "t").ok());
}

TEST(BearerAuthenticator, UnreadableFileIsFailedPrecondition) {
  const std::string path = "/nonexistent-dir/tokens";
  absl::StatusOr<BearerAuthenticator> auth = BearerAuthenticator::FromFile(path);
  EXPECT_EQ(auth.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(auth.status().message(), HasSubstr(path));
}

TEST(BearerAuthenticator, ReloadReplacesTheTokensWholeOrKeepsThem) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("inscribe-tokens-" + std::to_string(std::random_device{}()));
  const auto write = [&](const std::string& text) {
    std::ofstream(path, std::ios::binary) << text;
  };
  write(std::string(kToken) + "\n");
  absl::StatusOr<BearerAuthenticator> auth = BearerAuthenticator::FromFile(path.string());
  ASSERT_TRUE(auth.ok()) << auth.status();
  const std::string token = std::string("Bearer ") + kToken;
  const std::string other = std::string("Bearer ") + kOther;

  write(std::string(kOther) + "\n");
  EXPECT_TRUE(auth->CheckHeader(token).ok()) << "the file is read on Reload only";
  ASSERT_TRUE(auth->Reload().ok());
  EXPECT_EQ(auth->token_count(), 1u);
  EXPECT_FALSE(auth->CheckHeader(token).ok());
  EXPECT_TRUE(auth->CheckHeader(other).ok());

  // A file that fails any rule changes nothing, not even its valid lines.
  write(std::string(kToken) + "\nshort\n");
  const absl::Status bad = auth->Reload();
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.message(), HasSubstr("line 2"));
  EXPECT_FALSE(auth->CheckHeader(token).ok());
  EXPECT_TRUE(auth->CheckHeader(other).ok());

  std::filesystem::remove(path);
  EXPECT_EQ(auth->Reload().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(auth->CheckHeader(other).ok());

  // Tokens given as text have no file to read again.
  BearerAuthenticator from_text = Make(kToken);
  EXPECT_EQ(from_text.Reload().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(from_text.CheckHeader(token).ok());
}

// Checks on several threads while the set is replaced: each sees one whole set, old or new.
TEST(BearerAuthenticator, ChecksDuringReloadsSeeOneWholeSet) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("inscribe-tokens-" + std::to_string(std::random_device{}()));
  std::ofstream(path, std::ios::binary) << kToken << "\n" << kOther << "\n";
  absl::StatusOr<BearerAuthenticator> auth = BearerAuthenticator::FromFile(path.string());
  ASSERT_TRUE(auth.ok()) << auth.status();
  std::atomic<bool> stop{false};
  std::atomic<int> refused{0};
  std::vector<std::thread> checkers;
  for (int t = 0; t < 3; ++t) {
    checkers.emplace_back([&] {
      while (!stop.load()) {
        // kToken is in every version of the file.
        if (!auth->CheckHeader(std::string("Bearer ") + kToken).ok()) ++refused;
      }
    });
  }
  for (int i = 0; i < 200; ++i) {
    std::ofstream(path, std::ios::binary) << kToken << "\n"
                                          << (i % 2 == 0 ? "" : std::string(kOther) + "\n");
    EXPECT_TRUE(auth->Reload().ok());
  }
  stop = true;
  for (std::thread& checker : checkers) checker.join();
  EXPECT_EQ(refused.load(), 0);
  std::filesystem::remove(path);
}

// --- The client side's files ------------------------------------------------------------

class ClientSecurityFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    certs_ = new testing::TestCertificates(testing::MakeTestCertificates());
  }
  static void TearDownTestSuite() {
    certs_->Remove();
    delete certs_;
  }
  void SetUp() override { ASSERT_TRUE(certs_->error.empty()) << certs_->error; }

  static std::string WriteFile(const std::string& name, const std::string& text) {
    return certs_->Write(name, text);
  }

  static testing::TestCertificates* certs_;
};

testing::TestCertificates* ClientSecurityFiles::certs_ = nullptr;

TEST_F(ClientSecurityFiles, ReadBearerTokenTakesTheFirstTokenLine) {
  const std::string path =
      WriteFile("token", std::string("# for staging\n\n  ") + kToken + " \r\n" + kOther + "\n");
  absl::StatusOr<std::string> token = client::ReadBearerToken(path);
  ASSERT_TRUE(token.ok()) << token.status();
  EXPECT_EQ(*token, kToken);
}

TEST_F(ClientSecurityFiles, ReadBearerTokenErrorsNameTheFile) {
  const std::string missing = (certs_->dir / "missing-token").string();
  const std::string comments = WriteFile("comments", "# none\n\n");
  const std::string spaced = WriteFile("spaced", "two words\n");
  const std::string control = WriteFile("control", "tab\tinside\n");
  for (const std::string& path : {missing, comments, spaced, control}) {
    absl::StatusOr<std::string> token = client::ReadBearerToken(path);
    EXPECT_EQ(token.status().code(), absl::StatusCode::kInvalidArgument) << path;
    EXPECT_THAT(token.status().message(), HasSubstr(path));
    EXPECT_THAT(token.status().message(), Not(HasSubstr("words")));
  }
}

TEST_F(ClientSecurityFiles, MakeTlsCredentialsAcceptsTheTestPki) {
  EXPECT_TRUE(client::MakeTlsCredentials({certs_->ca, "", ""}).ok());
  EXPECT_TRUE(
      client::MakeTlsCredentials({certs_->ca, certs_->client_cert, certs_->client_key}).ok());
  EXPECT_TRUE(client::MakeTlsCredentials({"", certs_->client_cert, certs_->client_key}).ok());
}

TEST_F(ClientSecurityFiles, MakeTlsCredentialsErrorsNameTheFile) {
  const std::string missing = (certs_->dir / "missing.pem").string();
  const std::string text = WriteFile("text.pem", "not pem at all\n");
  struct Case {
    client::TlsFiles files;
    std::string names;
  };
  const Case cases[] = {
      {{missing, "", ""}, missing},
      {{text, "", ""}, text},
      {{certs_->client_key, "", ""}, certs_->client_key},  // a key given as the CA
      {{certs_->ca, certs_->client_cert, missing}, missing},
      {{certs_->ca, certs_->client_cert, certs_->client_cert}, certs_->client_cert},
      {{certs_->ca, certs_->client_key, certs_->client_key}, certs_->client_key},
      {{certs_->ca, certs_->client_cert, ""}, "both"},
      {{certs_->ca, "", certs_->client_key}, "both"},
  };
  for (const Case& c : cases) {
    auto credentials = client::MakeTlsCredentials(c.files);
    EXPECT_EQ(credentials.status().code(), absl::StatusCode::kInvalidArgument) << c.names;
    EXPECT_THAT(credentials.status().message(), HasSubstr(c.names));
  }
}

}  // namespace
}  // namespace inscribe::server
