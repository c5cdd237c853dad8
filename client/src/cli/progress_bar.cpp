#include "progress_bar.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace inscribe::cli {
namespace {

std::atomic<ProgressMode> mode{ProgressMode::kAuto};

bool StderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

ProgressMode ProgressModeFromEnvironment() {
  const char* value = std::getenv("INSCRIBE_PROGRESS");
  if (value == nullptr || *value == '\0') return ProgressMode::kAuto;
  if (std::strcmp(value, "0") == 0 || std::strcmp(value, "off") == 0) return ProgressMode::kOff;
  return ProgressMode::kLines;
}

void SetProgressMode(ProgressMode m) { mode.store(m); }

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), start_(std::chrono::steady_clock::now()), last_draw_(start_) {
  const ProgressMode m = mode.load();
  terminal_ = m != ProgressMode::kOff && StderrIsTerminal();
  lines_ = m == ProgressMode::kLines && !terminal_;
  if (lines_) {
    std::fprintf(stderr, "inscribe: %s\n", label_.c_str());
    std::fflush(stderr);
  }
}

ProgressBar::~ProgressBar() {
  if (drawn_) std::fprintf(stderr, "\r\033[K");
  if (lines_) {
    std::fprintf(stderr, "inscribe: %s: done in %.1f s\n", label_.c_str(), Since(start_));
  }
}

void ProgressBar::Update(double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  if (lines_) {
    // A line as each quarter is reached (the constructor said it started).
    if (fraction * 4.0 >= next_quarter_ && next_quarter_ < 4) {
      std::fprintf(stderr, "inscribe: %s %3d%% %.1f s\n", label_.c_str(),
                   static_cast<int>(fraction * 100.0), Since(start_));
      std::fflush(stderr);
      next_quarter_ = static_cast<int>(fraction * 4.0) + 1;
    }
    return;
  }
  if (!terminal_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - start_ < std::chrono::seconds(1)) return;
  if (drawn_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
  last_draw_ = now;
  drawn_ = true;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%% %.1fs", label_.c_str(), filled,
               "##############################", kWidth - filled, "",
               static_cast<int>(fraction * 100.0), Since(start_));
  std::fflush(stderr);
}

ProgressStage::ProgressStage(std::string label)
    : label_(std::move(label)), start_(std::chrono::steady_clock::now()) {
  const ProgressMode m = mode.load();
  if (m == ProgressMode::kOff) return;
  if (StderrIsTerminal()) {
    drawer_ = std::thread([this] { Draw(); });
  } else if (m == ProgressMode::kLines) {
    lines_ = true;
    std::fprintf(stderr, "inscribe: %s\n", label_.c_str());
    std::fflush(stderr);
  }
}

ProgressStage::~ProgressStage() {
  if (drawer_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
    }
    done_.notify_all();
    drawer_.join();
    if (drawn_) std::fprintf(stderr, "\r\033[K");
  }
  if (lines_) std::fprintf(stderr, "inscribe: %s: done in %.1f s\n", label_.c_str(), Since(start_));
}

void ProgressStage::Draw() {
  std::unique_lock<std::mutex> lock(mutex_);
  if (done_.wait_for(lock, std::chrono::seconds(1), [this] { return finished_; })) return;
  do {
    drawn_ = true;
    std::fprintf(stderr, "\r\033[K%s ... %.1fs", label_.c_str(), Since(start_));
    std::fflush(stderr);
  } while (!done_.wait_for(lock, std::chrono::milliseconds(200), [this] { return finished_; }));
}

}  // namespace inscribe::cli
