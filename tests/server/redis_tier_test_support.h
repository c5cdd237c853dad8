// What the Redis tier tests share: caches opened on a test's redis-server, a thread-safe
// record of the tier's events, and payloads that must survive Redis byte for byte.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "inscribe/server/result_cache.h"

namespace inscribe::server::cache_test {

// Every SharedTierEvent a cache reported, in order; safe to read while lookups run.
class EventLog {
 public:
  void Record(const SharedTierEvent& event) {
    std::lock_guard<std::mutex> lock(mutex_);
    events_.push_back(event);
  }
  std::vector<SharedTierEvent> events() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return events_;
  }
  int downs() const { return Count(false); }
  int ups() const { return Count(true); }

 private:
  int Count(bool available) const {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const SharedTierEvent& event : events_) n += event.available == available ? 1 : 0;
    return n;
  }
  mutable std::mutex mutex_;
  std::vector<SharedTierEvent> events_;
};

// A cache with a 64 MB memory tier on `redis_url`, optionally with a disk tier; throws (failing
// the test) when Open fails. `events` (may be null) must outlive the cache.
inline std::unique_ptr<ResultCache> OpenShared(const std::string& redis_url,
                                               EventLog* events = nullptr,
                                               std::string disk_dir = "", int timeout_ms = 250) {
  ResultCacheOptions options;
  options.memory_bytes = std::int64_t{64} << 20;
  options.disk_dir = std::move(disk_dir);
  options.redis_url = redis_url;
  options.redis_timeout_ms = timeout_ms;
  if (events != nullptr) {
    options.on_shared_tier_event = [events](const SharedTierEvent& e) { events->Record(e); };
  }
  absl::StatusOr<std::unique_ptr<ResultCache>> cache = ResultCache::Open(options);
  if (!cache.ok()) throw std::runtime_error(cache.status().ToString());
  return *std::move(cache);
}

// Every byte value, NULs included, so the tier must be binary-safe.
inline std::string BinaryPayload(std::size_t size, int seed = 0) {
  std::string payload(size, '\0');
  for (std::size_t i = 0; i < size; ++i) {
    payload[i] = static_cast<char>((i * 7 + i / 256 + static_cast<std::size_t>(seed)) % 256);
  }
  return payload;
}

// Keeps the bytes; counts its calls.
inline ResultCache::Decode KeepBytes(int* calls = nullptr) {
  return [calls](std::string bytes) -> absl::StatusOr<CachedValue> {
    if (calls != nullptr) ++*calls;
    CachedValue value;
    value.bytes = std::move(bytes);
    return value;
  };
}

// Counters every lookup lands in exactly one of.
inline std::int64_t Lookups(const ResultCacheStats& s) {
  return s.memory_hits + s.disk_hits + s.shared_hits + s.misses + s.joined;
}

}  // namespace inscribe::server::cache_test
