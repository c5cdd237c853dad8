// The result cache's memory tier (LRU by bytes), its keys and its single flight. The disk
// tier is tested in result_cache_disk_test.cpp.
#include "inscribe/server/result_cache.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <random>
#include <thread>
#include <vector>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "result_cache_test_support.h"

namespace inscribe::server {
namespace {

using cache_test::MustNotCompute;
using cache_test::MustNotDecode;
using cache_test::OpenCache;
using cache_test::Returning;
using cache_test::TempDir;
using cache_test::Value;
using ::testing::HasSubstr;
using namespace std::chrono_literals;

void RunThreads(int count, const std::function<void(int)>& body) {
  std::vector<std::thread> threads;
  for (int i = 0; i < count; ++i) threads.emplace_back(body, i);
  for (std::thread& thread : threads) thread.join();
}

// Polls until `counter` reaches `target` (or 10 s pass, so a bug fails instead of hanging).
void WaitForCount(const std::atomic<int>& counter, int target) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (counter.load() < target && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(1ms);
  }
}

constexpr int kCallers = 8;

// Calls GetOrCompute(key) from kCallers threads at once. The computation returns `outcome`
// after waiting until every thread has called, and 100 ms more so that the others are waiting
// on it; `*computations` counts its runs.
std::vector<absl::StatusOr<CacheLookup>> CallConcurrently(
    ResultCache& cache, const std::string& key, const absl::StatusOr<CachedValue>& outcome,
    std::atomic<int>* computations) {
  std::atomic<int> calling{0};
  const ResultCache::Compute compute = [&]() -> absl::StatusOr<CachedValue> {
    ++*computations;
    WaitForCount(calling, kCallers);
    std::this_thread::sleep_for(100ms);
    return outcome;
  };
  std::vector<absl::StatusOr<CacheLookup>> results(kCallers);
  RunThreads(kCallers, [&](int i) {
    ++calling;
    results[i] = cache.GetOrCompute(key, compute, MustNotDecode());
  });
  return results;
}

TEST(ResultCache, ComputesOnceThenHitsMemory) {
  auto cache = OpenCache(1 << 20);
  int calls = 0;
  auto first = cache->GetOrCompute("spheres/v1/abc", Returning("payload", &calls), MustNotDecode());
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(first->source, CacheSource::kComputed);
  EXPECT_EQ(first->value->bytes, "payload");
  auto second = cache->GetOrCompute("spheres/v1/abc", MustNotCompute(), MustNotDecode());
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_EQ(second->source, CacheSource::kMemory);
  EXPECT_EQ(second->value, first->value);  // the same shared value, not a copy
  EXPECT_EQ(calls, 1);

  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.entries, 1);
  EXPECT_EQ(stats.bytes, 14 + 7);  // key + bytes
  EXPECT_EQ(stats.misses, 1);
  EXPECT_EQ(stats.computations, 1);
  EXPECT_EQ(stats.memory_hits, 1);
  EXPECT_EQ(stats.disk_hits + stats.joined + stats.evictions, 0);
  EXPECT_EQ(stats.disk_entries + stats.disk_bytes + stats.disk_errors, 0);
}

TEST(ResultCache, EvictsLeastRecentlyUsedByBytes) {
  // Keys of 3 characters with 100 bytes cost 103: three fit in 320, four do not.
  auto cache = OpenCache(320);
  int calls = 0;
  const std::string hundred(100, 'x');
  for (const char* key : {"k/a", "k/b", "k/c"}) {
    ASSERT_TRUE(cache->GetOrCompute(key, Returning(hundred, &calls), MustNotDecode()).ok());
  }
  EXPECT_EQ(cache->stats().bytes, 309);
  auto held_b = cache->Get("k/b", MustNotDecode());
  ASSERT_TRUE(held_b.ok());
  ASSERT_TRUE(cache->Get("k/a", MustNotDecode()).ok());  // recency now a, b, c (most first)
  ASSERT_TRUE(cache->Get("k/c", MustNotDecode()).ok());  // c, a, b
  ASSERT_TRUE(cache->GetOrCompute("k/d", Returning(hundred, &calls), MustNotDecode()).ok());

  // d pushed the total to 412: b, the least recently used, went.
  ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.entries, 3);
  EXPECT_EQ(stats.bytes, 309);
  EXPECT_EQ(stats.evictions, 1);
  EXPECT_EQ(cache->Get("k/b", MustNotDecode()).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(held_b->value->bytes, hundred);        // a caller's value outlives its eviction
  for (const char* key : {"k/c", "k/a", "k/d"}) {  // recency d, a, c
    auto hit = cache->Get(key, MustNotDecode());
    ASSERT_TRUE(hit.ok()) << key;
    EXPECT_EQ(hit->source, CacheSource::kMemory);
  }

  // object_bytes count too: 3 + 10 + 200 = 213 more needs 202 freed, so c then a go.
  ASSERT_TRUE(
      cache->GetOrCompute("k/e", Returning(std::string(10, 'y'), &calls, 200), MustNotDecode())
          .ok());
  stats = cache->stats();
  EXPECT_EQ(stats.entries, 2);
  EXPECT_EQ(stats.bytes, 103 + 213);
  EXPECT_EQ(stats.evictions, 3);
  EXPECT_FALSE(cache->Get("k/c", MustNotDecode()).ok());
  EXPECT_FALSE(cache->Get("k/a", MustNotDecode()).ok());
  EXPECT_TRUE(cache->Get("k/d", MustNotDecode()).ok());
  EXPECT_TRUE(cache->Get("k/e", MustNotDecode()).ok());
  EXPECT_EQ(calls, 5);
}

