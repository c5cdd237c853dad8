// The result cache's counters: what the server's ResultCache counts, CacheStats sends
// (CacheStatsResponse in proto/inscribe/v1/service.proto) and the client library and
// `inscribe stats` read. A plain value, without gRPC, so that the server, the client's API and
// the CLI share one type; convert.h maps it to and from the wire.
#pragma once

#include <cstdint>

namespace inscribe::wire {

// Counters since the cache was opened (disk_entries / disk_bytes: what the directory holds
// now, counted at open and kept up to date by the server). Each lookup (GetOrCompute or Get
// with a well-formed key) counts in exactly one of memory_hits, disk_hits, shared_hits, misses
// and joined.
struct CacheStats {
  std::int64_t entries = 0;  // in memory
  std::int64_t bytes = 0;    // in memory (key length + bytes + object_bytes, summed)
  std::int64_t memory_hits = 0;
  std::int64_t disk_hits = 0;
  std::int64_t hits = 0;          // memory_hits + disk_hits
  std::int64_t misses = 0;        // lookups found in no tier (GetOrCompute or Get)
  std::int64_t computations = 0;  // compute functions run (failed ones included)
  std::int64_t joined = 0;        // lookups that waited for an identical computation
  std::int64_t evictions = 0;     // entries dropped from memory for the byte budget
  std::int64_t disk_entries = 0;
  std::int64_t disk_bytes = 0;
  std::int64_t disk_errors = 0;        // disk files dropped (bad checksum, truncated, wrong key)
  std::int64_t disk_write_errors = 0;  // results that could not be written (disk full, ...)
  // The shared Redis tier; all 0 without one.
  std::int64_t shared_hits = 0;    // lookups served from Redis
  std::int64_t shared_misses = 0;  // Redis reads that found nothing
  // Redis reads that failed (went on as a miss), or the check at open.
  std::int64_t shared_errors = 0;
  std::int64_t shared_writes = 0;  // entries written through to Redis
  std::int64_t shared_write_errors = 0;
  std::int64_t shared_skipped = 0;    // reads and writes not tried while Redis was marked down
  std::int64_t shared_corrupt = 0;    // Redis values that failed their checks (deleted)
  std::int64_t shared_available = 0;  // 1 while Redis is configured and not marked down
  // 1 while the disk tier is configured and writing; 0 without one, when it was off at open,
  // or while its writes are stopped after a failure.
  std::int64_t disk_available = 0;
  std::int64_t disk_writes_skipped = 0;  // results not written while disk writes were stopped
  // The disk tier's bound (--cache-disk-bytes; 0 = unbounded or no disk tier), the entries
  // deleted for it since open (at open included) and their bytes, and the results not written
  // because they alone exceed it.
  std::int64_t disk_bytes_limit = 0;
  std::int64_t disk_evictions = 0;
  std::int64_t disk_evicted_bytes = 0;
  std::int64_t disk_writes_too_large = 0;
};

// One counter of CacheStats: its name, which is its CacheStatsResponse field's and its key in
// `inscribe stats --json`, and where it is in the struct.
struct CacheStatsCounter {
  const char* name;
  std::int64_t CacheStats::*value;
};

// Every counter, in CacheStatsResponse's field order: the one list that the conversions both
// ways (convert.h) and `inscribe stats` go through. A new counter is a proto field, a member
// above and a line here.
inline constexpr CacheStatsCounter kCacheStatsCounters[] = {
    {"entries", &CacheStats::entries},
    {"bytes", &CacheStats::bytes},
    {"memory_hits", &CacheStats::memory_hits},
    {"disk_hits", &CacheStats::disk_hits},
    {"hits", &CacheStats::hits},
    {"misses", &CacheStats::misses},
    {"computations", &CacheStats::computations},
    {"joined", &CacheStats::joined},
    {"evictions", &CacheStats::evictions},
    {"disk_entries", &CacheStats::disk_entries},
    {"disk_bytes", &CacheStats::disk_bytes},
    {"disk_errors", &CacheStats::disk_errors},
    {"shared_hits", &CacheStats::shared_hits},
    {"shared_misses", &CacheStats::shared_misses},
    {"shared_errors", &CacheStats::shared_errors},
    {"shared_writes", &CacheStats::shared_writes},
    {"shared_write_errors", &CacheStats::shared_write_errors},
    {"shared_skipped", &CacheStats::shared_skipped},
    {"shared_corrupt", &CacheStats::shared_corrupt},
    {"shared_available", &CacheStats::shared_available},
    {"disk_write_errors", &CacheStats::disk_write_errors},
    {"disk_writes_skipped", &CacheStats::disk_writes_skipped},
    {"disk_available", &CacheStats::disk_available},
    {"disk_bytes_limit", &CacheStats::disk_bytes_limit},
    {"disk_evictions", &CacheStats::disk_evictions},
    {"disk_evicted_bytes", &CacheStats::disk_evicted_bytes},
    {"disk_writes_too_large", &CacheStats::disk_writes_too_large},
};

}  // namespace inscribe::wire
