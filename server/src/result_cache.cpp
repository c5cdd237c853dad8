#include "inscribe/server/result_cache.h"

#include <cassert>
#include <condition_variable>
#include <list>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "disk_tier.h"
#include "redis_tier.h"

namespace inscribe::server {
namespace {

constexpr std::size_t kMaxKeyLength = 200;

std::int64_t Cost(absl::string_view key, const CachedValue& value) {
  return static_cast<std::int64_t>(key.size() + value.bytes.size()) + value.object_bytes;
}

absl::Status NotCached(absl::string_view key) {
  return absl::NotFoundError(absl::StrCat("no cached entry ", key));
}

// One computation (or disk or Redis lookup) of a key in progress, and its outcome once done.
struct Flight {
  std::mutex mutex;
  std::condition_variable finished;
  bool done = false;
  // A Get led the flight and found the key in no tier: waiting Gets report NOT_FOUND and
  // waiting GetOrComputes start over (one of them computes).
  bool absent = false;
  absl::Status status;  // the computation's error
  std::shared_ptr<const CachedValue> value;
};

void Publish(Flight& flight, bool absent, absl::Status status,
             std::shared_ptr<const CachedValue> value) {
  {
    std::lock_guard<std::mutex> lock(flight.mutex);
    if (flight.done) return;
    flight.done = true;
    flight.absent = absent;
    flight.status = std::move(status);
    flight.value = std::move(value);
  }
  flight.finished.notify_all();
}

}  // namespace

const char* CacheSourceName(CacheSource source) {
  switch (source) {
    case CacheSource::kMemory:
      return "memory";
    case CacheSource::kDisk:
      return "disk";
    case CacheSource::kComputed:
      return "computed";
    case CacheSource::kJoined:
      return "joined";
    case CacheSource::kShared:
      return "redis";
  }
  return "unknown";
}

absl::Status CheckCacheKey(absl::string_view key) {
  if (key.empty()) return absl::InvalidArgumentError("cache key is empty");
  if (key.size() > kMaxKeyLength) {
    return absl::InvalidArgumentError(
        absl::StrCat("cache key has ", key.size(), " characters; at most ", kMaxKeyLength));
  }
  for (std::size_t i = 0; i < key.size(); ++i) {
    const char c = key[i];
    if (absl::ascii_isalnum(c) || c == '.' || c == '_' || c == ':' || c == '/' || c == '-') {
      continue;
    }
    return absl::InvalidArgumentError(absl::StrCat(
        "cache key \"", absl::CHexEscape(key), "\" has '", absl::CHexEscape(key.substr(i, 1)),
        "' at offset ", i, "; allowed are A-Z a-z 0-9 . _ : / -"));
  }
  return absl::OkStatus();
}

struct ResultCache::Impl {
  struct Entry {
    std::string key;
    std::shared_ptr<const CachedValue> value;
    std::int64_t cost;
  };

  explicit Impl(std::int64_t memory_budget) : budget(memory_budget) {}

  ~Impl() { assert(flights.empty() && "ResultCache destroyed during a lookup"); }

  absl::StatusOr<CacheLookup> Lookup(absl::string_view key, const Compute* compute,
                                     const Decode& decode);
  absl::StatusOr<CacheLookup> Lead(absl::string_view key, const std::shared_ptr<Flight>& flight,
                                   const Compute* compute, const Decode& decode);
  // The value from disk, else from Redis (decoded; a value that fails to decode is dropped
  // from its tier), with the tier it came from; null when neither holds it.
  std::shared_ptr<const CachedValue> ReadStored(absl::string_view key, const Decode& decode,
                                                CacheSource* source);
  // Writes a persistent value through to disk and Redis (each skipped when absent).
  void WriteStored(absl::string_view key, const CachedValue& value, bool to_shared);
  std::shared_ptr<const CachedValue> FindLocked(absl::string_view key);
  std::shared_ptr<const CachedValue> InsertLocked(
      absl::string_view key, std::shared_ptr<const CachedValue> value,
      std::vector<std::shared_ptr<const CachedValue>>& evicted);
  void EraseFlightLocked(absl::string_view key, const std::shared_ptr<Flight>& flight);

