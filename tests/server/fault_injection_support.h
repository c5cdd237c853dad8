// Helpers of the fault injection tests: an inscribed child with a client and a metrics scrape,
// scratch cache directories, random sphere sets, and a DistanceStream client child process to
// kill.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "inscribe/client/client.h"
#include "support/inscribed_process.h"

namespace inscribe::client::faults {

constexpr uid_t kNobody = 65534;

// A fresh directory under the system's temporary directory, removed (after making it writable
// again) at the end.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Creates path()/name (mode 0755) and returns it.
  std::string Sub(const std::string& name) const;

 private:
  std::filesystem::path path_;
};

// An inscribed child process (its stderr kept), ready to call.
class Server {
 public:
  // Starts INSCRIBED with `args` plus "--listen 127.0.0.1:0"; `prefix` is a command that
  // execs it (e.g. AsNobodyPrefix()), so the process id stays the server's.
  explicit Server(std::vector<std::string> args, const std::vector<std::string>& prefix = {});

  bool ready() const { return !address_.empty(); }
  const std::string& address() const { return address_; }
  pid_t pid() const { return process_->pid(); }
  Client& client() { return *client_; }
  std::string log() const { return process_->log(); }

  // The value of the unlabelled sample `name` on the metrics endpoint (--metrics-listen, or
  // -1 when there is none or the scrape failed).
  double Metric(const std::string& name) const;

  // SIGTERM, then the exit code (or -1 when it did not exit within 30 s or died of a signal).
  int Stop();
  // SIGKILL; the raw wait status, -1 when it was not reaped.
  int Kill();

 private:
  std::unique_ptr<testing::InscribedProcess> process_;
  std::string address_;
  std::unique_ptr<Client> client_;
  int metrics_port_ = 0;
};

// setpriv dropping to uid/gid 65534 with no supplementary groups, or empty when that does not
// work here (no setpriv, no CAP_SETUID, or nobody cannot execute INSCRIBED).
std::vector<std::string> AsNobodyPrefix();

// chmod `mode` on `dir` and every directory under it.
void ChmodTree(const std::string& dir, std::filesystem::perms mode);
inline void ChmodTree(const std::string& dir, int mode) {
  ChmodTree(dir, static_cast<std::filesystem::perms>(mode));
}

// Entry files (dir/<2 hex>/<64 hex>) and temporary files ("*.tmp-*") under a cache directory.
std::vector<std::filesystem::path> EntryFiles(const std::string& dir);
int TempFiles(const std::string& dir);

std::string ReadBytes(const std::filesystem::path& path);
void WriteBytes(const std::filesystem::path& path, const std::string& bytes);

// Distinct small sets, cheap to store: n random balls from `seed`.
SphereSet RandomSet(int n, std::uint64_t seed);

// Equal sphere by sphere (a gtest failure otherwise).
void ExpectSameSpheres(const SphereSet& actual, const SphereSet& expected);

// Polls `condition` every 50 ms until it holds (true) or `timeout` passes (false).
bool WaitFor(std::chrono::milliseconds timeout, const std::function<bool()>& condition);

// This test binary run as "--stream-client ADDRESS PAIRS": stores two large random sets,
// opens a DistanceStream, prints "frame sent" to stdout and sends one frame of PAIRS pose
// pairs, then waits for its answer (until killed). Returns the exit code.
int RunStreamClient(const std::string& address, int pairs);

// RunStreamClient as a child process.
class StreamClientChild {
 public:
  StreamClientChild(const std::string& address, int pairs);
  ~StreamClientChild();  // kills it if still running
  StreamClientChild(const StreamClientChild&) = delete;
  StreamClientChild& operator=(const StreamClientChild&) = delete;

  // Reads its stdout up to "frame sent"; false when it ended first.
  bool WaitUntilFrameSent();
  void Kill();

 private:
  pid_t pid_ = -1;
  FILE* stdout_ = nullptr;
};

}  // namespace inscribe::client::faults
