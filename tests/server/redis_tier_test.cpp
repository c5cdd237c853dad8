// The result cache's shared Redis tier against a real redis-server: values written through by
// one cache and read by another without computing, the integrity framing, what never reaches
// Redis, passwords, URLs, concurrency and large values. Failures (Redis killed, frozen,
// unreachable) are in redis_tier_failure_test.cpp.
#include "redis_tier.h"  // private: ParseRedisUrl

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "redis_tier_test_support.h"
#include "result_cache_test_support.h"
#include "support/redis_process.h"

namespace inscribe::server {
namespace {

using cache_test::BinaryPayload;
using cache_test::EventLog;
using cache_test::KeepBytes;
using cache_test::Lookups;
using cache_test::MustNotCompute;
using cache_test::MustNotDecode;
using cache_test::OpenShared;
using cache_test::Returning;
using cache_test::TempDir;
using cache_test::Value;
using ::testing::HasSubstr;
using ::testing::Not;
using testing::RedisProcess;
using ::testing::StartsWith;

constexpr absl::string_view kMagic = "inscribe-cache 1\n";

TEST(RedisTier, ValueComputedByOneCacheIsReadByAnotherWithoutComputing) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  EventLog events_a;
  auto a = OpenShared(redis.url(), &events_a);
  auto b = OpenShared(redis.url());
  EXPECT_EQ(events_a.ups(), 1);  // the state at Open
  EXPECT_EQ(events_a.downs(), 0);

  const std::string payload = BinaryPayload(1000);
  int calls = 0;
  auto computed = a->GetOrCompute("spheres/v1/abc", Returning(payload, &calls), MustNotDecode());
  ASSERT_TRUE(computed.ok()) << computed.status();
  EXPECT_EQ(computed->source, CacheSource::kComputed);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(a->stats().shared_writes, 1);
  EXPECT_EQ(a->stats().shared_misses, 1);  // looked before computing

  // Stored framed, under the prefixed key.
  const std::optional<std::string> stored = redis.Get("inscribe:spheres/v1/abc");
  ASSERT_TRUE(stored.has_value());
  EXPECT_THAT(*stored, StartsWith(std::string(kMagic)));
  EXPECT_EQ(stored->substr(stored->size() - payload.size()), payload);

  int decodes = 0;
  auto shared = b->GetOrCompute("spheres/v1/abc", MustNotCompute(), KeepBytes(&decodes));
  ASSERT_TRUE(shared.ok()) << shared.status();
  EXPECT_EQ(shared->source, CacheSource::kShared);
  EXPECT_STREQ(CacheSourceName(shared->source), "redis");
  EXPECT_EQ(shared->value->bytes, payload);
  EXPECT_EQ(decodes, 1);
  auto again = b->GetOrCompute("spheres/v1/abc", MustNotCompute(), MustNotDecode());
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->source, CacheSource::kMemory);

  const ResultCacheStats s = b->stats();
  EXPECT_EQ(s.shared_hits, 1);
  EXPECT_EQ(s.memory_hits, 1);
  EXPECT_EQ(s.misses, 0);
  EXPECT_EQ(s.computations, 0);
  EXPECT_EQ(s.shared_writes, 0);  // a hit is not written back
  EXPECT_EQ(s.shared_available, 1);
  EXPECT_EQ(Lookups(s), 2);
}

TEST(RedisTier, GetReadsRedisAndReportsAbsenceAsNotFound) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  auto b = OpenShared(redis.url());
  int calls = 0;
  ASSERT_TRUE(a->GetOrCompute("mesh:1", Returning("mesh bytes", &calls), MustNotDecode()).ok());
  auto got = b->Get("mesh:1", KeepBytes());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->source, CacheSource::kShared);
  EXPECT_EQ(got->value->bytes, "mesh bytes");

  auto missing = b->Get("mesh:2", KeepBytes());
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  const ResultCacheStats s = b->stats();
  EXPECT_EQ(s.shared_hits, 1);
  EXPECT_EQ(s.shared_misses, 1);
  EXPECT_EQ(s.misses, 1);
  EXPECT_EQ(s.shared_errors, 0);
}

