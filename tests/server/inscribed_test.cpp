// The inscribed executable as an operator runs it: start, learn the port from stderr, serve a
// call, stop on SIGTERM with exit status 0.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/client/client.h"
#include "support/synthetic_meshes.h"

extern char** environ;

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

constexpr char kReadyPrefix[] = "inscribed listening on ";

// A child process running inscribed with its stderr piped to us.
class Inscribed {
 public:
  explicit Inscribed(std::vector<std::string> args) {
    int fds[2];
    if (pipe(fds) != 0) return;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    args.insert(args.begin(), INSCRIBED);
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, INSCRIBED, &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    stderr_ = fdopen(fds[0], "r");
  }
  ~Inscribed() {
    if (pid_ > 0 && !exited_) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
    if (stderr_ != nullptr) fclose(stderr_);
  }

  bool started() const { return pid_ > 0 && stderr_ != nullptr; }

  // Reads stderr up to the ready line and returns its HOST:PORT ("" if the process ended).
  std::string WaitUntilListening() {
    char line[4096];
    while (fgets(line, sizeof line, stderr_) != nullptr) {
      log_ += line;
      const std::string text(line);
      const std::size_t at = text.find(kReadyPrefix);
      if (at != std::string::npos) {
        std::string address = text.substr(at + sizeof kReadyPrefix - 1);
        while (!address.empty() && (address.back() == '\n' || address.back() == '\r')) {
          address.pop_back();
        }
        return address;
      }
    }
    return "";
  }

  // Sends `signal`, then reads the rest of stderr and reaps the process. Returns the wait
  // status, or -1 if it did not exit within `timeout`.
  int StopWith(int signal, std::chrono::seconds timeout) {
    kill(pid_, signal);
    const auto give_up = std::chrono::steady_clock::now() + timeout;
    int status = 0;
    while (waitpid(pid_, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() > give_up) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    exited_ = true;
    char line[4096];
    while (fgets(line, sizeof line, stderr_) != nullptr) log_ += line;
    return status;
  }

  const std::string& log() const { return log_; }

 private:
  pid_t pid_ = -1;
  FILE* stderr_ = nullptr;
  bool exited_ = false;
  std::string log_;
};

TEST(Inscribed, ServesOnAPickedPortAndStopsCleanlyOnSigterm) {
  // A grace period far longer than the stop may take: the client's idle connection must not
  // hold the server until the grace period ends.
  Inscribed inscribed({"--listen", "127.0.0.1:0", "--jobs", "1", "--shutdown-grace", "600"});
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
  Inscribed inscribed({"--listen", "127.0.0.1:0"});
  ASSERT_TRUE(inscribed.started());
  ASSERT_FALSE(inscribed.WaitUntilListening().empty()) << inscribed.log();
  const int status = inscribed.StopWith(SIGINT, std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status)) << inscribed.log();
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST(Inscribed, BadFlagValueIsAUsageError) {
  Inscribed inscribed({"--max-queue", "0"});
  ASSERT_TRUE(inscribed.started());
  EXPECT_EQ(inscribed.WaitUntilListening(), "");
  const int status = inscribed.StopWith(0, std::chrono::seconds(30));
  ASSERT_TRUE(status != -1 && WIFEXITED(status));
  EXPECT_NE(WEXITSTATUS(status), 0);
  EXPECT_THAT(inscribed.log(), HasSubstr("--max-queue"));
}

}  // namespace
}  // namespace inscribe::server