TEST(ResultCache, EntryLargerThanBudgetIsReturnedButNotKept) {
  auto cache = OpenCache(100);
  int calls = 0;
  // Exactly the budget (3 + 97) is kept.
  ASSERT_TRUE(
      cache->GetOrCompute("k/a", Returning(std::string(97, 'a'), &calls), MustNotDecode()).ok());
  EXPECT_EQ(cache->stats().bytes, 100);
  for (int round = 0; round < 2; ++round) {
    auto big =
        cache->GetOrCompute("k/big", Returning(std::string(200, 'b'), &calls), MustNotDecode());
    ASSERT_TRUE(big.ok()) << big.status();
    EXPECT_EQ(big->source, CacheSource::kComputed);
    EXPECT_EQ(big->value->bytes, std::string(200, 'b'));
  }
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(stats.entries, 1);  // the oversized entry evicted nothing
  EXPECT_EQ(stats.bytes, 100);
  EXPECT_EQ(stats.evictions, 0);
  EXPECT_EQ(stats.misses, 3);
}

TEST(ResultCacheSingleFlight, ConcurrentCallersComputeOnce) {
  TempDir dir;
  auto cache = OpenCache(1 << 20, dir.cache());
  std::atomic<int> computations{0};
  const std::vector<absl::StatusOr<CacheLookup>> results =
      CallConcurrently(*cache, "spheres/v1/one", Value("shared result"), &computations);

  int computed = 0;
  int joined = 0;
  for (const absl::StatusOr<CacheLookup>& result : results) {
    ASSERT_TRUE(result.ok()) << result.status();
    EXPECT_EQ(result->value, results[0]->value);
    computed += result->source == CacheSource::kComputed;
    joined += result->source == CacheSource::kJoined;
  }
  EXPECT_EQ(computations.load(), 1);
  EXPECT_EQ(computed, 1);
  EXPECT_EQ(joined, kCallers - 1);
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.computations, 1);
  EXPECT_EQ(stats.misses, 1);
  EXPECT_EQ(stats.joined, kCallers - 1);
  EXPECT_EQ(stats.memory_hits, 0);
  EXPECT_EQ(stats.disk_entries, 1);
}

TEST(ResultCacheSingleFlight, FailureIsSharedWithWaitersAndNotCached) {
  TempDir dir;
  auto cache = OpenCache(1 << 20, dir.cache());
  std::atomic<int> computations{0};
  const std::vector<absl::StatusOr<CacheLookup>> results =
      CallConcurrently(*cache, "k/flaky", absl::UnavailableError("backend down"), &computations);
  for (const absl::StatusOr<CacheLookup>& result : results) {
    EXPECT_EQ(result.status().code(), absl::StatusCode::kUnavailable);
    EXPECT_EQ(result.status().message(), "backend down");
  }
  EXPECT_EQ(computations.load(), 1);
  ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.computations, 1);
  EXPECT_EQ(stats.joined, kCallers - 1);
  EXPECT_EQ(stats.entries + stats.disk_entries, 0);

  int calls = 0;
  auto retry = cache->GetOrCompute("k/flaky", Returning("fine now", &calls), MustNotDecode());
  ASSERT_TRUE(retry.ok()) << retry.status();
  EXPECT_EQ(retry->source, CacheSource::kComputed);
  EXPECT_EQ(calls, 1);
  stats = cache->stats();
  EXPECT_EQ(stats.computations, 2);
  EXPECT_EQ(stats.entries, 1);
  EXPECT_EQ(stats.disk_entries, 1);
}