TEST(RedisTier, PutWritesThroughAndRedisHitsReachTheDisk) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  TempDir dir;
  auto a = OpenShared(redis.url());
  ASSERT_TRUE(a->Put("sha256:aa", Value("uploaded")).ok());
  EXPECT_EQ(a->stats().shared_writes, 1);
  {
    auto b = OpenShared(redis.url(), nullptr, dir.cache());
    auto got = b->Get("sha256:aa", KeepBytes());
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_EQ(got->source, CacheSource::kShared);
    EXPECT_EQ(b->stats().disk_entries, 1);  // written to B's disk
  }
  redis.Kill();
  // B restarted without Redis: its disk tier has it.
  auto b = OpenShared("", nullptr, dir.cache());
  auto got = b->Get("sha256:aa", KeepBytes());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->source, CacheSource::kDisk);
  EXPECT_EQ(got->value->bytes, "uploaded");
}

TEST(RedisTier, CorruptValuesAreCountedDeletedAndRecomputed) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  // Entries framed for their own keys, then damaged in Redis.
  for (const char* key : {"k/good", "k/flipped", "k/truncated"}) {
    int calls = 0;
    ASSERT_TRUE(a->GetOrCompute(key, Returning(BinaryPayload(500), &calls), MustNotDecode()).ok());
  }
  const std::string good = *redis.Get("inscribe:k/good");
  std::string flipped = *redis.Get("inscribe:k/flipped");
  flipped.back() ^= 1;  // a payload byte: only the SHA-256 can tell
  std::string truncated = *redis.Get("inscribe:k/truncated");
  truncated.pop_back();  // the length no longer matches
  const std::vector<std::pair<std::string, std::string>> planted = {
      {"k/garbage", "not an entry at all"},
      {"k/flipped", flipped},
      {"k/truncated", truncated},
      {"k/moved", good},  // a valid entry, but for another key
  };
  for (const auto& [key, value] : planted) ASSERT_TRUE(redis.Set("inscribe:" + key, value));

  auto b = OpenShared(redis.url());
  for (const auto& [key, value] : planted) {
    SCOPED_TRACE(key);
    int b_calls = 0;
    auto got = b->GetOrCompute(key, Returning("fresh " + key, &b_calls), MustNotDecode());
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_EQ(got->source, CacheSource::kComputed);
    EXPECT_EQ(b_calls, 1);
    // Replaced by the recomputed value, properly framed.
    const std::optional<std::string> now = redis.Get("inscribe:" + key);
    ASSERT_TRUE(now.has_value());
    EXPECT_THAT(*now, StartsWith(std::string(kMagic)));
    EXPECT_THAT(*now, HasSubstr("fresh " + key));
  }
  const ResultCacheStats s = b->stats();
  EXPECT_EQ(s.shared_corrupt, 4);
  EXPECT_EQ(s.shared_hits, 0);
  EXPECT_EQ(s.misses, 4);
  EXPECT_EQ(s.computations, 4);
  EXPECT_EQ(s.shared_errors, 0);  // corrupt is not unavailable
  EXPECT_EQ(s.shared_available, 1);
}

TEST(RedisTier, ValueThatFailsToDecodeIsCorruptAndDeleted) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  auto b = OpenShared(redis.url());
  ASSERT_TRUE(a->Put("k/undecodable", Value("bytes")).ok());
  const ResultCache::Decode refuse = [](std::string) -> absl::StatusOr<CachedValue> {
    return absl::DataLossError("bad proto");
  };
  auto got = b->Get("k/undecodable", refuse);
  EXPECT_EQ(got.status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(b->stats().shared_corrupt, 1);
  EXPECT_EQ(b->stats().misses, 1);
  EXPECT_FALSE(redis.Get("inscribe:k/undecodable").has_value());
}

TEST(RedisTier, ValuesThatDoNotPersistNeverReachRedis) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  const ResultCache::Compute local = []() -> absl::StatusOr<CachedValue> {
    CachedValue value = Value("refit oracle");
    value.persist = false;
    return value;
  };
  ASSERT_TRUE(a->GetOrCompute("deformer/v1/x", local, MustNotDecode()).ok());
  CachedValue put = Value("also local");
  put.persist = false;
  ASSERT_TRUE(a->Put("deformer/v1/y", put).ok());
  ASSERT_TRUE(
      a->GetOrCompute(
           "spheres/v1/z", [] { return absl::StatusOr<CachedValue>(Value("z")); }, MustNotDecode())
          .ok());
  const auto keys = redis.Keys("*");
  ASSERT_TRUE(keys.has_value());
  EXPECT_THAT(*keys, ::testing::ElementsAre("inscribe:spheres/v1/z"));
  EXPECT_EQ(a->stats().shared_writes, 1);
}

