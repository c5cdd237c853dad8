// The shared Redis tier when Redis fails: unreachable at Open, killed while lookups run (and
// back after a restart on the same port), frozen with SIGSTOP. Lookups must keep succeeding
// from the local tiers or by computing, within a few timeouts, with the failures counted and
// reported.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "redis_tier_test_support.h"
#include "result_cache_test_support.h"
#include "support/inscribed_process.h"
#include "support/redis_process.h"

namespace inscribe::server {
namespace {

using cache_test::EventLog;
using cache_test::KeepBytes;
using cache_test::Lookups;
using cache_test::MustNotCompute;
using cache_test::MustNotDecode;
using cache_test::OpenShared;
using cache_test::Returning;
using cache_test::Value;
using ::testing::HasSubstr;
using testing::RedisProcess;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

TEST(RedisTierFailure, UnreachableAtOpenIsNotAnError) {
  const int port = testing::UnusedLoopbackPort();
  EventLog events;
  const auto start = Clock::now();
  auto cache = OpenShared("redis://127.0.0.1:" + std::to_string(port), &events);
  EXPECT_LT(SecondsSince(start), 5.0);
  ASSERT_EQ(events.downs(), 1);
  EXPECT_THAT(std::string(events.events()[0].error.message()),
              HasSubstr(absl::StrCat("redis 127.0.0.1:", port)));
  EXPECT_EQ(cache->stats().shared_available, 0);
  int calls = 0;
  auto got = cache->GetOrCompute("k", Returning("v", &calls), MustNotDecode());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->source, CacheSource::kComputed);
  // Within the first second's backoff: the read and the write were skipped, not tried.
  EXPECT_EQ(cache->stats().shared_skipped, 2);