  const std::int64_t budget;
  std::unique_ptr<DiskTier> disk;     // null: no disk tier
  std::unique_ptr<RedisTier> shared;  // null: no Redis tier

  // Guards the memory tier, the flights and the lookup counters. Held only for map and list
  // updates: never while computing, decoding, doing disk or network IO or freeing evicted
  // values.
  mutable std::mutex mutex;
  std::list<Entry> lru;  // most recently used first
  absl::flat_hash_map<absl::string_view, std::list<Entry>::iterator> index;  // views Entry::key
  absl::flat_hash_map<std::string, std::shared_ptr<Flight>> flights;
  ResultCacheStats counters;  // the memory tier's and the lookups'; the tiers count the rest
};

std::shared_ptr<const CachedValue> ResultCache::Impl::FindLocked(absl::string_view key) {
  const auto it = index.find(key);
  if (it == index.end()) return nullptr;
  lru.splice(lru.begin(), lru, it->second);
  return it->second->value;
}

std::shared_ptr<const CachedValue> ResultCache::Impl::InsertLocked(
    absl::string_view key, std::shared_ptr<const CachedValue> value,
    std::vector<std::shared_ptr<const CachedValue>>& evicted) {
  if (std::shared_ptr<const CachedValue> existing = FindLocked(key)) return existing;
  assert(value->object_bytes >= 0);
  const std::int64_t cost = Cost(key, *value);
  if (cost > budget) return value;  // larger than the whole tier: returned, not kept
  lru.push_front(Entry{std::string(key), value, cost});
  index.emplace(lru.front().key, lru.begin());
  ++counters.entries;
  counters.bytes += cost;
  // The new entry fits on its own, so it is never the one evicted.
  while (counters.bytes > budget) {
    Entry& oldest = lru.back();
    index.erase(oldest.key);
    counters.bytes -= oldest.cost;
    --counters.entries;
    ++counters.evictions;
    evicted.push_back(std::move(oldest.value));  // freed by the caller, after unlocking
    lru.pop_back();
  }
  return value;
}

void ResultCache::Impl::EraseFlightLocked(absl::string_view key,
                                          const std::shared_ptr<Flight>& flight) {
  const auto it = flights.find(key);
  if (it != flights.end() && it->second == flight) flights.erase(it);
}

std::shared_ptr<const CachedValue> ResultCache::Impl::ReadStored(absl::string_view key,
                                                                 const Decode& decode,
                                                                 CacheSource* source) {
  if (disk != nullptr) {
    if (std::optional<std::string> payload = disk->Read(key)) {
      absl::StatusOr<CachedValue> decoded = decode(*std::move(payload));
      if (decoded.ok()) {
        *source = CacheSource::kDisk;
        return std::make_shared<const CachedValue>(*std::move(decoded));
      }
      disk->DropCorrupt(key);
    }
  }
  if (shared != nullptr) {
    RedisTier::ReadResult read = shared->Get(key);
    if (read.outcome == RedisTier::Outcome::kHit) {
      absl::StatusOr<CachedValue> decoded = decode(std::move(read.payload));
      if (decoded.ok()) {
        *source = CacheSource::kShared;
        return std::make_shared<const CachedValue>(*std::move(decoded));
      }
      shared->DropCorrupt(key);
    }
  }
  return nullptr;
}

void ResultCache::Impl::WriteStored(absl::string_view key, const CachedValue& value,
                                    bool to_shared) {
  if (!value.persist) return;
  if (disk != nullptr) disk->Write(key, value.bytes);
  if (to_shared && shared != nullptr) shared->Put(key, value.bytes);
}

absl::StatusOr<CacheLookup> ResultCache::Impl::Lookup(absl::string_view key, const Compute* compute,
                                                      const Decode& decode) {
  if (absl::Status status = CheckCacheKey(key); !status.ok()) return status;
  for (;;) {
    std::shared_ptr<Flight> flight;
    bool leader = false;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (std::shared_ptr<const CachedValue> value = FindLocked(key)) {
        ++counters.memory_hits;
        return CacheLookup{std::move(value), CacheSource::kMemory};
      }
      auto [it, inserted] = flights.try_emplace(key);
      if (inserted) it->second = std::make_shared<Flight>();
      flight = it->second;
      leader = inserted;
    }
    if (leader) {
      try {
        return Lead(key, flight, compute, decode);
      } catch (...) {
        // A throwing compute or decode is the caller's bug; still release the waiters.
        {
          std::lock_guard<std::mutex> lock(mutex);
          EraseFlightLocked(key, flight);
        }
        Publish(*flight, /*absent=*/false,
                absl::InternalError(absl::StrCat("computing ", key, " threw an exception")),
                nullptr);
        throw;
      }
    }

    std::unique_lock<std::mutex> wait(flight->mutex);
    flight->finished.wait(wait, [&] { return flight->done; });
    const bool absent = flight->absent;
    const absl::Status status = flight->status;
    std::shared_ptr<const CachedValue> value = flight->value;
    wait.unlock();
    if (absent && compute != nullptr) continue;  // a Get found nothing: compute it ourselves
    // The leader's caller gave up; that says nothing about this caller, which takes over.
    if (compute != nullptr && (status.code() == absl::StatusCode::kCancelled ||
                               status.code() == absl::StatusCode::kDeadlineExceeded)) {
      continue;
    }

    std::lock_guard<std::mutex> lock(mutex);
    if (absent) {
      ++counters.misses;
      return NotCached(key);
    }
    ++counters.joined;
    if (!status.ok()) {
      if (compute != nullptr) return status;
      return absl::NotFoundError(absl::StrCat(
          "no cached entry ", key, " (its computation failed: ", status.ToString(), ")"));
    }
    return CacheLookup{std::move(value), CacheSource::kJoined};
  }
}

