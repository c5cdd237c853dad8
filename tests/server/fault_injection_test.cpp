// Fault injection against real inscribed processes on loopback (issue 8): corrupt disk cache
// entries, an unwritable or full cache directory (at start and at run time), SIGKILL during
// cache writes, and clients that cancel or vanish mid-call. Every call must still succeed (or
// fail with the caller's own CANCELLED), nothing partial may ever be served, and the server
// must free the abandoned work.
//
// Unwritable for real: as root (CI) the server runs as nobody (setpriv), since root ignores
// permission bits. Full: RLIMIT_FSIZE lowered on the running server (prlimit(2); inscribed
// ignores SIGXFSZ, so writes fail with EFBIG like a full disk) always, and a 256 KiB tmpfs
// where mount(2) is allowed. The binary's own main() also serves as a DistanceStream client
// child (--stream-client) that the test kills mid-frame.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "fault_injection_support.h"
#include "grpcpp/grpcpp.h"
#include "inscribe/client/client.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "support/sphere_sets.h"
#include "support/test_meshes.h"

namespace inscribe::client {
namespace {

namespace fs = std::filesystem;
using faults::EntryFiles;
using faults::ExpectSameSpheres;
using faults::RandomSet;
using faults::ReadBytes;
using faults::ScratchDir;
using faults::Server;
using faults::TempFiles;
using faults::WaitFor;
using faults::WriteBytes;
using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;

GenerateSettings CoarseFor(const Mesh& mesh) {
  GenerateSettings settings;
  settings.parameters.voxel_size = 0.05 * ComputeBoundingBox(mesh.vertices).diagonal();
  settings.parameters.evaluate = false;
  return settings;
}

// --- a. Corrupt entries ----------------------------------------------------------------------

struct Corruption {
  const char* name;
  std::function<void(std::string&)> apply;
};

std::vector<Corruption> Corruptions() {
  const auto flip = [](double where) {
    return [where](std::string& bytes) {
      const std::size_t at = std::min(bytes.size() - 1, static_cast<std::size_t>(where));
      bytes[at] = static_cast<char>(bytes[at] ^ 0x10);
    };
  };
  return {
      {"truncated to half", [](std::string& b) { b.resize(b.size() / 2); }},
      {"truncated inside the header", [](std::string& b) { b.resize(20); }},
      {"empty", [](std::string& b) { b.clear(); }},
      {"zeroed", [](std::string& b) { b.assign(b.size(), '\0'); }},
      {"bit flip in the magic", flip(3)},
      {"bit flip in the key length", flip(18)},
      {"bit flip in the payload", [](std::string& b) { b[b.size() / 2] ^= 0x01; }},
      {"bit flip in the last byte", [](std::string& b) { b.back() ^= 0x80; }},
  };
}

TEST(DiskFaults, CorruptEntriesAreDroppedRecomputedAndReplaced) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  const GenerateSettings settings = CoarseFor(mesh);
  ScratchDir dir;
  const std::string cache = dir.Sub("cache");
  const std::vector<std::string> args = {"--cache-dir", cache, "--jobs", "2"};

  GenerateResult original;
  {
    Server server(args);
    ASSERT_TRUE(server.ready()) << server.log();
    absl::StatusOr<GenerateResult> generated = server.client().Generate(mesh, settings);
    ASSERT_TRUE(generated.ok()) << generated.status();
    EXPECT_EQ(generated->cache, "computed");
    original = *std::move(generated);
    ASSERT_EQ(server.Stop(), 0) << server.log();
  }
  // The mesh's entry and the sphere set's.
  const std::vector<fs::path> files = EntryFiles(cache);
  ASSERT_EQ(files.size(), 2u);
  std::map<fs::path, std::string> good;
  for (const fs::path& file : files) good[file] = ReadBytes(file);