// A leader whose caller gave up (CANCELLED, DEADLINE_EXCEEDED) does not fail the waiters: the
// first of them computes the key itself and the rest join that computation.
TEST(ResultCacheSingleFlight, WaitersTakeOverFromCancelledLeader) {
  for (const absl::StatusCode code :
       {absl::StatusCode::kCancelled, absl::StatusCode::kDeadlineExceeded}) {
    SCOPED_TRACE(absl::StatusCodeToString(code));
    auto cache = OpenCache(1 << 20);
    std::atomic<int> started{0};
    std::atomic<int> release{0};
    std::atomic<int> taken_over{0};
    const ResultCache::Compute cancelled = [&]() -> absl::StatusOr<CachedValue> {
      ++started;
      WaitForCount(release, 1);
      return absl::Status(code, "caller gave up");
    };
    const ResultCache::Compute completes = [&]() -> absl::StatusOr<CachedValue> {
      ++taken_over;
      return Value("computed by a waiter");
    };
    absl::StatusOr<CacheLookup> led;
    std::vector<absl::StatusOr<CacheLookup>> waited(3);
    std::thread leader([&] { led = cache->GetOrCompute("k/taken", cancelled, MustNotDecode()); });
    WaitForCount(started, 1);
    std::vector<std::thread> waiters;
    for (auto& result : waited) {
      waiters.emplace_back(
          [&] { result = cache->GetOrCompute("k/taken", completes, MustNotDecode()); });
    }
    std::this_thread::sleep_for(200ms);  // lets the waiters reach their wait
    ++release;
    leader.join();
    for (std::thread& waiter : waiters) waiter.join();

    EXPECT_EQ(led.status().code(), code);
    EXPECT_EQ(taken_over.load(), 1);
    int computed = 0;
    for (const auto& result : waited) {
      ASSERT_TRUE(result.ok()) << result.status();
      EXPECT_EQ(result->value->bytes, "computed by a waiter");
      computed += result->source == CacheSource::kComputed;
    }
    EXPECT_EQ(computed, 1);
    EXPECT_EQ(cache->stats().computations, 2);
  }
}

// persist = false keeps a value in memory only.
TEST(ResultCache, ValuesNotPersistedStayOffDisk) {
  TempDir dir;
  auto cache = OpenCache(1 << 20, dir.cache());
  const ResultCache::Compute compute = []() -> absl::StatusOr<CachedValue> {
    CachedValue value = Value("process-local");
    value.persist = false;
    return value;
  };
  ASSERT_TRUE(cache->GetOrCompute("k/local", compute, MustNotDecode()).ok());
  CachedValue put = Value("also local");
  put.persist = false;
  ASSERT_TRUE(cache->Put("k/local2", std::move(put)).ok());
  int calls = 0;
  ASSERT_TRUE(cache->GetOrCompute("k/kept", Returning("on disk", &calls), MustNotDecode()).ok());
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.entries, 3);
  EXPECT_EQ(stats.disk_entries, 1);
}

// Get waits for a computation in progress and shares its value, or reports its failure.

TEST(ResultCacheSingleFlight, GetWaitsForComputationInProgress) {
  for (const bool succeeds : {true, false}) {
    SCOPED_TRACE(succeeds ? "succeeds" : "fails");
    auto cache = OpenCache(1 << 20);
    std::atomic<int> started{0};
    std::atomic<int> release{0};
    const ResultCache::Compute compute = [&]() -> absl::StatusOr<CachedValue> {
      ++started;
      WaitForCount(release, 1);
      if (!succeeds) return absl::ResourceExhaustedError("too many spheres");
      return Value("late");
    };
    absl::StatusOr<CacheLookup> led;
    absl::StatusOr<CacheLookup> got;
    std::thread leader([&] { led = cache->GetOrCompute("k/slow", compute, MustNotDecode()); });
    WaitForCount(started, 1);
    std::thread waiter([&] { got = cache->Get("k/slow", MustNotDecode()); });
    std::this_thread::sleep_for(200ms);  // lets the Get reach its wait
    ++release;
    leader.join();
    waiter.join();
    if (succeeds) {
      ASSERT_TRUE(got.ok()) << got.status();
      EXPECT_EQ(got->source, CacheSource::kJoined);
      EXPECT_EQ(got->value, led->value);
    } else {
      EXPECT_EQ(got.status().code(), absl::StatusCode::kNotFound);
      EXPECT_THAT(got.status().message(), HasSubstr("k/slow"));
      EXPECT_THAT(got.status().message(), HasSubstr("too many spheres"));
    }
    EXPECT_EQ(cache->stats().joined, 1);
  }
}

// Many threads over a few keys with a memory tier too small for them: each key is computed

// exactly once (the disk tier keeps every result), and every lookup is counted once.