absl::StatusOr<CacheLookup> ResultCache::Impl::Lead(absl::string_view key,
                                                    const std::shared_ptr<Flight>& flight,
                                                    const Compute* compute, const Decode& decode) {
  CacheSource source = CacheSource::kDisk;
  std::shared_ptr<const CachedValue> value = ReadStored(key, decode, &source);
  std::vector<std::shared_ptr<const CachedValue>> evicted;
  if (value != nullptr) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++(source == CacheSource::kDisk ? counters.disk_hits : counters.shared_hits);
      value = InsertLocked(key, std::move(value), evicted);
      if (source == CacheSource::kDisk) EraseFlightLocked(key, flight);
    }
    Publish(*flight, /*absent=*/false, absl::OkStatus(), value);
    if (source == CacheSource::kShared) {
      // Kept on disk too, so a restart of this replica does not go back to Redis; the flight
      // stays registered until the file exists (see below).
      WriteStored(key, *value, /*to_shared=*/false);
      std::lock_guard<std::mutex> lock(mutex);
      EraseFlightLocked(key, flight);
    }
    return CacheLookup{std::move(value), source};
  }

  {
    std::lock_guard<std::mutex> lock(mutex);
    ++counters.misses;
    if (compute == nullptr) {
      EraseFlightLocked(key, flight);
    } else {
      ++counters.computations;
    }
  }
  if (compute == nullptr) {
    Publish(*flight, /*absent=*/true, absl::OkStatus(), nullptr);
    return NotCached(key);
  }

  absl::StatusOr<CachedValue> computed = (*compute)();
  if (!computed.ok()) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      EraseFlightLocked(key, flight);
    }
    Publish(*flight, /*absent=*/false, computed.status(), nullptr);
    return computed.status();
  }
  value = std::make_shared<const CachedValue>(*std::move(computed));
  {
    std::lock_guard<std::mutex> lock(mutex);
    value = InsertLocked(key, std::move(value), evicted);
  }
  // Waiters go on while the file and the Redis value are written. The flight stays registered
  // until both exist, so a value too large for memory is joined rather than computed again
  // meanwhile.
  Publish(*flight, /*absent=*/false, absl::OkStatus(), value);
  WriteStored(key, *value, /*to_shared=*/true);
  {
    std::lock_guard<std::mutex> lock(mutex);
    EraseFlightLocked(key, flight);
  }
  return CacheLookup{std::move(value), CacheSource::kComputed};
}

