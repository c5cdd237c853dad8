// Where a stream frame's work runs: at once on the gRPC thread that read the frame, or on the
// job pool. One rule for every streaming RPC that answers frames (DistanceStream, SceneStream).
// Private to the server.
//
// A frame of a few distance queries costs tens of microseconds, the same order as handing it to
// a pool thread and back (two wake-ups, and on a busy machine two waits for a core), so such
// frames are answered on the gRPC thread that read them. Everything else goes to the
// pool as any call's work does: frames whose cost is not known yet (a stream's first frame,
// which also looks up and may build hierarchies), frames over the time budget, frames that
// would run parallel loops, and frames arriving while other gRPC threads are already
// computing inline frames, so that one gRPC thread always stays free to read, write and
// accept calls even when an estimate was wrong.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>

#include "inscribe/server/job_pool.h"

namespace inscribe::server {

// What a stream knows of a frame before running it. O(1) to fill once its objects are found.
struct FrameWork {
  // The frame's work in the stream's own unit (DistanceStream: distance queries, two per
  // certified pair), the unit its FrameCostModel was fed in.
  std::int64_t items = 0;
  // Every object the frame names is already held by the stream: running it looks nothing up
  // in the cache (which may read disk or Redis, or build a hierarchy).
  bool resolved = false;
  // The work runs on the calling thread alone, never a TBB parallel loop (which belongs in the
  // pool's arena): DistanceStream frames of at most kSerialFramePairs pairs.
  bool serial = false;
  // The frame's memory reservation (--memory-budget); picks the pool's lane when the frame
  // goes there (LaneFor in memory_budget.h, as for every call).
  std::int64_t memory_bytes = 0;
};

// PairSeparationDistances answers up to 64 pairs on the calling thread (its header), so a
// DistanceStream frame of at most this many pairs is FrameWork::serial (a certified frame makes
// two such batches, internal sets and covers).
inline constexpr std::int64_t kSerialFramePairs = 64;

// Frames estimated at most this long run inline: a few times the two thread hops a pool frame
// pays (tens of microseconds), and well under the stream's 1 ms round-trip target. A frame of
// 10 pairs of 1,000-sphere sets takes 50-150 us.
inline constexpr double kInlineFrameSeconds = 200e-6;

// One stream's cost per item, learnt from its own frames: an exponential average (weight 1/4
// for the newest frame) of run seconds per item. Not thread-safe; a stream's frames run one at
// a time. O(1).
class FrameCostModel {
 public:
  // Seconds `items` items are expected to take: 0 for none, +infinity before any frame with
  // items was recorded.
  double Estimate(std::int64_t items) const;
  // A frame of `items` items ran `seconds` (its compute, not its queueing).
  void Record(std::int64_t items, double seconds);

 private:
  double seconds_per_item_ = -1.0;  // < 0: nothing recorded yet
};

// Where Run ran a frame; passed to the frame's work.
enum class FramePlace { kInline, kPool };

// The default number of frames computed inline at once: one fewer than gRPC's callback
// threads, which for gRPC 1.51's callback API are clamp(cores / 2, 2, 16) threads polling one
// process-wide completion queue (two on 2 cores, hence one inline frame at a time), and at
// least one.
int DefaultMaxInlineFrames();

// The rule itself, shared by the service's streams. Thread-safe.
class FrameDispatcher {
 public:
  // `pool` runs the frames that do not run inline; it must outlive the dispatcher.
  // `max_inline`: frames computed inline at the same time, at most; >= 0 (0: never inline).
  explicit FrameDispatcher(JobPool* pool, int max_inline = DefaultMaxInlineFrames(),
                           double inline_seconds = kInlineFrameSeconds);
  FrameDispatcher(const FrameDispatcher&) = delete;
  FrameDispatcher& operator=(const FrameDispatcher&) = delete;

  // Whether `frame`, estimated at `estimated_seconds` (its stream's FrameCostModel), may run
  // inline: resolved, serial and within the time budget. Inline slots are not looked at.
  bool Small(const FrameWork& frame, double estimated_seconds) const;

  // Runs `work` (the frame's whole answer, ending in the stream's StartWrite or Finish; it
  // must not throw) and tells it where: inline, returning after it, when the frame is Small
  // and an inline slot is free; else queued on the pool's lane for frame.memory_bytes.
  // Returns false, without running `work`, when the pool refused it (--max-queue full): the
  // stream answers the service's QueueFullError. The caller must hold no lock that `work`
  // takes, and must not touch the stream after a true return: once the reply is written the
  // stream's next frame may already be running on another thread.
  bool Run(const FrameWork& frame, double estimated_seconds, std::function<void(FramePlace)> work);

  // Frames Run has run inline and handed to the pool since the dispatcher was made: for tests.
  std::int64_t inline_frames() const { return inline_frames_.load(std::memory_order_relaxed); }
  std::int64_t pooled_frames() const { return pooled_frames_.load(std::memory_order_relaxed); }

 private:
  JobPool* const pool_;
  const int max_inline_;
  const double inline_seconds_;
  std::atomic<int> running_inline_{0};
  std::atomic<std::int64_t> inline_frames_{0};
  std::atomic<std::int64_t> pooled_frames_{0};
};

}  // namespace inscribe::server
