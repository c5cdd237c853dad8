// Progress on stderr for long runs. On a terminal: one redrawn line, shown only once a stage
// has lasted a second, so short runs stay clean. Elsewhere (a pipe, a log, CI): nothing, unless
// asked for with `--progress` or INSCRIBE_PROGRESS=1, which print plain lines instead: one as
// a stage starts, one per quarter of a measured stage, one as it ends.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace inscribe::cli {

enum class ProgressMode {
  kAuto,   // the redrawn line on a terminal, nothing elsewhere
  kLines,  // the redrawn line on a terminal, plain lines elsewhere
  kOff,    // nothing
};

// The process's mode: INSCRIBE_PROGRESS=1 (or "lines") gives kLines, 0 (or "off") kOff,
// unset kAuto; `--progress` (main) sets kLines. Read by every ProgressBar and ProgressStage.
ProgressMode ProgressModeFromEnvironment();
void SetProgressMode(ProgressMode mode);

// A stage measured by a fraction done (e.g. generating, fed by the service's messages).
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();  // clears the line if it was drawn; in lines mode, says it ended

  // fraction in [0, 1]; cheap to call often (redraws at most 10 times a second).
  void Update(double fraction);

 private:
  std::string label_;
  bool terminal_ = false;
  bool lines_ = false;
  bool drawn_ = false;
  int next_quarter_ = 1;  // lines mode: the next quarter to print a line at
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

// A stage without a measure of how far it is (reading a file, validating a mesh): on a
// terminal, "label ... 2.3s" redrawn by a thread while it lasts (after its first second); in
// lines mode, a line as it starts and one as it ends.
class ProgressStage {
 public:
  explicit ProgressStage(std::string label);
  ~ProgressStage();
  ProgressStage(const ProgressStage&) = delete;
  ProgressStage& operator=(const ProgressStage&) = delete;

 private:
  void Draw();

  std::string label_;
  bool lines_ = false;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable done_;
  bool finished_ = false;
  bool drawn_ = false;
  std::thread drawer_;
};

}  // namespace inscribe::cli