ResultCache::ResultCache(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

ResultCache::~ResultCache() = default;

absl::StatusOr<std::unique_ptr<ResultCache>> ResultCache::Open(const ResultCacheOptions& options) {
  if (options.memory_bytes < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--cache-memory-bytes must be >= 0, got ", options.memory_bytes));
  }
  if (options.disk_bytes < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--cache-disk-bytes must be >= 0 (0 = unbounded), got ", options.disk_bytes));
  }
  auto impl = std::make_unique<Impl>(options.memory_bytes);
  if (!options.disk_dir.empty()) {
    absl::StatusOr<std::unique_ptr<DiskTier>> disk =
        DiskTier::Open(options.disk_dir, options.disk_bytes, options.on_disk_tier_event);
    if (disk.ok()) {
      impl->disk = *std::move(disk);
    } else if (options.on_disk_tier_event) {
      // Memory (and Redis) only: a cache without its disk tier still answers every lookup.
      options.on_disk_tier_event(
          DiskTierEvent{DiskTierEvent::Kind::kOff, options.disk_dir, disk.status(), {}});
    }
  }
  if (!options.redis_url.empty()) {
    absl::StatusOr<std::unique_ptr<RedisTier>> shared = RedisTier::Create(
        options.redis_url, options.redis_timeout_ms, options.on_shared_tier_event);
    if (!shared.ok()) return shared.status();
    impl->shared = *std::move(shared);
  }
  return std::unique_ptr<ResultCache>(new ResultCache(std::move(impl)));
}

absl::StatusOr<CacheLookup> ResultCache::GetOrCompute(absl::string_view key, const Compute& compute,
                                                      const Decode& decode) {
  return impl_->Lookup(key, &compute, decode);
}

absl::StatusOr<CacheLookup> ResultCache::Get(absl::string_view key, const Decode& decode) {
  return impl_->Lookup(key, nullptr, decode);
}

absl::StatusOr<std::shared_ptr<const CachedValue>> ResultCache::Put(absl::string_view key,
                                                                    CachedValue value) {
  if (absl::Status status = CheckCacheKey(key); !status.ok()) return status;
  auto fresh = std::make_shared<const CachedValue>(std::move(value));
  std::shared_ptr<const CachedValue> kept;
  std::vector<std::shared_ptr<const CachedValue>> evicted;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    kept = impl_->FindLocked(key);
    if (kept != nullptr) return kept;
    kept = impl_->InsertLocked(key, std::move(fresh), evicted);
  }
  impl_->WriteStored(key, *kept, /*to_shared=*/true);
  return kept;
}

ResultCacheStats ResultCache::stats() const {
  ResultCacheStats stats;
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    stats = impl_->counters;
  }
  stats.hits = stats.memory_hits + stats.disk_hits;
  if (impl_->disk != nullptr) {
    const DiskTier::Counts disk = impl_->disk->counts();
    stats.disk_entries = disk.entries;
    stats.disk_bytes = disk.bytes;
    stats.disk_errors = disk.errors;
    stats.disk_write_errors = disk.write_errors;
    stats.disk_writes_skipped = disk.writes_skipped;
    stats.disk_available = disk.available ? 1 : 0;
    stats.disk_bytes_limit = disk.max_bytes;
    stats.disk_evictions = disk.evictions;
    stats.disk_evicted_bytes = disk.evicted_bytes;
    stats.disk_writes_too_large = disk.writes_too_large;
  }
  if (impl_->shared != nullptr) {
    const RedisTier::Counts shared = impl_->shared->counts();
    stats.shared_misses = shared.misses;
    stats.shared_errors = shared.errors;
    stats.shared_writes = shared.writes;
    stats.shared_write_errors = shared.write_errors;
    stats.shared_skipped = shared.skipped;
    stats.shared_corrupt = shared.corrupt;
    stats.shared_available = shared.available ? 1 : 0;
  }
  return stats;
}

}  // namespace inscribe::server
