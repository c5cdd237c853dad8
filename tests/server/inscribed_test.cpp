// The inscribed executable as an operator runs it: start, learn the port from stderr, serve a
// call, reload its token file on SIGHUP, stop on SIGTERM with exit status 0.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/client/client.h"
#include "inscribe/client/connection.h"
#include "support/inscribed_process.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

TEST(Inscribed, ServesOnAPickedPortAndStopsCleanlyOnSigterm) {
  // A grace period far longer than the stop may take: the client's idle connection must not
  // hold the server until the grace period ends.
  testing::InscribedProcess inscribed(
      INSCRIBED, {"--listen", "127.0.0.1:0", "--jobs", "1", "--shutdown-grace", "600"});
  ASSERT_TRUE(inscribed.started());
  const std::string address = inscribed.WaitUntilListening();
  ASSERT_THAT(address, ::testing::StartsWith("127.0.0.1:")) << inscribed.log();
  EXPECT_NE(address, "127.0.0.1:0");

  client::Client client(client::MakeGrpcConnection(address));
  absl::StatusOr<client::InspectMeshResult> result = client.InspectMesh(testing::UnitCube());
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_TRUE(result->report.usable());

  const int status = inscribed.StopWith(SIGTERM, std::chrono::seconds(30));
  ASSERT_NE(status, -1) << "inscribed did not stop within 30 s of SIGTERM";
  ASSERT_TRUE(WIFEXITED(status)) << inscribed.log();
  EXPECT_EQ(WEXITSTATUS(status), 0) << inscribed.log();
  EXPECT_THAT(inscribed.log(), HasSubstr("event=call method=InspectMesh"));
  EXPECT_THAT(inscribed.log(), HasSubstr("code=OK"));
  EXPECT_THAT(inscribed.log(), HasSubstr("event=stopped"));
}

TEST(Inscribed, SigintAlsoStopsIt) {
  testing::InscribedProcess inscribed(INSCRIBED, {"--listen", "127.0.0.1:0"});
  ASSERT_TRUE(inscribed.started());
  ASSERT_FALSE(inscribed.WaitUntilListening().empty()) << inscribed.log();
  const int status = inscribed.StopWith(SIGINT, std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status)) << inscribed.log();
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// Polls (up to 30 s; the log arrives on a pipe) until `inscribed`'s log holds `count` lines
// with `text`.
bool LogShows(const testing::InscribedProcess& inscribed, const std::string& text, int count) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (;;) {
    const std::string log = inscribed.log();
    int seen = 0;
    for (std::size_t at = log.find(text); at != std::string::npos; at = log.find(text, at + 1)) {
      ++seen;
    }
    if (seen >= count) return true;
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

TEST(Inscribed, SighupReloadsTheTokenFileAndKeepsItWhenBad) {
  const std::filesystem::path tokens =
      std::filesystem::temp_directory_path() /
      ("inscribed-tokens-" + std::to_string(std::random_device{}()));
  const std::string old_token = "old-token-0123456789abcdef";
  const std::string new_token = "new-token-fedcba9876543210";
  std::ofstream(tokens) << old_token << "\n";
  testing::InscribedProcess inscribed(
      INSCRIBED, {"--listen", "127.0.0.1:0", "--jobs", "1", "--auth-tokens", tokens.string()});
  ASSERT_TRUE(inscribed.started());
  const std::string address = inscribed.WaitUntilListening();
  ASSERT_FALSE(address.empty()) << inscribed.log();
  inscribed.DrainLogInBackground();
  const auto stats_with = [&](const std::string& token) {
    client::ConnectionOptions options;
    options.bearer_token = token;
    client::Client client(client::MakeGrpcConnection(address, options));
    return client.CacheStats().status().code();
  };
  EXPECT_EQ(stats_with(new_token), absl::StatusCode::kUnauthenticated);

  std::ofstream(tokens) << new_token << "\n";
  kill(inscribed.pid(), SIGHUP);
  ASSERT_TRUE(LogShows(inscribed, "event=reload", 1)) << inscribed.log();
  EXPECT_THAT(inscribed.log(),
              HasSubstr("level=info event=reload signal=SIGHUP tokens=reloaded tls=off"));
  EXPECT_EQ(stats_with(new_token), absl::StatusCode::kOk);
  EXPECT_EQ(stats_with(old_token), absl::StatusCode::kUnauthenticated);

  std::ofstream(tokens) << "# all retired\n";
  kill(inscribed.pid(), SIGHUP);
  ASSERT_TRUE(LogShows(inscribed, "event=reload", 2)) << inscribed.log();
  EXPECT_THAT(inscribed.log(), HasSubstr("level=error event=reload signal=SIGHUP tokens=kept"));
  EXPECT_THAT(inscribed.log(), HasSubstr("holds no token"));
  EXPECT_EQ(stats_with(new_token), absl::StatusCode::kOk);

  const int status = inscribed.StopWith(SIGTERM, std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status)) << inscribed.log();
  EXPECT_EQ(WEXITSTATUS(status), 0);
  std::filesystem::remove(tokens);
}

TEST(Inscribed, BadFlagValueIsAUsageError) {
  testing::InscribedProcess inscribed(INSCRIBED, {"--max-queue", "0"});
  ASSERT_TRUE(inscribed.started());
  EXPECT_EQ(inscribed.WaitUntilListening(), "");
  const int status = inscribed.StopWith(0, std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status));
  EXPECT_NE(WEXITSTATUS(status), 0);
  EXPECT_THAT(inscribed.log(), HasSubstr("--max-queue"));
}

TEST(Inscribed, BadCacheDiskBytesIsAnErrorNamingTheFlag) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--cache-disk-bytes", "lots"},
        std::vector<std::string>{"--cache-disk-bytes", "12x"},
        std::vector<std::string>{"--cache-disk-bytes=-5"}}) {
    SCOPED_TRACE(args.back());
    std::vector<std::string> all = {"--listen", "127.0.0.1:0"};
    all.insert(all.end(), args.begin(), args.end());
    testing::InscribedProcess inscribed(INSCRIBED, all);
    ASSERT_TRUE(inscribed.started());
    EXPECT_EQ(inscribed.WaitUntilListening(), "");
    const int status = inscribed.StopWith(0, std::chrono::seconds(30));
    ASSERT_TRUE(status != -1 && WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
    EXPECT_THAT(inscribed.log(), HasSubstr("--cache-disk-bytes"));
  }
}

}  // namespace
}  // namespace inscribe::server
