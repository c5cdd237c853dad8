#include "frame_dispatch.h"

#include <algorithm>
#include <cassert>
#include <limits>
#include <thread>
#include <utility>

#include "memory_budget.h"

namespace inscribe::server {

double FrameCostModel::Estimate(std::int64_t items) const {
  if (items <= 0) return 0.0;
  if (seconds_per_item_ < 0.0) return std::numeric_limits<double>::infinity();
  return seconds_per_item_ * static_cast<double>(items);
}

void FrameCostModel::Record(std::int64_t items, double seconds) {
  if (items <= 0) return;
  const double per_item = std::max(seconds, 0.0) / static_cast<double>(items);
  seconds_per_item_ =
      seconds_per_item_ < 0.0 ? per_item : 0.75 * seconds_per_item_ + 0.25 * per_item;
}

int DefaultMaxInlineFrames() {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int grpc_threads = std::clamp(cores / 2, 2, 16);
  return std::max(1, grpc_threads - 1);
}

FrameDispatcher::FrameDispatcher(JobPool* pool, int max_inline, double inline_seconds)
    : pool_(pool), max_inline_(max_inline), inline_seconds_(inline_seconds) {
  assert(pool != nullptr && max_inline >= 0);
}

bool FrameDispatcher::Small(const FrameWork& frame, double estimated_seconds) const {
  return frame.resolved && frame.serial && estimated_seconds <= inline_seconds_;
}

bool FrameDispatcher::Run(const FrameWork& frame, double estimated_seconds,
                          std::function<void(FramePlace)> work) {
  if (Small(frame, estimated_seconds)) {
    // Take a slot only while fewer than max_inline_ are taken; never waits.
    int running = running_inline_.load(std::memory_order_relaxed);
    while (running < max_inline_) {
      if (running_inline_.compare_exchange_weak(running, running + 1, std::memory_order_acquire)) {
        inline_frames_.fetch_add(1, std::memory_order_relaxed);
        work(FramePlace::kInline);
        running_inline_.fetch_sub(1, std::memory_order_release);
        return true;
      }
    }
  }
  if (!pool_->TrySubmit([work = std::move(work)] { work(FramePlace::kPool); },
                        LaneFor(frame.memory_bytes))) {
    return false;
  }
  pooled_frames_.fetch_add(1, std::memory_order_relaxed);
  return true;
}

}  // namespace inscribe::server