TEST(ResultCacheSingleFlight, ManyThreadsManyKeysComputeEachKeyOnce) {
  TempDir dir;
  constexpr int kKeys = 20;
  constexpr int kThreads = 4;
  constexpr int kLookups = 300;
  auto cache = OpenCache(5 * 104, dir.cache());  // five entries of 4 + 100 bytes
  const auto key_of = [](int k) { return absl::StrCat("k/", k / 10, k % 10); };
  const auto payload_of = [&](int k) {
    std::string payload;
    while (payload.size() < 100) payload += key_of(k);
    payload.resize(100);
    return payload;
  };
  std::array<std::atomic<int>, kKeys> computations{};
  std::array<std::atomic<int>, 4> by_source{};
  std::atomic<int> wrong{0};
  RunThreads(kThreads, [&](int t) {
    std::mt19937 random(t);
    for (int i = 0; i < kLookups; ++i) {
      const int k = static_cast<int>(random() % kKeys);
      const ResultCache::Compute compute = [&, k]() -> absl::StatusOr<CachedValue> {
        ++computations[k];
        return Value(payload_of(k));
      };
      const ResultCache::Decode decode = [](std::string bytes) -> absl::StatusOr<CachedValue> {
        return Value(std::move(bytes));  // no object: every entry costs 104
      };
      auto lookup = cache->GetOrCompute(key_of(k), compute, decode);
      if (!lookup.ok() || lookup->value->bytes != payload_of(k)) ++wrong;
      if (lookup.ok()) ++by_source[static_cast<int>(lookup->source)];
    }
  });
  EXPECT_EQ(wrong.load(), 0);
  for (int k = 0; k < kKeys; ++k) EXPECT_EQ(computations[k].load(), 1) << key_of(k);
  const ResultCacheStats stats = cache->stats();
  EXPECT_EQ(stats.computations, kKeys);
  EXPECT_EQ(stats.misses, kKeys);
  EXPECT_EQ(stats.memory_hits, by_source[static_cast<int>(CacheSource::kMemory)].load());
  EXPECT_EQ(stats.disk_hits, by_source[static_cast<int>(CacheSource::kDisk)].load());
  EXPECT_EQ(stats.joined, by_source[static_cast<int>(CacheSource::kJoined)].load());
  EXPECT_EQ(stats.memory_hits + stats.disk_hits + stats.misses + stats.joined, kThreads * kLookups);
  EXPECT_LE(stats.entries, 5);
  EXPECT_EQ(stats.bytes, stats.entries * 104);
  EXPECT_EQ(stats.disk_entries, kKeys);
  EXPECT_EQ(stats.disk_errors + stats.disk_write_errors, 0);
}

TEST(ResultCache, GetOfUnknownKeyIsNotFoundNamingTheKey) {
  TempDir dir;
  for (const std::string& disk_dir : {std::string(), dir.cache()}) {
    SCOPED_TRACE(disk_dir);
    auto cache = OpenCache(1 << 20, disk_dir);
    auto got = cache->Get("spheres/v1/unknown", MustNotDecode());
    EXPECT_EQ(got.status().code(), absl::StatusCode::kNotFound);
    EXPECT_THAT(got.status().message(), HasSubstr("spheres/v1/unknown"));
    EXPECT_EQ(cache->stats().misses, 1);
    EXPECT_EQ(cache->stats().computations, 0);
  }
}

TEST(ResultCache, MalformedKeysAreInvalidArgument) {
  auto cache = OpenCache(1 << 20);
  int calls = 0;
  const std::string bad_keys[] = {"",          std::string(201, 'a'),  "a b", "a\nb",
                                  "k\xc3\xa4", std::string("a\0b", 3), "k*",  "k\\x"};
  for (const std::string& key : bad_keys) {
    SCOPED_TRACE(absl::CHexEscape(key));
    EXPECT_EQ(CheckCacheKey(key).code(), absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(cache->GetOrCompute(key, Returning("x", &calls), MustNotDecode()).status().code(),
              absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(cache->Get(key, MustNotDecode()).status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(cache->Put(key, Value("x")).status().code(), absl::StatusCode::kInvalidArgument);
  }
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(cache->stats().misses + cache->stats().entries, 0);
  EXPECT_THAT(CheckCacheKey(std::string(201, 'a')).message(), HasSubstr("201"));
  EXPECT_THAT(CheckCacheKey("a b").message(), HasSubstr("offset 1"));
  EXPECT_TRUE(CheckCacheKey(std::string(200, 'a')).ok());
  EXPECT_TRUE(CheckCacheKey("spheres/v1:abc.DEF_0-9").ok());
}

TEST(ResultCache, SourceNames) {
  EXPECT_STREQ(CacheSourceName(CacheSource::kMemory), "memory");
  EXPECT_STREQ(CacheSourceName(CacheSource::kDisk), "disk");
  EXPECT_STREQ(CacheSourceName(CacheSource::kComputed), "computed");
  EXPECT_STREQ(CacheSourceName(CacheSource::kJoined), "joined");
}

}  // namespace
}  // namespace inscribe::server