TEST(RedisTier, FailedComputationsAreNotWritten) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  auto failed = a->GetOrCompute(
      "k/fails", [] { return absl::StatusOr<CachedValue>(absl::InternalError("no")); },
      MustNotDecode());
  EXPECT_FALSE(failed.ok());
  EXPECT_FALSE(redis.Get("inscribe:k/fails").has_value());
  EXPECT_EQ(a->stats().shared_writes, 0);
}

TEST(RedisTier, RightPasswordWorks) {
  RedisProcess redis(0, {"--requirepass", "s3cret@/x"}, "s3cret@/x");
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  auto b = OpenShared(redis.url());
  int calls = 0;
  ASSERT_TRUE(a->GetOrCompute("k", Returning("v", &calls), MustNotDecode()).ok());
  auto got = b->GetOrCompute("k", MustNotCompute(), KeepBytes());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->source, CacheSource::kShared);
  EXPECT_EQ(b->stats().shared_errors, 0);
}

TEST(RedisTier, WrongOrMissingPasswordCountsErrorsButLookupsSucceed) {
  RedisProcess redis(0, {"--requirepass", "right-password"}, "right-password");
  ASSERT_TRUE(redis.ready());
  const std::string wrong = "redis://:wrong-password@127.0.0.1:" + std::to_string(redis.port());
  const std::string none = "redis://127.0.0.1:" + std::to_string(redis.port());
  for (const std::string& url : {wrong, none}) {
    SCOPED_TRACE(RedactRedisUrl(url));
    EventLog events;
    auto cache = OpenShared(url, &events);
    ASSERT_EQ(events.downs(), 1);
    EXPECT_THAT(std::string(events.events().back().error.message()),
                Not(HasSubstr("wrong-password")));
    EXPECT_EQ(events.events().back().retry_after, std::chrono::milliseconds(1000));
    for (int i = 0; i < 5; ++i) {
      int calls = 0;
      auto got = cache->GetOrCompute(absl::StrCat("k", i), Returning("v", &calls), MustNotDecode());
      ASSERT_TRUE(got.ok()) << got.status();
      EXPECT_EQ(got->source, CacheSource::kComputed);
    }
    const ResultCacheStats s = cache->stats();
    EXPECT_GE(s.shared_errors, 1);
    EXPECT_GE(s.shared_skipped, 1);
    EXPECT_EQ(s.shared_available, 0);
    EXPECT_EQ(s.computations, 5);
  }
  const auto keys = redis.Keys("*");
  ASSERT_TRUE(keys.has_value());
  EXPECT_TRUE(keys->empty());
}

TEST(RedisTier, ParsesUrls) {
  auto plain = ParseRedisUrl("redis://cache.internal");
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_EQ(plain->host, "cache.internal");
  EXPECT_EQ(plain->port, 6379);
  EXPECT_EQ(plain->db, 0);
  EXPECT_EQ(plain->password, "");

  auto full = ParseRedisUrl("redis://:p@ss:w/rd@10.0.0.7:6380/3");
  ASSERT_TRUE(full.ok()) << full.status();
  EXPECT_EQ(full->host, "10.0.0.7");
  EXPECT_EQ(full->port, 6380);
  EXPECT_EQ(full->db, 3);
  EXPECT_EQ(full->user, "");
  EXPECT_EQ(full->password, "p@ss:w/rd");

  auto user = ParseRedisUrl("redis://inscribe:pw@[::1]:7000/");
  ASSERT_TRUE(user.ok()) << user.status();
  EXPECT_EQ(user->host, "::1");
  EXPECT_EQ(user->port, 7000);
  EXPECT_EQ(user->user, "inscribe");
  EXPECT_EQ(user->password, "pw");
}