  for (const Corruption& corruption : Corruptions()) {
    SCOPED_TRACE(corruption.name);
    for (const auto& [file, bytes] : good) {
      std::string bad = bytes;
      corruption.apply(bad);
      ASSERT_NE(bad, bytes);
      WriteBytes(file, bad);
    }
    {
      Server server(args);
      ASSERT_TRUE(server.ready()) << server.log();
      absl::StatusOr<GenerateResult> again = server.client().Generate(mesh, settings);
      ASSERT_TRUE(again.ok()) << again.status();
      EXPECT_EQ(again->cache, "computed");
      EXPECT_EQ(again->sphere_set_key, original.sphere_set_key);
      ExpectSameSpheres(again->set, original.set);
      absl::StatusOr<ServerCacheStats> stats = server.client().CacheStats();
      ASSERT_TRUE(stats.ok()) << stats.status();
      EXPECT_EQ(stats->disk_errors, 2);  // each file read once, failed its checks, dropped
      EXPECT_EQ(stats->disk_hits, 0);
      EXPECT_EQ(stats->disk_entries, 2);  // written again
      ASSERT_EQ(server.Stop(), 0) << server.log();
    }
    // The replacements are good: a fresh server serves both from disk.
    Server server(args);
    ASSERT_TRUE(server.ready()) << server.log();
    absl::StatusOr<GenerateResult> from_disk = server.client().Generate(mesh, settings);
    ASSERT_TRUE(from_disk.ok()) << from_disk.status();
    EXPECT_EQ(from_disk->cache, "disk");
    ExpectSameSpheres(from_disk->set, original.set);
    absl::StatusOr<ServerCacheStats> stats = server.client().CacheStats();
    ASSERT_TRUE(stats.ok()) << stats.status();
    EXPECT_EQ(stats->disk_errors, 0);
    EXPECT_EQ(stats->disk_hits, 2);
    ASSERT_EQ(server.Stop(), 0) << server.log();
    for (const auto& [file, bytes] : good) good[file] = ReadBytes(file);
  }
}

// --- b. Unwritable and full directories ------------------------------------------------------

// Calls succeed without the disk; `expect_on_disk` entries are there.
void ExpectServedFromMemory(Client& client, int sets, std::uint64_t seed) {
  for (int i = 0; i < sets; ++i) {
    const SphereSet set = RandomSet(20, seed + i);
    absl::StatusOr<PutSphereSetResult> put = client.PutSphereSet(set);
    ASSERT_TRUE(put.ok()) << put.status();
    absl::StatusOr<StoredSphereSet> got = client.GetSphereSet(put->sphere_set_key);
    ASSERT_TRUE(got.ok()) << got.status();
    ExpectSameSpheres(got->spheres, set);
  }
}

TEST(DiskFaults, UnusableDirectoryAtStartRunsMemoryOnly) {
  ScratchDir dir;
  // Cannot be created (its parent is a file), and exists but is read-only to the server.
  WriteBytes(dir.path() / "file", "x");
  const std::string under_file = (dir.path() / "file" / "cache").string();
  const std::string read_only = dir.Sub("read-only");
  ::chmod(read_only.c_str(), 0555);
  std::vector<std::string> as_nobody;
  if (::geteuid() == 0) {
    as_nobody = faults::AsNobodyPrefix();
    if (as_nobody.empty()) GTEST_SKIP() << "running as root and cannot drop to uid 65534";
  }
  for (const auto& [cache, prefix] :
       {std::pair{under_file, std::vector<std::string>{}}, std::pair{read_only, as_nobody}}) {
    SCOPED_TRACE(cache);
    Server server({"--cache-dir", cache}, prefix);
    ASSERT_TRUE(server.ready()) << server.log();
    ExpectServedFromMemory(server.client(), 3, 100);
    absl::StatusOr<ServerCacheStats> stats = server.client().CacheStats();
    ASSERT_TRUE(stats.ok()) << stats.status();
    EXPECT_EQ(stats->disk_available, 0);
    EXPECT_EQ(stats->disk_entries + stats->disk_write_errors + stats->disk_writes_skipped, 0);
    EXPECT_EQ(server.Metric("inscribe_disk_cache_available"), 0);
    ASSERT_EQ(server.Stop(), 0) << server.log();
    EXPECT_THAT(server.log(),
                HasSubstr("level=warning event=disk_cache_off dir=\"" + cache + "\" reason=\""));
  }
  EXPECT_TRUE(fs::is_empty(read_only));
}

// A server on a writable directory whose writes then fail (`impose`) and later work again
// (`lift`): calls all succeed, the warning is logged once, stats show the tier down, and after
// the backoff a write restores it.
void DegradeAndRestore(Server& server, const std::string& cache,
                       const std::function<void()>& impose, const std::function<void()>& lift,
                       const std::string& reason) {
  Client& client = server.client();
  ExpectServedFromMemory(client, 3, 1000);
  absl::StatusOr<ServerCacheStats> stats = client.CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  ASSERT_EQ(stats->disk_entries, 3);
  ASSERT_EQ(stats->disk_available, 1);

  impose();
  ExpectServedFromMemory(client, 5, 2000);
  stats = client.CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_EQ(stats->disk_available, 0);
  EXPECT_EQ(server.Metric("inscribe_disk_cache_available"), 0);
  EXPECT_GE(stats->disk_write_errors, 1);
  EXPECT_EQ(stats->disk_write_errors + stats->disk_writes_skipped, 5);
  EXPECT_EQ(stats->disk_entries, 3);
  EXPECT_TRUE(WaitFor(seconds(5), [&] {
    return server.log().find("event=disk_cache_degraded") != std::string::npos;
  }));
  const std::string log = server.log();
  EXPECT_THAT(log, HasSubstr("level=warning event=disk_cache_degraded dir=\"" + cache + "\""));
  EXPECT_THAT(log, HasSubstr(reason));
  EXPECT_THAT(log, HasSubstr("retry_ms=1000"));
  EXPECT_EQ(TempFiles(cache), 0);

  lift();
  std::uint64_t seed = 3000;
  const bool restored = WaitFor(seconds(20), [&] {
    ExpectServedFromMemory(client, 1, seed++);
    absl::StatusOr<ServerCacheStats> now = client.CacheStats();
    return now.ok() && now->disk_available == 1;
  });
  ASSERT_TRUE(restored) << server.log();
  stats = client.CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_EQ(stats->disk_entries, 4);  // the retried write; those skipped stay in memory only
  EXPECT_EQ(server.Metric("inscribe_disk_cache_available"), 1);
  EXPECT_TRUE(WaitFor(seconds(5), [&] {
    return server.log().find("level=info event=disk_cache_restored dir=\"" + cache + "\"") !=
           std::string::npos;
  })) << server.log();
  // Logged once per outage, not per failed write.
  const std::string final_log = server.log();
  std::size_t warnings = 0;
  for (std::size_t at = final_log.find("event=disk_cache_degraded"); at != std::string::npos;
       at = final_log.find("event=disk_cache_degraded", at + 1)) {
    ++warnings;
  }
  EXPECT_EQ(warnings, 1u);
}

TEST(DiskFaults, DirectoryTurnedReadOnlyDegradesThenRestores) {
  ScratchDir dir;
  const std::string cache = dir.Sub("cache");
  std::vector<std::string> prefix;
  if (::geteuid() == 0) {
    prefix = faults::AsNobodyPrefix();
    if (prefix.empty()) GTEST_SKIP() << "running as root and cannot drop to uid 65534";
    ASSERT_EQ(::chown(cache.c_str(), faults::kNobody, faults::kNobody), 0);
  }
  Server server({"--cache-dir", cache}, prefix);
  ASSERT_TRUE(server.ready()) << server.log();
  DegradeAndRestore(
      server, cache, [&] { faults::ChmodTree(cache, 0555); },
      [&] { faults::ChmodTree(cache, 0755); }, "Permission denied");
}

TEST(DiskFaults, FileSizeLimitLikeAFullDiskDegradesThenRestores) {
  ScratchDir dir;
  const std::string cache = dir.Sub("cache");
  Server server({"--cache-dir", cache});
  ASSERT_TRUE(server.ready()) << server.log();
  rlimit saved{};
  ASSERT_EQ(::prlimit(server.pid(), RLIMIT_FSIZE, nullptr, &saved), 0);
  const auto set_limit = [&](rlim_t bytes) {
    rlimit limit = saved;
    limit.rlim_cur = bytes;
    ASSERT_EQ(::prlimit(server.pid(), RLIMIT_FSIZE, &limit, nullptr), 0);
  };
  DegradeAndRestore(
      server, cache, [&] { set_limit(64); }, [&] { set_limit(saved.rlim_cur); }, "File too large");
  EXPECT_EQ(server.Stop(), 0) << "the server must survive SIGXFSZ\n" << server.log();
}

TEST(DiskFaults, FullTmpfsDegradesThenRestoresWhenSpaceIsFreed) {
  ScratchDir dir;
  const std::string cache = dir.Sub("cache");
  if (::geteuid() != 0 || ::mount("tmpfs", cache.c_str(), "tmpfs", 0, "size=256k") != 0) {
    GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno)
                 << "); FileSizeLimitLikeAFullDiskDegradesThenRestores covers full disks";
  }
  struct Unmount {
    std::string at;
    ~Unmount() { ::umount2(at.c_str(), MNT_DETACH); }
  } unmount{cache};
  Server server({"--cache-dir", cache});
  ASSERT_TRUE(server.ready()) << server.log();
  Client& client = server.client();
  // ~16 KiB entries: the 256 KiB file system fills after about 15.
  int stored = 0;
  std::uint64_t seed = 5000;
  const bool full = WaitFor(seconds(20), [&] {
    const SphereSet set = RandomSet(500, seed++);
    absl::StatusOr<PutSphereSetResult> put = client.PutSphereSet(set);
    EXPECT_TRUE(put.ok()) << put.status();
    ++stored;
    absl::StatusOr<ServerCacheStats> stats = client.CacheStats();
    return stats.ok() && stats->disk_available == 0;
  });
  ASSERT_TRUE(full);
  EXPECT_GT(stored, 5);
  EXPECT_LT(stored, 40);
  EXPECT_TRUE(WaitFor(seconds(5), [&] {
    return server.log().find("No space left on device") != std::string::npos;
  })) << server.log();
  EXPECT_EQ(TempFiles(cache), 0);  // the partial file was removed
  // An operator frees space: the next write after the backoff goes through.
  for (const fs::path& file : EntryFiles(cache)) fs::remove(file);
  const bool restored = WaitFor(seconds(20), [&] {
    ExpectServedFromMemory(client, 1, seed++);
    absl::StatusOr<ServerCacheStats> stats = client.CacheStats();
    return stats.ok() && stats->disk_available == 1;
  });
  EXPECT_TRUE(restored) << server.log();
  EXPECT_EQ(server.Stop(), 0) << server.log();
  EXPECT_THAT(server.log(), HasSubstr("event=disk_cache_restored"));
}

