// A redis-server child process on loopback for tests of the shared cache tier: no persistence,
// its own port, stopped, frozen or killed by signal; plus a tiny hiredis client to look at or
// plant values.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace inscribe::testing {

class RedisProcess {
 public:
  // Starts `redis-server --save "" --appendonly no --port PORT --bind 127.0.0.1` plus `extra`
  // (e.g. {"--requirepass", "secret"}); port 0 = UnusedLoopbackPort(). Then waits (up to 10 s)
  // until it answers PING; ready() says whether it did.
  explicit RedisProcess(int port = 0, std::vector<std::string> extra = {},
                        std::string password = "");
  // SIGKILL if still running, then reaps it.
  ~RedisProcess();
  RedisProcess(const RedisProcess&) = delete;
  RedisProcess& operator=(const RedisProcess&) = delete;

  bool ready() const { return ready_; }
  int port() const { return port_; }
  // "redis://127.0.0.1:PORT" (with ":PASSWORD@" when given one).
  std::string url() const;

  void Kill();    // SIGKILL and reap: the port refuses connections at once
  void Freeze();  // SIGSTOP: connections are still accepted by the kernel, never answered
  void Thaw();    // SIGCONT

  // Direct commands (each on a fresh connection, 2 s timeout); nullopt on any failure.
  std::optional<std::string> Get(const std::string& key) const;  // "" payloads are fine
  bool Set(const std::string& key, const std::string& value) const;
  std::optional<std::vector<std::string>> Keys(const std::string& pattern) const;

 private:
  bool Ping() const;

  int port_ = 0;
  std::string password_;
  pid_t pid_ = -1;
  bool ready_ = false;
};

}  // namespace inscribe::testing
