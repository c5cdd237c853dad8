// core's parallel loops (core/src/base/parallel.h): every index once, folds in index order whatever
// the schedule, exceptions reach the caller; and, in ThreadSanitizer builds, that a loop is
// ordered with the code around it while its bodies stay unordered with one another.
#include "base/parallel.h"

#include <gtest/gtest.h>
#include <tbb/combinable.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace inscribe::internal {
namespace {

const std::vector<std::int64_t> kSizes = {0, 1, 2, 7, 64, 65, 1000, 100003};
const std::vector<std::size_t> kGrains = {0, 1, 3, 64, std::size_t{1} << 20};

// Makes two threads meet in a loop: the first thread to arrive waits (up to 2 s, for a machine
// with one thread) until a body on another thread arrives; then every arrival passes. So the
// loop's bodies run on at least two threads. Relaxed atomics: the meeting orders nothing in
// ThreadSanitizer's eyes.
class Meeting {
 public:
  void Arrive() {
    if (met_.load(std::memory_order_relaxed)) return;
    const std::thread::id me = std::this_thread::get_id();
    std::thread::id nobody;
    if (!first_.compare_exchange_strong(nobody, me, std::memory_order_relaxed)) {
      if (nobody != me) met_.store(true, std::memory_order_relaxed);
      return;
    }
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
    while (!met_.load(std::memory_order_relaxed) && std::chrono::steady_clock::now() < until) {
      std::this_thread::yield();
    }
  }

 private:
  std::atomic<std::thread::id> first_{};
  std::atomic<bool> met_{false};
};

TEST(ParallelLoops, EveryIndexOfARangeIsVisitedOnce) {
  for (const std::int64_t n : kSizes) {
    for (const std::size_t grain : kGrains) {
      std::vector<int> visits(static_cast<std::size_t>(n), 0);
      ParallelForRange(std::int64_t{0}, n, grain, [&](std::int64_t begin, std::int64_t end) {
        ASSERT_LE(begin, end);
        for (std::int64_t i = begin; i < end; ++i) ++visits[static_cast<std::size_t>(i)];
      });
      for (std::int64_t i = 0; i < n; ++i) {
        ASSERT_EQ(visits[static_cast<std::size_t>(i)], 1) << "n " << n << " grain " << grain;
      }
      std::vector<int> each(static_cast<std::size_t>(n), 0);
      ParallelFor(std::int64_t{0}, n, [&](std::int64_t i) { ++each[static_cast<std::size_t>(i)]; });
      EXPECT_EQ(std::count(each.begin(), each.end(), 1), n);
    }
  }
  // A range that does not start at zero.
  std::vector<int> visits(50, 0);
  ParallelForRange(std::size_t{20}, std::size_t{45}, 4, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) ++visits[i];
  });
  for (std::size_t i = 0; i < visits.size(); ++i) EXPECT_EQ(visits[i], i >= 20 && i < 45) << i;
}

// The chunks and the joins are fixed, so a join that is neither commutative nor associative in
// floating point still gives the serial fold's chunked result, bit for bit, on any number of
// threads.
TEST(ParallelLoops, ReduceJoinsChunksInIndexOrderOnAnyNumberOfThreads) {
  for (const std::int64_t n : kSizes) {
    for (const std::size_t grain : kGrains) {
      const auto concatenate = [&] {
        return ParallelReduce(
            std::int64_t{0}, n, grain, std::string(),
            [](std::int64_t begin, std::int64_t end, std::string s) {
              for (std::int64_t i = begin; i < end; ++i) s += static_cast<char>('a' + i % 26);
              return s + "|";
            },
            [](std::string a, const std::string& b) {
              a += b;
              return a;
            });
      };
      std::string expected;
      const std::int64_t step = static_cast<std::int64_t>(grain > 0 ? grain : 1);
      for (std::int64_t i = 0; i < n; ++i) {
        expected += static_cast<char>('a' + i % 26);
        if ((i + 1) % step == 0 || i + 1 == n) expected += "|";
      }
      EXPECT_EQ(concatenate(), expected) << "n " << n << " grain " << grain;
    }
  }
  std::mt19937_64 random(7);
  std::vector<double> values(200000);
  for (double& v : values) v = std::ldexp(static_cast<double>(random() >> 11), -40) - 4096.0;
  const auto sum = [&] {
    return ParallelReduce(
        std::size_t{0}, values.size(), 97, 0.0,
        [&](std::size_t begin, std::size_t end, double s) {
          for (std::size_t i = begin; i < end; ++i) s += values[i];
          return s;
        },
        [](double a, double b) { return a + b; });
  };
  const double on_all = sum();
  double on_one = 0.0;
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    on_one = sum();
  }
  EXPECT_EQ(on_all, on_one);
  for (int k = 0; k < 20; ++k) ASSERT_EQ(sum(), on_all);
}