// --- c. SIGKILL during cache writes ----------------------------------------------------------

TEST(CrashFaults, KillDuringWritesNeverLeavesAPartialEntry) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  const double diagonal = ComputeBoundingBox(mesh.vertices).diagonal();
  ScratchDir dir;
  const std::string cache = dir.Sub("cache");
  std::mt19937_64 rng(20240608);
  std::map<std::string, SphereSet> acknowledged;  // key -> what the client stored
  std::atomic<std::uint64_t> next_seed{1};
  int kills_mid_write = 0;
  constexpr int kRounds = 4;
  for (int round = 0; round < kRounds; ++round) {
    Server server({"--cache-dir", cache, "--jobs", "2"});
    ASSERT_TRUE(server.ready()) << server.log();
    std::mutex mutex;
    std::atomic<bool> stop{false};
    std::vector<std::thread> threads;
    ClientOptions one_try;
    one_try.retry.max_attempts = 1;
    one_try.default_timeout = milliseconds(5000);
    for (int t = 0; t < 3; ++t) {
      threads.emplace_back([&, t] {
        Client client(MakeGrpcConnection(server.address()), one_try);
        while (!stop.load()) {
          if (t == 0) {  // a Generate now and then: a few distinct voxel sizes
            GenerateSettings settings = CoarseFor(mesh);
            settings.parameters.voxel_size = diagonal * (0.04 + 0.001 * (next_seed++ % 20));
            absl::StatusOr<GenerateResult> made = client.Generate(mesh, settings);
            if (!made.ok()) return;
            std::lock_guard<std::mutex> lock(mutex);
            acknowledged[made->sphere_set_key] = made->set;
            continue;
          }
          const std::uint64_t seed = next_seed++;
          const SphereSet set = RandomSet(1 + static_cast<int>(seed % 300), seed);
          absl::StatusOr<PutSphereSetResult> put = client.PutSphereSet(set);
          if (!put.ok()) return;  // the server is gone
          std::lock_guard<std::mutex> lock(mutex);
          acknowledged[put->sphere_set_key] = set;
        }
      });
    }
    std::this_thread::sleep_for(
        testing::Stretched(milliseconds(std::uniform_int_distribution<int>(150, 600)(rng))));
    EXPECT_NE(server.Kill(), -1);
    stop.store(true);
    for (std::thread& thread : threads) thread.join();
    if (TempFiles(cache) > 0) ++kills_mid_write;
  }
  std::cout << "[ stats    ] " << kRounds << " kills, " << kills_mid_write
            << " left temporary files; " << acknowledged.size() << " acknowledged results\n";
  ASSERT_GT(acknowledged.size(), 20u);

  Server server({"--cache-dir", cache});
  ASSERT_TRUE(server.ready()) << server.log();
  EXPECT_EQ(TempFiles(cache), 0);  // removed at start
  Client& client = server.client();
  absl::StatusOr<ServerCacheStats> before = client.CacheStats();
  ASSERT_TRUE(before.ok()) << before.status();
  EXPECT_EQ(before->disk_entries, static_cast<std::int64_t>(EntryFiles(cache).size()));
  // The server acknowledges a result only after its file was renamed into place, and SIGKILL
  // loses no page cache: every acknowledged result is on disk, whole.
  int missing = 0;
  for (const auto& [key, set] : acknowledged) {
    absl::StatusOr<StoredSphereSet> got = client.GetSphereSet(key);
    if (!got.ok()) {
      ++missing;
      EXPECT_EQ(got.status().code(), absl::StatusCode::kNotFound) << key << " " << got.status();
      continue;
    }
    ExpectSameSpheres(got->spheres, set);
  }
  EXPECT_EQ(missing, 0);
  absl::StatusOr<ServerCacheStats> after = client.CacheStats();
  ASSERT_TRUE(after.ok()) << after.status();
  EXPECT_EQ(after->disk_errors, 0);  // no file failed its checks
  EXPECT_EQ(after->disk_hits, static_cast<std::int64_t>(acknowledged.size()) - missing);
  EXPECT_EQ(server.Stop(), 0);
}

