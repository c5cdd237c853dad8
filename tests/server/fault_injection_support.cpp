#include "fault_injection_support.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <random>
#include <sstream>
#include <thread>
#include <utility>

#include "support/inscribed_process.h"
#include "support/sphere_sets.h"

extern char** environ;

namespace inscribe::client::faults {
namespace fs = std::filesystem;
namespace {

// Spawns `argv` (argv[0] an absolute path) with stdout piped back; stderr inherited. The pid,
// or -1.
pid_t Spawn(std::vector<std::string> argv, FILE** out) {
  int fds[2];
  if (::pipe(fds) != 0) return -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  std::vector<char*> raw;
  for (std::string& arg : argv) raw.push_back(arg.data());
  raw.push_back(nullptr);
  pid_t pid = -1;
  if (::posix_spawn(&pid, raw[0], &actions, nullptr, raw.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&actions);
  ::close(fds[1]);
  *out = ::fdopen(fds[0], "r");
  return pid;
}

}  // namespace

ScratchDir::ScratchDir() {
  std::random_device random;
  path_ = fs::temp_directory_path() /
          ("inscribe-faults-" + std::to_string(::getpid()) + "-" + std::to_string(random()));
  fs::create_directories(path_);
  fs::permissions(path_, static_cast<fs::perms>(0755));
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  ChmodTree(path_.string(), fs::perms::owner_all);
  fs::remove_all(path_, ignored);
}

SphereSet RandomSet(int n, std::uint64_t seed) {
  SphereSet set;
  set.spheres = testing::RandomBalls(n, 1.0, 0.01, 0.1, seed);
  return set;
}

void ExpectSameSpheres(const SphereSet& actual, const SphereSet& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    ASSERT_EQ(actual.spheres[i].center, expected.spheres[i].center) << "sphere " << i;
    ASSERT_EQ(actual.spheres[i].radius, expected.spheres[i].radius) << "sphere " << i;
  }
}

std::string ScratchDir::Sub(const std::string& name) const {
  const fs::path sub = path_ / name;
  fs::create_directories(sub);
  fs::permissions(sub, static_cast<fs::perms>(0755));
  return sub.string();
}

Server::Server(std::vector<std::string> args, const std::vector<std::string>& prefix) {
  args.insert(args.begin(), {"--listen", "127.0.0.1:0"});
  if (std::find(args.begin(), args.end(), "--metrics-listen") == args.end()) {
    args.insert(args.end(), {"--metrics-listen", "127.0.0.1:0"});
  }
  std::string binary = INSCRIBED;
  if (!prefix.empty()) {
    args.insert(args.begin(), binary);
    args.insert(args.begin(), prefix.begin() + 1, prefix.end());
    binary = prefix.front();
  }
  process_ = std::make_unique<testing::InscribedProcess>(binary, args);
  if (!process_->started()) return;
  address_ = process_->WaitUntilListening();
  if (address_.empty()) return;
  process_->DrainLogInBackground();
  // "... metrics_port=N" on the event=serving line, logged before the ready line.
  const std::string log = process_->log();
  const std::size_t at = log.find("metrics_port=");
  if (at != std::string::npos) metrics_port_ = std::atoi(log.c_str() + at + 13);
  client_ = std::make_unique<Client>(MakeGrpcConnection(address_));
}

double Server::Metric(const std::string& name) const {
  if (metrics_port_ == 0) return -1;
  std::istringstream body(testing::ScrapeMetrics(metrics_port_));
  std::string line;
  while (std::getline(body, line)) {
    if (line.rfind(name + " ", 0) == 0) return std::strtod(line.c_str() + name.size() + 1, nullptr);
  }
  return -1;
}

int Server::Stop() {
  const int status = process_->StopWith(SIGTERM, std::chrono::seconds(30));
  return status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int Server::Kill() { return process_->StopWith(SIGKILL, std::chrono::seconds(30)); }

std::vector<std::string> AsNobodyPrefix() {
  std::vector<std::string> prefix = {"/usr/bin/setpriv", "--reuid=65534", "--regid=65534",
                                     "--clear-groups", "--"};
  std::vector<std::string> check = prefix;
  check.push_back(INSCRIBED);
  check.push_back("--help");
  FILE* out = nullptr;
  const pid_t pid = Spawn(check, &out);
  if (out != nullptr) {
    char buffer[4096];
    while (std::fread(buffer, 1, sizeof buffer, out) > 0) {
    }
    std::fclose(out);
  }
  int status = 0;
  if (pid <= 0 || ::waitpid(pid, &status, 0) != pid || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0) {
    return {};
  }
  return prefix;
}

void ChmodTree(const std::string& dir, fs::perms mode) {
  std::error_code ignored;
  fs::permissions(dir, mode, ignored);
  for (auto it = fs::recursive_directory_iterator(dir, ignored);
       it != fs::recursive_directory_iterator(); it.increment(ignored)) {
    if (it->is_directory(ignored)) fs::permissions(it->path(), mode, ignored);
  }
}

std::vector<fs::path> EntryFiles(const std::string& dir) {
  std::vector<fs::path> files;
  std::error_code ignored;
  for (auto it = fs::recursive_directory_iterator(dir, ignored);
       it != fs::recursive_directory_iterator(); it.increment(ignored)) {
    const std::string name = it->path().filename().string();
    if (it->is_regular_file(ignored) && name.size() == 64 &&
        name.find_first_not_of("0123456789abcdef") == std::string::npos) {
      files.push_back(it->path());
    }
  }
  return files;
}

int TempFiles(const std::string& dir) {
  int count = 0;
  std::error_code ignored;
  for (auto it = fs::recursive_directory_iterator(dir, ignored);
       it != fs::recursive_directory_iterator(); it.increment(ignored)) {
    if (it->path().filename().string().find(".tmp-") != std::string::npos) ++count;
  }
  return count;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

bool WaitFor(std::chrono::milliseconds timeout, const std::function<bool()>& condition) {
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (condition()) return true;
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

int RunStreamClient(const std::string& address, int pairs) {
  Client client(MakeGrpcConnection(address));
  // Two dense clouds of 4,000 overlapping balls: each exact distance query descends deep into
  // both hierarchies, so the frame takes many seconds unless it is stopped.
  SphereSet a, b;
  a.spheres = testing::RandomBalls(4000, 1.0, 0.02, 0.05, 1);
  b.spheres = testing::RandomBalls(4000, 1.0, 0.02, 0.05, 2);
  absl::StatusOr<PutSphereSetResult> key_a = client.PutSphereSet(a);
  absl::StatusOr<PutSphereSetResult> key_b = client.PutSphereSet(b);
  if (!key_a.ok() || !key_b.ok()) {
    std::cerr << "stream client: PutSphereSet failed\n";
    return 2;
  }
  DistanceSessionOptions options;
  options.frame_timeout = std::chrono::milliseconds(120'000);
  absl::StatusOr<DistanceSession> session = client.OpenDistanceSession(options);
  if (!session.ok()) {
    std::cerr << "stream client: " << session.status() << "\n";
    return 2;
  }
  std::mt19937_64 rng(static_cast<std::uint64_t>(pairs));
  std::vector<PosePair> frame(static_cast<std::size_t>(pairs));
  for (PosePair& pair : frame) {
    pair.sphere_set_a = key_a->sphere_set_key;
    pair.sphere_set_b = key_b->sphere_set_key;
    pair.pose_a = testing::RandomPose(rng, 0.3);
    pair.pose_b = testing::RandomPose(rng, 0.3);
  }
  std::cout << "frame sent" << std::endl;
  absl::StatusOr<std::vector<DistanceResult>> answer = session->Query(frame);
  std::cerr << "stream client: the frame was answered (" << answer.status()
            << "); it should have been killed first\n";
  return 3;
}

StreamClientChild::StreamClientChild(const std::string& address, int pairs) {
  pid_ = Spawn({"/proc/self/exe", "--stream-client", address, std::to_string(pairs)}, &stdout_);
}

StreamClientChild::~StreamClientChild() {
  Kill();
  if (stdout_ != nullptr) std::fclose(stdout_);
}

bool StreamClientChild::WaitUntilFrameSent() {
  if (pid_ <= 0 || stdout_ == nullptr) return false;
  char line[256];
  while (std::fgets(line, sizeof line, stdout_) != nullptr) {
    if (std::string(line).rfind("frame sent", 0) == 0) return true;
  }
  return false;
}

void StreamClientChild::Kill() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  ::waitpid(pid_, nullptr, 0);
  pid_ = -1;
}

}  // namespace inscribe::client::faults