TEST(ParallelLoops, ABodysExceptionReachesTheCaller) {
  const auto throws_at = [](std::int64_t bad) {
    ParallelForRange(std::int64_t{0}, std::int64_t{10000}, 16,
                     [&](std::int64_t begin, std::int64_t end) {
                       if (begin <= bad && bad < end) throw std::runtime_error("body failed");
                     });
  };
  EXPECT_THROW(throws_at(0), std::runtime_error);
  EXPECT_THROW(throws_at(9999), std::runtime_error);
  EXPECT_THROW(ParallelFor(0, 100,
                           [](int i) {
                             if (i == 50) throw std::invalid_argument("index 50");
                           }),
               std::invalid_argument);
  // The loops work as before afterwards.
  std::vector<int> visits(1000, 0);
  ParallelFor(0, 1000, [&](int i) { ++visits[static_cast<std::size_t>(i)]; });
  EXPECT_EQ(std::accumulate(visits.begin(), visits.end(), 0), 1000);
}

// Plain writes before a loop, read in its bodies; plain writes in the bodies, read after it;
// with the bodies made to run on at least two threads. Under ThreadSanitizer (halt_on_error,
// as scripts/sanitize runs it) a loop that did not order these would end the test with a race
// report; elsewhere it checks the values.
TEST(ParallelLoops, WritesAroundALoopAreOrderedWithItsBodies) {
  for (int round = 0; round < 20; ++round) {
    std::vector<std::int64_t> input(4096);
    std::iota(input.begin(), input.end(), round);
    std::vector<std::int64_t> output(input.size(), -1);
    Meeting meeting;
    ParallelForRange(std::size_t{0}, input.size(), 64, [&](std::size_t begin, std::size_t end) {
      meeting.Arrive();
      for (std::size_t i = begin; i < end; ++i) output[i] = 2 * input[i];
    });
    for (std::size_t i = 0; i < input.size(); ++i) ASSERT_EQ(output[i], 2 * input[i]);
    Meeting reduce_meeting;
    const std::int64_t total = ParallelReduce(
        std::size_t{0}, input.size(), 64, std::int64_t{0},
        [&](std::size_t begin, std::size_t end, std::int64_t s) {
          reduce_meeting.Arrive();
          for (std::size_t i = begin; i < end; ++i) s += output[i];
          return s;
        },
        [](std::int64_t a, std::int64_t b) { return a + b; });
    EXPECT_EQ(total, 2 * std::accumulate(input.begin(), input.end(), std::int64_t{0}));
  }
}

// TBB's thread-local containers in nested loops, as the cover certificate uses them: under TSan
// a helper thread can take over the slot of one that has ended (its id reused; ThreadIdKey in
// parallel.h). The counts add up either way, and TSan reports no race.
TEST(ParallelLoops, ThreadLocalSlotsInNestedLoopsAddUp) {
  for (int round = 0; round < 10; ++round) {
    tbb::combinable<std::int64_t> counts;
    ParallelFor(0, 8, [&](int) {
      ParallelFor(0, 8, [&](int) { ParallelFor(1, 5, [&](int j) { counts.local() += j; }); });
    });
    EXPECT_EQ(counts.combine(std::plus<>{}), 64 * (1 + 2 + 3 + 4));
  }
}

#if INSCRIBE_TSAN_LOOPS
// The loop adds no ordering between its bodies: two bodies writing one plain variable are
// still a race that ThreadSanitizer reports.
TEST(ParallelLoopsDeathTest, ARaceBetweenTwoBodiesIsStillReported) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        std::int64_t shared = 0;
        Meeting meeting;
        ParallelFor(0, 2, [&](int i) {
          meeting.Arrive();
          shared += i + 1;
        });
        std::printf("%lld\n", static_cast<long long>(shared));
        std::exit(0);
      },
      "ThreadSanitizer: data race");
}
#endif

}  // namespace
}  // namespace inscribe::internal