// --- d. Cancelled and abandoned calls --------------------------------------------------------

// A slow Generate (a fine grid on a real mesh) started on the raw stub and cancelled once its
// progress passes `cancel_at`.
void GenerateAndCancel(const std::string& address, const std::string& mesh_sha256,
                       double voxel_size, double cancel_at) {
  auto stub =
      v1::Inscribe::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + testing::Stretched(seconds(60)));
  v1::GenerateRequest request;
  request.set_mesh_sha256(mesh_sha256);
  request.mutable_parameters()->set_voxel_size(voxel_size);
  request.set_skip_quality(true);
  request.set_progress_interval(0.05);
  std::unique_ptr<grpc::ClientReader<v1::GenerateResponse>> reader =
      stub->Generate(&context, request);
  v1::GenerateResponse response;
  do {
    ASSERT_TRUE(reader->Read(&response)) << reader->Finish().error_message();
    ASSERT_TRUE(response.has_progress()) << "finished before it could be cancelled";
  } while (response.progress().fraction() < cancel_at);
  context.TryCancel();
  while (reader->Read(&response)) {
  }
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);
}

TEST(ClientFaults, CancelledGenerateAndKilledStreamClientFreeTheWork) {
  INSCRIBE_REQUIRE_MESH("elephant.off");
  const Mesh mesh = testing::LoadTestMesh("elephant.off");
  const double diagonal = ComputeBoundingBox(mesh.vertices).diagonal();
  // RSS tracks what the server still holds: freed blocks over 128 KiB go straight back to the
  // kernel (a fixed mmap threshold; glibc's adaptive one keeps them in the heap) and all threads
  // share one arena, so that memory freed by one cycle's threads is reused by the next cycle's
  // instead of each thread's arena keeping its own copy.
  ::setenv("GLIBC_TUNABLES",
           "glibc.malloc.mmap_threshold=131072:glibc.malloc.trim_threshold=131072:glibc.malloc."
           "arena_max=1",
           1);
  Server server({"--jobs", "2"});
  ::unsetenv("GLIBC_TUNABLES");
  ASSERT_TRUE(server.ready()) << server.log();
  Client& client = server.client();
  absl::StatusOr<PutMeshResult> stored = client.PutMesh(mesh);
  ASSERT_TRUE(stored.ok()) << stored.status();
  const auto in_flight = [&] { return server.Metric("inscribe_jobs_in_flight"); };
  const auto rss = [&] { return testing::ReadProcessMemory(server.pid()).resident; };

  // Each cycle: a Generate that would need far more time than it gets, cancelled mid-way; then
  // a stream client killed in the middle of a heavy frame (100,000 pose pairs: ~25 MB on the
  // wire, ~30 s of work uncancelled here). Distinct voxel sizes, so no cycle joins or hits
  // another's work.
  constexpr int kCycles = 4;
  constexpr std::int64_t kSlack = std::int64_t{64} << 20;
  std::int64_t baseline = 0, frame_bytes = 0, largest_after = 0;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    SCOPED_TRACE("cycle " + std::to_string(cycle));
    GenerateAndCancel(server.address(), stored->mesh_sha256, diagonal * (0.0040 + 0.0001 * cycle),
                      0.3);
    ASSERT_TRUE(WaitFor(testing::Stretched(seconds(10)), [&] { return in_flight() == 0; }))
        << "cancelled Generate still running";

    const std::int64_t before_stream = rss();
    faults::StreamClientChild child(server.address(), 100'000 + cycle);
    ASSERT_TRUE(child.WaitUntilFrameSent()) << "stream client failed to start";
    ASSERT_TRUE(WaitFor(testing::Stretched(seconds(10)), [&] { return in_flight() > 0; }))
        << "the frame never reached the pool";
    // The first frame's memory (its message, queries, results), measured from cold.
    if (cycle == 0) frame_bytes = rss() - before_stream;
    child.Kill();
    ASSERT_TRUE(WaitFor(testing::Stretched(seconds(10)), [&] { return in_flight() == 0; }))
        << "abandoned stream frame still running";

    if (cycle == 0) {
      baseline = rss();  // warmed up: caches, pools, connections, the stream's hierarchies
      continue;
    }
    // Released within seconds of the work stopping; leaked work would stay.
    std::int64_t settled = rss();
    const bool returned = WaitFor(testing::Stretched(seconds(10)), [&] {
      settled = rss();
      return settled - baseline < kSlack;
    });
    largest_after = std::max(largest_after, settled - baseline);
    // Under a sanitizer freed memory stays resident (ASan's quarantine, shadow memory); there
    // only the work's end (in_flight() above) is checked.
    if (!testing::kSanitizedBuild) {
      EXPECT_TRUE(returned) << "RSS stays " << (settled - baseline) / (1 << 20)
                            << " MiB above the baseline";
    }
  }
  std::cout << "[ stats    ] baseline RSS " << baseline / (1 << 20) << " MiB; one frame +"
            << frame_bytes / (1 << 20) << " MiB; after cancelling up to +"
            << largest_after / (1 << 20) << " MiB\n";
  // Abandoned work kept alive would add at least a frame per cycle: more than the slack.
  EXPECT_GT(frame_bytes, kSlack) << "the work is too small to show a leak";
  absl::StatusOr<ServerCacheStats> stats = client.CacheStats();
  ASSERT_TRUE(stats.ok()) << stats.status();
  EXPECT_EQ(server.Stop(), 0) << server.log();
}

}  // namespace
}  // namespace inscribe::client

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--stream-client") {
    return inscribe::client::faults::RunStreamClient(argv[2], std::atoi(argv[3]));
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
