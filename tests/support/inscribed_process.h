// The inscribed executable as a child process, for tests that run it as an operator would:
// start it with flags, learn its address from the ready line on stderr, stop it by signal.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace inscribe::testing {

class InscribedProcess {
 public:
  // Spawns `binary` with `args`, its stderr piped to this object. started() says whether the
  // spawn worked.
  InscribedProcess(const std::string& binary, std::vector<std::string> args);
  // SIGKILL if still running, then reaps it.
  ~InscribedProcess();
  InscribedProcess(const InscribedProcess&) = delete;
  InscribedProcess& operator=(const InscribedProcess&) = delete;

  bool started() const { return pid_ > 0 && stderr_ != nullptr; }

  // The child's process id (for /proc/<pid>/status, signals); -1 when the spawn failed.
  pid_t pid() const { return pid_; }

  // Reads stderr up to the line "inscribed listening on HOST:PORT" and returns HOST:PORT, or
  // "" when the process ended first.
  std::string WaitUntilListening();

  // For a server that runs for the whole test: reads (and keeps) the rest of its stderr on a
  // thread, so that its log lines never fill the pipe and block it.
  void DrainLogInBackground();

  // Sends `signal` (0: none, just wait), then reads the rest of stderr and reaps the process.
  // The wait status, or -1 if it did not exit within `timeout`.
  int StopWith(int signal, std::chrono::seconds timeout);

  // Everything read from stderr so far.
  std::string log() const;

 private:
  pid_t pid_ = -1;
  FILE* stderr_ = nullptr;
  bool exited_ = false;
  mutable std::mutex log_mutex_;
  std::string log_;  // guarded by log_mutex_
  std::thread drain_;
};

// Whether this build (and so the inscribed it starts) runs under ASan or TSan: resident memory
// then includes the sanitizer's shadow memory and quarantine, so bounds on it do not apply.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
// How much longer a call's deadline in a test is under a sanitizer: ctest's factor for its time
// limits, which tests/CMakeLists.txt defines for every target linking inscribe_test_support.
#ifndef INSCRIBE_TEST_TIME_SCALE
#error "INSCRIBE_TEST_TIME_SCALE comes from inscribe_test_support (tests/CMakeLists.txt)"
#endif
inline constexpr double kSanitizerTimeScale = INSCRIBE_TEST_TIME_SCALE;

// A test's wait or deadline `d`, stretched by kSanitizerTimeScale.
template <typename Rep, typename Period>
std::chrono::milliseconds Stretched(std::chrono::duration<Rep, Period> d) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(d * kSanitizerTimeScale);
}

// Memory of a process from /proc/<pid>/status, bytes; -1 where unreadable (e.g. it exited).
struct ProcessMemory {
  std::int64_t resident = -1;       // VmRSS: resident now
  std::int64_t peak_resident = -1;  // VmHWM: the most it has been resident so far
};
ProcessMemory ReadProcessMemory(pid_t pid);

// Sends `request` to 127.0.0.1:`port` over a plain socket and returns all the server sent back
// until it closed the connection (the metrics endpoint closes after one response); empty on
// any failure.
std::string ExchangeOnLoopback(int port, const std::string& request);

// GET /metrics from 127.0.0.1:`port`: the response body, or empty on any failure.
std::string ScrapeMetrics(int port);

// A loopback port that was free a moment ago (bound by the kernel's choice, then released):
// a server address nothing listens on, for unreachable-server tests.
int UnusedLoopbackPort();

}  // namespace inscribe::testing