  // Redis appears later: after the backoff a lookup probes it and the tier comes up.
  RedisProcess redis(port);
  ASSERT_TRUE(redis.ready());
  const auto give_up = Clock::now() + 20s;
  int i = 0;
  while (cache->stats().shared_available == 0 && Clock::now() < give_up) {
    ASSERT_TRUE(
        cache->GetOrCompute(absl::StrCat("probe/", i++), Returning("v", &calls), MustNotDecode())
            .ok());
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(cache->stats().shared_available, 1);
  EXPECT_EQ(events.ups(), 1);
}

TEST(RedisTierFailure, KilledMidRunLookupsSucceedAndTheTierComesBackAfterARestart) {
  auto redis = std::make_unique<RedisProcess>();
  ASSERT_TRUE(redis->ready());
  const int port = redis->port();
  EventLog events;
  auto a = OpenShared(redis->url(), &events, "", 200);
  auto b = OpenShared(redis->url(), nullptr, "", 200);
  int calls = 0;
  ASSERT_TRUE(a->GetOrCompute("before", Returning("v0", &calls), MustNotDecode()).ok());

  redis->Kill();
  // Lookups keep succeeding: old keys from memory, new ones computed; B, which never saw
  // "before", computes it.
  std::atomic<int> failed{0};
  std::vector<std::thread> threads;
  const auto start = Clock::now();
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      ResultCache& cache = t % 2 == 0 ? *a : *b;
      for (int i = 0; i < 20; ++i) {
        const std::string key = i == 0 ? "before" : absl::StrCat("down/", t, "/", i);
        int n = 0;
        auto got = cache.GetOrCompute(key, Returning("v", &n), KeepBytes());
        if (!got.ok()) ++failed;
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_LT(SecondsSince(start), 20.0);  // no hang: a refused connect is immediate
  const ResultCacheStats down = a->stats();
  EXPECT_GE(down.shared_errors + down.shared_write_errors, 1);
  EXPECT_GE(down.shared_skipped, 1);
  EXPECT_EQ(down.shared_available, 0);
  EXPECT_EQ(down.shared_hits, 0);
  EXPECT_EQ(Lookups(down), 1 + 40);
  EXPECT_EQ(events.downs(), 1);
  ASSERT_FALSE(events.events().back().available);
  EXPECT_THAT(std::string(events.events().back().error.message()),
              HasSubstr(absl::StrCat("127.0.0.1:", port)));

  // Restarted (empty: no persistence) on the same port: after the backoff, a lookup probes it
  // and values flow through it again.
  redis = std::make_unique<RedisProcess>(port);
  ASSERT_TRUE(redis->ready());
  const auto give_up = Clock::now() + 40s;  // the backoff may have grown to 2-4 s meanwhile
  int i = 0;
  while (a->stats().shared_available == 0 && Clock::now() < give_up) {
    ASSERT_TRUE(
        a->GetOrCompute(absl::StrCat("probe/", i++), Returning("v", &calls), MustNotDecode()).ok());
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_EQ(a->stats().shared_available, 1);
  EXPECT_EQ(events.ups(), 2);  // at Open, and now
  ASSERT_TRUE(a->GetOrCompute("after", Returning("v1", &calls), MustNotDecode()).ok());
  EXPECT_TRUE(redis->Get("inscribe:after").has_value());
  // B's tier comes back too (its own probe), then reads what A wrote.
  const auto b_give_up = Clock::now() + 40s;
  while (b->stats().shared_available == 0 && Clock::now() < b_give_up) {
    ASSERT_TRUE(
        b->GetOrCompute(absl::StrCat("b-probe/", i++), Returning("v", &calls), MustNotDecode())
            .ok());
    std::this_thread::sleep_for(100ms);
  }
  auto after = b->GetOrCompute("after", MustNotCompute(), KeepBytes());
  ASSERT_TRUE(after.ok()) << after.status();
  EXPECT_EQ(after->source, CacheSource::kShared);
}

// hiredis writes with write(2): a write to a connection Redis has closed raises SIGPIPE, which
// would end the process. An 8 MB SET on the pooled connection of a killed Redis must not.
TEST(RedisTierFailure, WritingToAKilledRedisDoesNotRaiseSigpipe) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto cache = OpenShared(redis.url());  // keeps the connection it checked Redis with
  redis.Kill();
  ASSERT_TRUE(cache->Put("k/big", Value(std::string(8 << 20, 'x'))).ok());
  EXPECT_EQ(cache->stats().shared_write_errors, 1);
  EXPECT_EQ(cache->stats().shared_writes, 0);
  EXPECT_EQ(cache->stats().shared_available, 0);
}

TEST(RedisTierFailure, FrozenRedisCostsAFewTimeoutsNotAHang) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  constexpr int kTimeoutMs = 200;
  EventLog events;
  auto cache = OpenShared(redis.url(), &events, "", kTimeoutMs);
  int calls = 0;
  ASSERT_TRUE(cache->GetOrCompute("warm", Returning("v", &calls), MustNotDecode()).ok());

  redis.Freeze();
  // The pooled connection's GET times out (the kernel still accepts, nobody answers); the
  // tier is then skipped until its backoff ends.
  double slowest = 0.0;
  const auto start = Clock::now();
  for (int i = 0; i < 20; ++i) {
    const auto lookup = Clock::now();
    auto got =
        cache->GetOrCompute(absl::StrCat("frozen/", i), Returning("v", &calls), MustNotDecode());
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_EQ(got->source, CacheSource::kComputed);
    slowest = std::max(slowest, SecondsSince(lookup));
  }
  // Generous bounds for a loaded machine: at most ~4 timeouts (0.8 s) per lookup are expected.
  EXPECT_LT(slowest, 5.0);
  EXPECT_LT(SecondsSince(start), 20.0);
  // A cache opened while Redis is frozen does not hang either.
  const auto open = Clock::now();
  auto late = OpenShared(redis.url(), nullptr, "", kTimeoutMs);
  ASSERT_TRUE(late->GetOrCompute("late", Returning("v", &calls), MustNotDecode()).ok());
  EXPECT_LT(SecondsSince(open), 5.0);
  redis.Thaw();

  const ResultCacheStats s = cache->stats();
  EXPECT_GE(s.shared_errors, 1);
  EXPECT_GE(s.shared_skipped, 1);
  EXPECT_EQ(s.computations, 21);
  EXPECT_GE(events.downs(), 1);
  EXPECT_GE(late->stats().shared_errors, 1);
}

}  // namespace
}  // namespace inscribe::server
