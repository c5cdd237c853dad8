// inscribed with TLS, client certificates and bearer tokens, as an operator runs it, and the
// `inscribe` CLI's --tls-ca/--tls-cert/--tls-key/--token-file against it: what works, what
// is refused, and the exit codes of each refusal.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "support/inscribed_process.h"
#include "support/test_certificates.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kToken[] = "cli-test-token-6f1d2a9b7c";
constexpr int kExitBadInput = 2;
constexpr int kExitServerUnavailable = 69;
constexpr int kExitNotAuthorized = 77;

class CliSecurity : public ::testing::Test {
 protected:
  // One server for the suite: TLS, client certificates from the test CA, one token.
  static void SetUpTestSuite() {
    certs_ = new testing::TestCertificates(testing::MakeTestCertificates());
    if (!certs_->error.empty()) return;
    token_file_ = WriteFile("token", std::string("# the CLI's token\n") + kToken + "\n");
    tokens_file_ = WriteFile("tokens", std::string("# accepted\n") + kToken + "\n");
    server_ = new testing::InscribedProcess(
        INSCRIBED,
        {"--listen", "127.0.0.1:0", "--jobs", "1", "--tls-cert", certs_->server_cert, "--tls-key",
         certs_->server_key, "--tls-client-ca", certs_->ca, "--auth-tokens", tokens_file_});
    if (server_->started()) address_ = server_->WaitUntilListening();
    server_->DrainLogInBackground();
  }
  static void TearDownTestSuite() {
    delete server_;
    certs_->Remove();
    delete certs_;
  }
  void SetUp() override {
    ASSERT_TRUE(certs_->error.empty()) << certs_->error;
    ASSERT_FALSE(address_.empty()) << server_->log();
  }

  static std::string WriteFile(const std::string& name, const std::string& text) {
    const std::filesystem::path path = certs_->dir / name;
    std::ofstream(path) << text;
    return path.string();
  }

  // `inscribe stats` against the suite's server with `flags`; a short --timeout because
  // refused handshakes are UNAVAILABLE, which the client retries until then.
  static CliRun Stats(const std::string& flags) {
    return RunCli("stats --timeout 3 --server " + address_ + " " + flags);
  }
  static std::string Tls(bool client_certificate) {
    std::string flags = "--tls-ca " + Quote(certs_->ca);
    if (client_certificate) {
      flags +=
          " --tls-cert " + Quote(certs_->client_cert) + " --tls-key " + Quote(certs_->client_key);
    }
    return flags;
  }

  static testing::TestCertificates* certs_;
  static testing::InscribedProcess* server_;
  static std::string address_;
  static std::string token_file_;
  static std::string tokens_file_;
};

testing::TestCertificates* CliSecurity::certs_ = nullptr;
testing::InscribedProcess* CliSecurity::server_ = nullptr;
std::string CliSecurity::address_;
std::string CliSecurity::token_file_;
std::string CliSecurity::tokens_file_;

TEST_F(CliSecurity, StatsWithCertificateAndTokenSucceeds) {
  const CliRun run = Stats(Tls(true) + " --token-file " + Quote(token_file_));
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("computations"));
}

TEST_F(CliSecurity, StatsWithoutTokenIsUnauthenticated) {
  const CliRun run = Stats(Tls(true));
  EXPECT_EQ(run.exit_code, kExitNotAuthorized) << run.err;
  EXPECT_THAT(run.err, HasSubstr("UNAUTHENTICATED"));
  EXPECT_THAT(run.err, HasSubstr("missing bearer token"));
  EXPECT_EQ(run.out, "");
}

TEST_F(CliSecurity, StatsWithWrongTokenIsUnauthenticatedWithoutEchoingIt) {
  const std::string wrong = WriteFile("wrong", "cli-wrong-token-123456789\n");
  const CliRun run = Stats(Tls(true) + " --token-file " + Quote(wrong));
  EXPECT_EQ(run.exit_code, kExitNotAuthorized) << run.err;
  EXPECT_THAT(run.err, HasSubstr("invalid bearer token"));
  EXPECT_THAT(run.err, Not(HasSubstr("cli-wrong-token")));
}

TEST_F(CliSecurity, StatsWithoutClientCertificateCannotConnect) {
  const CliRun run = Stats(Tls(false) + " --token-file " + Quote(token_file_));
  EXPECT_EQ(run.exit_code, kExitServerUnavailable) << run.err;
  EXPECT_THAT(run.err, HasSubstr("UNAVAILABLE"));
}

TEST_F(CliSecurity, PlaintextStatsCannotConnect) {
  const CliRun run = Stats("--token-file " + Quote(token_file_));
  EXPECT_EQ(run.exit_code, kExitServerUnavailable) << run.err;
}

TEST_F(CliSecurity, HalfAClientCertificateIsBadInput) {
  const CliRun run = Stats("--tls-ca " + Quote(certs_->ca) + " --tls-cert " +
                           Quote(certs_->client_cert) + " --token-file " + Quote(token_file_));
  EXPECT_EQ(run.exit_code, kExitBadInput) << run.err;
  EXPECT_THAT(run.err, HasSubstr("key"));
}

// inscribed itself: bad files stop it before it listens; tokens over plaintext beyond
// loopback are allowed but warned about.
int ExitStatusOf(testing::InscribedProcess& process) {
  const int status = process.StopWith(0, std::chrono::seconds(30));
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST_F(CliSecurity, InscribedRefusesTokenFileWithoutTokens) {
  const std::string comments = WriteFile("comments", "# to be filled in\n\n");
  testing::InscribedProcess process(INSCRIBED,
                                    {"--listen", "127.0.0.1:0", "--auth-tokens", comments});
  ASSERT_TRUE(process.started());
  EXPECT_EQ(process.WaitUntilListening(), "");
  EXPECT_EQ(ExitStatusOf(process), 1);
  EXPECT_THAT(process.log(), HasSubstr("holds no token"));
  EXPECT_THAT(process.log(), HasSubstr(comments));
}

TEST_F(CliSecurity, InscribedRefusesKeyThatIsNotTheCertificates) {
  testing::InscribedProcess process(
      INSCRIBED, {"--listen", "127.0.0.1:0", "--tls-cert", certs_->server_cert, "--tls-key",
                  certs_->client_key});
  ASSERT_TRUE(process.started());
  EXPECT_EQ(process.WaitUntilListening(), "");
  EXPECT_EQ(ExitStatusOf(process), 1);
  EXPECT_THAT(process.log(), HasSubstr("is not the key of"));
}

TEST_F(CliSecurity, InscribedWarnsOfTokensOverPlaintextBeyondLoopback) {
  for (const std::string& listen : {std::string("0.0.0.0:0"), std::string("127.0.0.1:0")}) {
    SCOPED_TRACE(listen);
    testing::InscribedProcess process(INSCRIBED,
                                      {"--listen", listen, "--auth-tokens", tokens_file_});
    ASSERT_TRUE(process.started());
    ASSERT_NE(process.WaitUntilListening(), "") << process.log();
    const bool warned = process.log().find("event=plaintext_tokens") != std::string::npos;
    EXPECT_EQ(warned, listen == "0.0.0.0:0") << process.log();
    EXPECT_THAT(process.log(), Not(HasSubstr(kToken)));
    process.StopWith(SIGTERM, std::chrono::seconds(30));
  }
}

}  // namespace
}  // namespace inscribe
