#include "support/inscribed_process.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <utility>

extern char** environ;

namespace inscribe::testing {
namespace {

constexpr char kReadyPrefix[] = "inscribed listening on ";

}  // namespace

InscribedProcess::InscribedProcess(const std::string& binary, std::vector<std::string> args) {
  int fds[2];
  if (pipe(fds) != 0) return;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  args.insert(args.begin(), binary);
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  if (posix_spawn(&pid_, binary.c_str(), &actions, nullptr, argv.data(), environ) != 0) {
    pid_ = -1;
  }
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  stderr_ = fdopen(fds[0], "r");
}

InscribedProcess::~InscribedProcess() {
  if (pid_ > 0 && !exited_) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  if (drain_.joinable()) drain_.join();  // EOF once the process is gone
  if (stderr_ != nullptr) fclose(stderr_);
}

std::string InscribedProcess::WaitUntilListening() {
  char line[4096];
  while (fgets(line, sizeof line, stderr_) != nullptr) {
    const std::string text(line);
    {
      std::lock_guard<std::mutex> lock(log_mutex_);
      log_ += text;
    }
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

void InscribedProcess::DrainLogInBackground() {
  drain_ = std::thread([this] {
    char line[4096];
    while (fgets(line, sizeof line, stderr_) != nullptr) {
      std::lock_guard<std::mutex> lock(log_mutex_);
      log_ += line;
    }
  });
}

int InscribedProcess::StopWith(int signal, std::chrono::seconds timeout) {
  if (signal != 0) kill(pid_, signal);
  const auto give_up = std::chrono::steady_clock::now() + timeout;
  int status = 0;
  while (waitpid(pid_, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > give_up) return -1;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  exited_ = true;
  if (drain_.joinable()) {
    drain_.join();
  } else {
    char line[4096];
    while (fgets(line, sizeof line, stderr_) != nullptr) {
      std::lock_guard<std::mutex> lock(log_mutex_);
      log_ += line;
    }
  }
  return status;
}

std::string InscribedProcess::log() const {
  std::lock_guard<std::mutex> lock(log_mutex_);
  return log_;
}

ProcessMemory ReadProcessMemory(pid_t pid) {
  ProcessMemory memory;
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);) {
    // "VmRSS:\t  123456 kB"
    if (line.rfind("VmRSS:", 0) == 0) memory.resident = 1024 * std::stoll(line.substr(6));
    if (line.rfind("VmHWM:", 0) == 0) memory.peak_resident = 1024 * std::stoll(line.substr(6));
  }
  return memory;
}

std::string ExchangeOnLoopback(int port, const std::string& request) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return "";
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string response;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0 &&
      ::write(fd, request.data(), request.size()) == static_cast<ssize_t>(request.size())) {
    char buffer[4096];
    ssize_t got;
    while ((got = ::read(fd, buffer, sizeof buffer)) > 0) response.append(buffer, got);
  }
  ::close(fd);
  return response;
}

std::string ScrapeMetrics(int port) {
  const std::string response =
      ExchangeOnLoopback(port, "GET /metrics HTTP/1.0\r\nHost: 127.0.0.1\r\n\r\n");
  const std::size_t body = response.find("\r\n\r\n");
  return body == std::string::npos ? "" : response.substr(body + 4);
}

int UnusedLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(fd);
  return ntohs(address.sin_port);
}

}  // namespace inscribe::testing
