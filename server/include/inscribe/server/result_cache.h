// The server's cache of computed results (validated meshes, sphere sets, hierarchies), keyed by
// content: an in-memory LRU bounded in bytes, an optional on-disk content-addressed directory
// and an optional Redis server shared by replicas, with single flight (concurrent requests for
// one key compute it, or read it from disk or Redis, once).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <variant>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/wire/cache_stats.h"

namespace inscribe {
class SphereHierarchy;
struct CoverCertificate;
}  // namespace inscribe

namespace inscribe::server {

// The kinds of decoded object a cache entry can hold (defined by the server's store).
struct StoredMeshEntry;
struct SphereSetEntry;
struct DeformerEntry;

// A cache entry's decoded object: none, or exactly one of a closed set of kinds. A value can
// only be read back as the kind it holds (CachedValue::Get), never cast to another.
using CachedObject =
    std::variant<std::monostate, std::shared_ptr<const StoredMeshEntry>,
                 std::shared_ptr<const SphereSetEntry>, std::shared_ptr<const SphereHierarchy>,
                 std::shared_ptr<const DeformerEntry>, std::shared_ptr<const CoverCertificate>>;

// A change in the shared (Redis) tier's health, for the binary to log.
struct SharedTierEvent {
  // true: Redis answers (at open, or again after being down); false: it failed and is now
  // skipped until retry_after has passed.
  bool available = false;
  // Why it went down (UNAVAILABLE; the message names host:port and what failed, never the
  // password). OK when available.
  absl::Status error;
  // When down: time until one lookup tries Redis again (1 s, doubling per failed retry, at most
  // 30 s).
  std::chrono::milliseconds retry_after{0};
};

// A change in the disk tier's health, for the binary to log. Disk trouble never fails a
// lookup: without the tier, results are computed (or read from Redis) and kept in memory.
struct DiskTierEvent {
  enum class Kind {
    // At Open: the directory cannot be created, listed or written; the cache runs without a
    // disk tier (memory and Redis only) for its whole life.
    kOff,
    // A write failed because the file system is full, read-only, over quota or forbids it
    // (ENOSPC, EROFS, EACCES, EPERM, EDQUOT, EFBIG, EIO): writes stop (reads of existing
    // entries go on) until retry_after has passed, when one write is tried again.
    kDegraded,
    // That retried write succeeded: writes go on.
    kRestored,
  };
  Kind kind = Kind::kOff;
  std::string dir;  // ResultCacheOptions::disk_dir
  // kOff, kDegraded: what failed, naming the path and the system's message. OK for kRestored.
  absl::Status error;
  // kDegraded: time until a write is tried again (1 s, doubling per failed retry, at most
  // 60 s).
  std::chrono::milliseconds retry_after{0};
};

struct ResultCacheOptions {
  // --cache-memory-bytes: the in-memory tier holds entries up to this many bytes in all (each
  // entry counts its key's length, its bytes and its object_bytes); the least recently used go
  // first. An entry larger than the whole budget is returned but not kept in memory.
  std::int64_t memory_bytes = std::int64_t{1} << 30;
  // --cache-dir: directory of the on-disk tier, created if missing; empty = no disk tier.
  // Entries survive restarts; a file that fails its checks on read is deleted and recomputed.
  // Files are disk_dir/<first 2 hex digits>/<64 hex digits of SHA-256(key)>. One process per
  // directory: Open removes the temporary files it finds, and the disk counters assume no
  // other writer. A directory that cannot be written, at Open or later, costs only the disk
  // tier (see DiskTierEvent); no lookup fails because of it.
  std::string disk_dir;
  // --cache-disk-bytes: the disk tier holds entries up to this many bytes in all (each entry
  // counts its file's size); 0 = unbounded. When a write takes them past it, the least
  // recently used entries (by last read or write; the order survives restarts as the files'
  // modification times) are deleted until they fit, skipping any being read or written at that
  // moment. Open deletes down to it too, so a restart with a smaller bound shrinks the
  // directory. An entry larger than the whole bound is not written (disk_writes_too_large).
  std::int64_t disk_bytes = 0;
  // --redis: URL of the Redis server replicas share as a third tier,
  // "redis://[:PASSWORD@]HOST[:PORT][/DB]"; empty = none. Results are written through to it;
  // a lookup missing memory and disk reads it before computing. Redis down or slow never fails
  // a lookup: the tier is skipped (logged and counted) and retried later.
  std::string redis_url;
  // --redis-timeout-ms: longest wait for one Redis connect, read or write.
  int redis_timeout_ms = 250;
  // Called (on a lookup's thread, with no lock of the cache held; must be cheap and
  // thread-safe) when the Redis tier goes down or comes back, and once at Open with its first
  // state. May be empty. The cache itself never logs.
  std::function<void(const SharedTierEvent&)> on_shared_tier_event;
  // Called (on the thread of the Open or the write concerned, with no lock of the cache held;
  // must be cheap and thread-safe) when the disk tier is off at Open, stops writing, or writes
  // again. May be empty.
  std::function<void(const DiskTierEvent&)> on_disk_tier_event;
};

// `url` with its password replaced by "***" ("redis://:***@host:6379/0"), for logs.
std::string RedactRedisUrl(absl::string_view url);

// One cached result: its serialised bytes (what the disk tier stores and what RPCs ship) and,
// optionally, a decoded object the service queries directly (e.g. a SphereHierarchy), so a hit
// costs no parsing. Immutable once cached; shared by every caller holding it.
struct CachedValue {
  std::string bytes;
  CachedObject object;            // may be empty (std::monostate)
  std::int64_t object_bytes = 0;  // memory the object holds, for the LRU budget
  // False for values that only make sense in this process (e.g. a deformer holding a refit
  // oracle): kept in memory only, never written to the disk or Redis tier.
  bool persist = true;

