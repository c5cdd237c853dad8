#include "inscribe/server/job_pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

namespace inscribe::server {
namespace {

// Runs `jobs` sleeping jobs and returns the most that ran at the same time.
int PeakConcurrency(JobPool& pool, int jobs) {
  std::atomic<int> running{0};
  std::atomic<int> peak{0};
  for (int i = 0; i < jobs; ++i) {
    EXPECT_TRUE(pool.TrySubmit([&] {
      const int now = ++running;
      int seen = peak.load();
      while (now > seen && !peak.compare_exchange_weak(seen, now)) {
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      --running;
    }));
  }
  pool.WaitIdle();
  return peak.load();
}

TEST(JobPool, RunsExactlyConcurrencyJobsAtOnceEvenOnFewCores) {
  // More threads than this machine may have cores: the pool must still provide them.
  JobPool pool(JobPoolOptions{/*concurrency=*/4, /*max_jobs=*/100});
  EXPECT_EQ(PeakConcurrency(pool, 12), 4);
  EXPECT_EQ(pool.jobs_in_flight(), 0);
}

TEST(JobPool, SingleThreadRunsOneAtATime) {
  JobPool pool(JobPoolOptions{/*concurrency=*/1, /*max_jobs=*/100});
  EXPECT_EQ(PeakConcurrency(pool, 4), 1);
}

TEST(JobPool, RefusesBeyondMaxJobsAndAcceptsAgainWhenDrained) {
  JobPool pool(JobPoolOptions{/*concurrency=*/1, /*max_jobs=*/3});
  std::atomic<bool> go{false};
  std::atomic<int> ran{0};
  auto job = [&] {
    while (!go.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ++ran;
  };
  EXPECT_TRUE(pool.TrySubmit(job));
  EXPECT_TRUE(pool.TrySubmit(job));
  EXPECT_TRUE(pool.TrySubmit(job));
  EXPECT_FALSE(pool.TrySubmit(job));  // 1 running + 2 queued = 3
  EXPECT_EQ(pool.jobs_in_flight(), 3);
  go = true;
  pool.WaitIdle();
  EXPECT_EQ(ran.load(), 3);
  EXPECT_TRUE(pool.TrySubmit(job));
  pool.WaitIdle();
  EXPECT_EQ(ran.load(), 4);
}

TEST(JobPool, DestructorWaitsForAcceptedJobs) {
  std::atomic<int> ran{0};
  {
    JobPool pool(JobPoolOptions{/*concurrency=*/2, /*max_jobs=*/10});
    for (int i = 0; i < 5; ++i) {
      ASSERT_TRUE(pool.TrySubmit([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        ++ran;
      }));
    }
  }
  EXPECT_EQ(ran.load(), 5);
}

// Large jobs holding every thread must not delay a small job (the small-job lane), and
// without the lane the small job waits for them: the same setup, both ways.
TEST(JobPool, SmallJobsRunWhileLargeJobsHoldEveryThread) {
  for (const int lane : {1, 0}) {
    SCOPED_TRACE(lane);
    JobPoolOptions options{/*concurrency=*/2, /*max_jobs=*/10};
    options.small_job_threads = lane;
    JobPool pool(options);
    std::atomic<bool> release{false};
    std::atomic<int> large_running{0};
    for (int i = 0; i < 2; ++i) {
      ASSERT_TRUE(pool.TrySubmit([&] {
        ++large_running;
        while (!release.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }));
    }
    while (large_running.load() < 2) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::atomic<bool> small_ran{false};
    ASSERT_TRUE(pool.TrySubmit([&] { small_ran = true; }, JobSize::kSmall));
    // Generous for a loaded machine: the lane starts the job in microseconds.
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!small_ran.load() && std::chrono::steady_clock::now() < until && lane == 1) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (lane == 0) std::this_thread::sleep_for(std::chrono::milliseconds(200));
    EXPECT_EQ(small_ran.load(), lane == 1);
    release = true;
    pool.WaitIdle();
    EXPECT_TRUE(small_ran.load());
  }
}

}  // namespace
}  // namespace inscribe::server
