// The rule that puts a stream frame inline on the gRPC thread or on the pool
// (server/src/frame_dispatch.h), on its own, with a real JobPool.
#include "frame_dispatch.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>

#include "inscribe/server/job_pool.h"
#include "memory_budget.h"

namespace inscribe::server {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

FrameWork SmallFrame() {
  FrameWork frame;
  frame.items = 10;
  frame.resolved = true;
  frame.serial = true;
  frame.memory_bytes = 10 * MemoryCosts::kPerFramePair;
  return frame;
}

TEST(FrameCostModel, UnknownUntilAFrameWithItemsIsRecordedThenAveraged) {
  FrameCostModel model;
  EXPECT_EQ(model.Estimate(10), kInfinity);
  EXPECT_EQ(model.Estimate(0), 0.0);
  model.Record(0, 1.0);  // an empty frame teaches nothing
  EXPECT_EQ(model.Estimate(10), kInfinity);
  model.Record(10, 50e-6);
  EXPECT_DOUBLE_EQ(model.Estimate(10), 50e-6);
  EXPECT_DOUBLE_EQ(model.Estimate(20), 100e-6);
  // One slow frame moves the estimate a quarter of the way; cheap frames bring it back.
  model.Record(10, 450e-6);
  EXPECT_DOUBLE_EQ(model.Estimate(10), 150e-6);
  for (int i = 0; i < 60; ++i) model.Record(10, 50e-6);
  EXPECT_NEAR(model.Estimate(10), 50e-6, 1e-9);
}

TEST(FrameDispatcher, SmallMeansResolvedSerialAndWithinTheBudget) {
  JobPool pool(JobPoolOptions{1, 8});
  const FrameDispatcher dispatcher(&pool, 1, 200e-6);
  EXPECT_TRUE(dispatcher.Small(SmallFrame(), 50e-6));
  EXPECT_TRUE(dispatcher.Small(SmallFrame(), 200e-6));
  EXPECT_FALSE(dispatcher.Small(SmallFrame(), 201e-6));
  EXPECT_FALSE(dispatcher.Small(SmallFrame(), kInfinity));  // cost not known yet
  FrameWork unresolved = SmallFrame();
  unresolved.resolved = false;
  EXPECT_FALSE(dispatcher.Small(unresolved, 1e-6));
  FrameWork parallel = SmallFrame();
  parallel.serial = false;
  EXPECT_FALSE(dispatcher.Small(parallel, 1e-6));
  EXPECT_GE(DefaultMaxInlineFrames(), 1);
}

TEST(FrameDispatcher, SmallFramesRunOnTheCallingThreadBeforeRunReturns) {
  JobPool pool(JobPoolOptions{1, 8});
  FrameDispatcher dispatcher(&pool, 1);
  const std::thread::id caller = std::this_thread::get_id();
  for (int i = 0; i < 3; ++i) {
    bool ran = false;
    ASSERT_TRUE(dispatcher.Run(SmallFrame(), 10e-6, [&](FramePlace place) {
      EXPECT_EQ(place, FramePlace::kInline);
      EXPECT_EQ(std::this_thread::get_id(), caller);
      ran = true;
    }));
    EXPECT_TRUE(ran);
  }
  EXPECT_EQ(dispatcher.inline_frames(), 3);
  EXPECT_EQ(dispatcher.pooled_frames(), 0);
  EXPECT_EQ(pool.jobs_in_flight(), 0);
}

// Runs `frame` through the dispatcher and returns where it ran and whether on another thread.
std::pair<FramePlace, bool> Place(FrameDispatcher& dispatcher, JobPool& pool,
                                  const FrameWork& frame, double estimate) {
  std::atomic<FramePlace> where{FramePlace::kInline};
  std::atomic<bool> elsewhere{false};
  const std::thread::id caller = std::this_thread::get_id();
  EXPECT_TRUE(dispatcher.Run(frame, estimate, [&](FramePlace place) {
    where = place;
    elsewhere = std::this_thread::get_id() != caller;
  }));
  pool.WaitIdle();
  return {where.load(), elsewhere.load()};
}

TEST(FrameDispatcher, UnknownBigParallelAndUnresolvedFramesGoToThePool) {
  JobPool pool(JobPoolOptions{1, 8});
  FrameDispatcher dispatcher(&pool, 1);
  FrameWork unresolved = SmallFrame(), parallel = SmallFrame(), huge = SmallFrame();
  unresolved.resolved = false;
  parallel.serial = false;
  huge.memory_bytes = 2 * MemoryCosts::kSmallJob;  // the pool's large lane
  const std::pair<FramePlace, bool> pooled{FramePlace::kPool, true};
  EXPECT_EQ(Place(dispatcher, pool, SmallFrame(), kInfinity), pooled);
  EXPECT_EQ(Place(dispatcher, pool, SmallFrame(), 1e-3), pooled);
  EXPECT_EQ(Place(dispatcher, pool, unresolved, 1e-6), pooled);
  EXPECT_EQ(Place(dispatcher, pool, parallel, 1e-6), pooled);
  EXPECT_EQ(Place(dispatcher, pool, huge, kInfinity), pooled);
  EXPECT_EQ(dispatcher.pooled_frames(), 5);
  EXPECT_EQ(dispatcher.inline_frames(), 0);
  FrameDispatcher never(&pool, 0);
  EXPECT_EQ(Place(never, pool, SmallFrame(), 1e-6), pooled);
}

// While max_inline frames are computing inline, the next small frame goes to the pool rather
// than taking another gRPC thread.
TEST(FrameDispatcher, BusyInlineSlotsSendSmallFramesToThePool) {
  JobPool pool(JobPoolOptions{1, 8});
  FrameDispatcher dispatcher(&pool, 1);
  std::atomic<bool> holding{false}, release{false};
  std::thread holder([&] {
    EXPECT_TRUE(dispatcher.Run(SmallFrame(), 1e-6, [&](FramePlace place) {
      EXPECT_EQ(place, FramePlace::kInline);
      holding = true;
      while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }));
  });
  while (!holding) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(Place(dispatcher, pool, SmallFrame(), 1e-6), std::make_pair(FramePlace::kPool, true));
  release = true;
  holder.join();
  // The slot is free again.
  EXPECT_EQ(Place(dispatcher, pool, SmallFrame(), 1e-6),
            std::make_pair(FramePlace::kInline, false));
  EXPECT_EQ(dispatcher.inline_frames(), 2);
  EXPECT_EQ(dispatcher.pooled_frames(), 1);
}

TEST(FrameDispatcher, AFullPoolRefusesWithoutRunning) {
  JobPool pool(JobPoolOptions{1, 1});
  FrameDispatcher dispatcher(&pool, 1);
  std::atomic<bool> release{false};
  ASSERT_TRUE(pool.TrySubmit([&] {
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }));
  bool ran = false;
  FrameWork unknown = SmallFrame();
  EXPECT_FALSE(dispatcher.Run(unknown, kInfinity, [&](FramePlace) { ran = true; }));
  EXPECT_FALSE(ran);
  // A small frame does not need the pool.
  EXPECT_TRUE(dispatcher.Run(SmallFrame(), 1e-6, [&](FramePlace) { ran = true; }));
  EXPECT_TRUE(ran);
  release = true;
  pool.WaitIdle();
}

}  // namespace
}  // namespace inscribe::server