  // The object when it is a T, else null (another kind, or none).
  template <typename T>
  std::shared_ptr<const T> Get() const {
    const auto* held = std::get_if<std::shared_ptr<const T>>(&object);
    return held != nullptr ? *held : nullptr;
  }
};

// Where a lookup's value came from.
enum class CacheSource {
  kMemory,    // the in-memory tier
  kDisk,      // the on-disk tier (checksum verified), now also in memory
  kComputed,  // this call computed it
  kJoined,    // an identical call was computing it; this one waited for that result
  kShared,    // the shared Redis tier (checksum verified), now also in memory and on disk
};
// "memory", "disk", "computed", "joined", "redis"
const char* CacheSourceName(CacheSource source);

struct CacheLookup {
  std::shared_ptr<const CachedValue> value;
  CacheSource source = CacheSource::kMemory;
};

// The cache's counters: wire's plain value, so that CacheStats, the client and the CLI read the
// very struct the cache fills (wire/include/inscribe/wire/cache_stats.h documents each).
using ResultCacheStats = wire::CacheStats;

// Thread-safe. Keys are printable: 1-200 characters from [A-Za-z0-9._:/-], e.g.
// "spheres/v1/<64 hex>"; callers derive them from content hashes, so equal keys mean equal
// results. Disk files are named by the SHA-256 of the key.
class ResultCache {
 public:
  // Turns stored bytes back into a value (decoding its object), moving `bytes` into the
  // value's own `bytes`; used on disk hits. A failure counts as a corrupt entry: the file is
  // dropped and the result recomputed (GetOrCompute) or reported missing (Get).
  using Decode = std::function<absl::StatusOr<CachedValue>(std::string bytes)>;
  // Must not look up its own key (it would wait for itself).
  using Compute = std::function<absl::StatusOr<CachedValue>()>;

  // Creates disk_dir if needed and counts what it holds; connects to Redis once (unreachable
  // is not an error: the tier starts marked down, reported through on_shared_tier_event).
  // A disk_dir that cannot be created, listed or written is not an error either: the cache
  // runs without a disk tier (reported through on_disk_tier_event, kOff). INVALID_ARGUMENT for
  // a negative memory budget or disk bound (naming the flag) or a malformed redis_url (naming the
  // wrong part, never showing the password).
  static absl::StatusOr<std::unique_ptr<ResultCache>> Open(const ResultCacheOptions& options);

  // No call may be in progress.
  ~ResultCache();
  ResultCache(const ResultCache&) = delete;
  ResultCache& operator=(const ResultCache&) = delete;

  // The value under `key`: from memory, else from disk (decoded, then kept in memory), else
  // from Redis (verified, decoded, then kept in memory and written to disk), else computed by
  // `compute` on the calling thread, then stored in every tier (the disk write is atomic: a
  // temporary file, fsync, rename; the Redis write overwrites). A Redis that fails or times
  // out counts as a miss: the lookup goes on, costing at most a few redis_timeout_ms, and
  // Redis is skipped for a backoff. While one call computes a key, other calls for
  // the same key wait and share its result (or its error; errors are not cached), except that
  // when the computing call was cancelled or ran out of time (CANCELLED, DEADLINE_EXCEEDED:
  // its caller's own business) a waiter computes the key itself. INVALID_ARGUMENT for a
  // malformed key; otherwise compute's error.
  absl::StatusOr<CacheLookup> GetOrCompute(absl::string_view key, const Compute& compute,
                                           const Decode& decode);

  // The value under `key` from any tier, or NOT_FOUND ("no cached entry <key>"). Waits for
  // an identical computation in progress (NOT_FOUND, with its error, if that one fails).
  absl::StatusOr<CacheLookup> Get(absl::string_view key, const Decode& decode);

  // Stores a value computed elsewhere (e.g. an uploaded mesh) in every tier, replacing none: an
  // existing entry under `key` is kept (equal keys mean equal content) and returned; an
  // existing disk file is not rewritten (the Redis value is). INVALID_ARGUMENT for a malformed key.
  absl::StatusOr<std::shared_ptr<const CachedValue>> Put(absl::string_view key, CachedValue value);

  // A snapshot of every tier's counters; hits is memory_hits + disk_hits.
  ResultCacheStats stats() const;

 private:
  struct Impl;
  explicit ResultCache(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// OK for a well-formed key, else INVALID_ARGUMENT saying why.
absl::Status CheckCacheKey(absl::string_view key);

}  // namespace inscribe::server
