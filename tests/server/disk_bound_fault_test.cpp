// Fault injection on a bounded disk tier (--cache-disk-bytes, issue 27) against real inscribed
// processes: entry files deleted behind the server's back, SIGKILL, and a restart with a
// smaller bound. Calls must all succeed, the directory must stay within the bound, and the
// server's counts must agree with the files.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fault_injection_support.h"
#include "inscribe/client/client.h"

namespace inscribe::client {
namespace {

namespace fs = std::filesystem;
using faults::EntryFiles;
using faults::ExpectSameSpheres;
using faults::RandomSet;
using faults::ScratchDir;
using faults::Server;
using faults::TempFiles;

std::int64_t EntryBytes(const std::string& cache) {
  std::int64_t bytes = 0;
  for (const fs::path& file : EntryFiles(cache))
    bytes += static_cast<std::int64_t>(fs::file_size(file));
  return bytes;
}

// The server's disk counts against the files; the bound held.
void ExpectDiskWithin(Server& server, const std::string& cache, std::int64_t bound) {
  absl::StatusOr<ServerCacheStats> stats = server.client().CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_EQ(stats->disk_bytes_limit, bound);
  EXPECT_LE(stats->disk_bytes, bound);
  EXPECT_EQ(stats->disk_entries, static_cast<std::int64_t>(EntryFiles(cache).size()));
  EXPECT_EQ(stats->disk_bytes, EntryBytes(cache));
  EXPECT_EQ(stats->disk_errors + stats->disk_write_errors, 0);
  EXPECT_EQ(server.Metric("inscribe_disk_cache_limit_bytes"), bound);
  EXPECT_EQ(server.Metric("inscribe_disk_cache_evictions_total"), stats->disk_evictions);
  EXPECT_EQ(server.Metric("inscribe_disk_cache_evicted_bytes_total"), stats->disk_evicted_bytes);
}

// Stores `count` sets from `seed` on; their keys and sets, in order.
struct Stored {
  std::vector<std::string> keys;
  std::vector<SphereSet> sets;
};
Stored PutSets(Client& client, int count, std::uint64_t seed) {
  Stored stored;
  for (int i = 0; i < count; ++i) {
    SphereSet set = RandomSet(50, seed + i);
    absl::StatusOr<PutSphereSetResult> put = client.PutSphereSet(set);
    EXPECT_TRUE(put.ok()) << put.status();
    if (!put.ok()) continue;
    stored.keys.push_back(put->sphere_set_key);
    stored.sets.push_back(std::move(set));
  }
  return stored;
}

TEST(DiskBoundFaults, BoundHoldsThroughDeletionsKillAndASmallerRestart) {
  ScratchDir dir;
  const std::string cache = dir.Sub("cache");
  constexpr std::int64_t kBound = 48 << 10;
  Stored last;
  {
    Server server({"--cache-dir", cache, "--cache-disk-bytes", std::to_string(kBound)});
    ASSERT_TRUE(server.ready()) << server.log();
    PutSets(server.client(), 40, 5000);
    ExpectDiskWithin(server, cache, kBound);
    absl::StatusOr<ServerCacheStats> stats = server.client().CacheStats();
    ASSERT_TRUE(stats.ok()) << stats.status();
    ASSERT_GT(stats->disk_evictions, 0) << "the sets are too small to reach the bound";

    // Files deleted behind the server's back are forgotten as eviction or reads reach them.
    const std::vector<fs::path> files = EntryFiles(cache);
    ASSERT_GE(files.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) fs::remove(files[i]);
    last = PutSets(server.client(), 40, 6000);
    ExpectDiskWithin(server, cache, kBound);
    ASSERT_NE(server.Kill(), -1);  // no clean shutdown: the next start rebuilds from the files
  }
  EXPECT_LE(EntryBytes(cache), kBound);

  // A smaller bound at start evicts down to it; the most recent sets are still on disk.
  Server server({"--cache-dir", cache, "--cache-disk-bytes", std::to_string(kBound / 2)});
  ASSERT_TRUE(server.ready()) << server.log();
  ExpectDiskWithin(server, cache, kBound / 2);
  EXPECT_EQ(TempFiles(cache), 0);
  absl::StatusOr<ServerCacheStats> stats = server.client().CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_GT(stats->disk_evictions, 0);
  ASSERT_FALSE(last.keys.empty());
  absl::StatusOr<StoredSphereSet> newest = server.client().GetSphereSet(last.keys.back());
  ASSERT_TRUE(newest.ok()) << newest.status();
  ExpectSameSpheres(newest->spheres, last.sets.back());
  absl::StatusOr<StoredSphereSet> oldest = server.client().GetSphereSet(last.keys.front());
  EXPECT_EQ(oldest.status().code(), absl::StatusCode::kNotFound) << "not evicted";
  stats = server.client().CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_GE(stats->disk_hits, 1);
  EXPECT_EQ(server.Stop(), 0) << server.log();
}

}  // namespace
}  // namespace inscribe::client
