// A one-line progress bar on stderr for long runs: shown only when stderr is a terminal and
// only once a run has lasted a second, so short runs and pipes/logs stay clean.
#pragma once

#include <chrono>
#include <string>

namespace inscribe::cli {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();  // clears the line if it was drawn

  // fraction in [0, 1]; cheap to call often (redraws at most 10 times a second).
  void Update(double fraction);

 private:
  std::string label_;
  bool enabled_ = false;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace inscribe::cli