TEST(RedisTier, MalformedUrlsNameTheWrongPartAndHideThePassword) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"http://:hunter2@host", "scheme"},
      {"rediss://host", "scheme"},
      {"redis://", "host is empty"},
      {"redis://:hunter2@:6379", "host is empty"},
      {"redis://:hunter2@host:port", "port 'port'"},
      {"redis://host:70000", "port '70000'"},
      {"redis://host:0", "port '0'"},
      {"redis://host:", "port after ':' is empty"},
      {"redis://:hunter2@host/db1", "database 'db1'"},
      {"redis://host/-1", "database '-1'"},
      {"redis://:@host", "password after ':' is empty"},
      {"redis://hunter2@host", "user information"},
      {"redis://[::1:6379", "'[' without ']'"},
  };
  for (const auto& [url, part] : cases) {
    SCOPED_TRACE(url);
    ResultCacheOptions options;
    options.redis_url = url;
    auto cache = ResultCache::Open(options);
    ASSERT_EQ(cache.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(std::string(cache.status().message()), HasSubstr(part));
    EXPECT_THAT(std::string(cache.status().message()), HasSubstr("--redis"));
    EXPECT_THAT(std::string(cache.status().message()), Not(HasSubstr("hunter2")));
  }
  ResultCacheOptions options;
  options.redis_url = "redis://127.0.0.1";
  options.redis_timeout_ms = 0;
  EXPECT_EQ(ResultCache::Open(options).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(RedisTier, RedactsPasswords) {
  EXPECT_EQ(RedactRedisUrl("redis://:hunter2@h:1/2"), "redis://:***@h:1/2");
  EXPECT_EQ(RedactRedisUrl("redis://user:hunter2@h"), "redis://user:***@h");
  EXPECT_EQ(RedactRedisUrl("redis://hunter2@h"), "redis://:***@h");
  EXPECT_EQ(RedactRedisUrl("redis://:a@b@h"), "redis://:***@h");
  EXPECT_EQ(RedactRedisUrl("redis://h:6379"), "redis://h:6379");
  EXPECT_EQ(RedactRedisUrl(""), "");
}

// Eight threads over two caches and twelve keys: every value arrives intact, each cache computes
// each key at most once, and every lookup is counted once.
TEST(RedisTier, ConcurrentLookupsFromTwoCaches) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  auto a = OpenShared(redis.url());
  auto b = OpenShared(redis.url());
  constexpr int kThreads = 8;
  constexpr int kKeys = 12;
  constexpr int kRounds = 60;
  std::atomic<int> computations{0};
  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      ResultCache& cache = t % 2 == 0 ? *a : *b;
      for (int r = 0; r < kRounds; ++r) {
        const int k = (r * 5 + t) % kKeys;
        const std::string expected = BinaryPayload(20'000 + k, k);
        auto got = cache.GetOrCompute(
            absl::StrCat("k/", k),
            [&]() -> absl::StatusOr<CachedValue> {
              ++computations;
              std::this_thread::sleep_for(std::chrono::milliseconds(5));
              return Value(expected);
            },
            KeepBytes());
        if (!got.ok() || got->value->bytes != expected) ++wrong;
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(wrong.load(), 0);
  const ResultCacheStats sa = a->stats();
  const ResultCacheStats sb = b->stats();
  EXPECT_LE(sa.computations, kKeys);
  EXPECT_LE(sb.computations, kKeys);
  EXPECT_EQ(sa.computations + sb.computations, computations.load());
  EXPECT_EQ(Lookups(sa) + Lookups(sb), kThreads * kRounds);
  EXPECT_EQ(sa.shared_errors + sb.shared_errors + sa.shared_write_errors + sb.shared_write_errors,
            0);

  // A third cache finds all of them in Redis, and eight concurrent misses of one key cost one
  // Redis read.
  auto c = OpenShared(redis.url());
  std::vector<std::thread> readers;
  std::atomic<int> failed{0};
  for (int t = 0; t < kThreads; ++t) {
    readers.emplace_back([&] {
      if (!c->GetOrCompute("k/3", MustNotCompute(), KeepBytes()).ok()) ++failed;
    });
  }
  for (std::thread& thread : readers) thread.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_EQ(c->stats().shared_hits, 1);
  EXPECT_EQ(c->stats().shared_misses, 0);
  for (int k = 0; k < kKeys; ++k) {
    auto got = c->Get(absl::StrCat("k/", k), KeepBytes());
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_EQ(got->value->bytes, BinaryPayload(20'000 + k, k));
  }
  EXPECT_EQ(c->stats().computations, 0);
}

TEST(RedisTier, LargeValueRoundTrips) {
  RedisProcess redis;
  ASSERT_TRUE(redis.ready());
  // A generous timeout: each socket read or write gets it, not the whole transfer.
  auto a = OpenShared(redis.url(), nullptr, "", 2000);
  auto b = OpenShared(redis.url(), nullptr, "", 2000);
  const std::string payload = BinaryPayload(20 << 20);
  int calls = 0;
  ASSERT_TRUE(a->GetOrCompute("k/large", Returning(payload, &calls), MustNotDecode()).ok());
  EXPECT_EQ(a->stats().shared_writes, 1);
  auto got = b->GetOrCompute("k/large", MustNotCompute(), KeepBytes());
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->source, CacheSource::kShared);
  EXPECT_TRUE(got->value->bytes == payload);  // no 20 MB diff on failure
}

}  // namespace
}  // namespace inscribe::server
