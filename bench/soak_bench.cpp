// Soak: one inscribed process on loopback, N concurrent clients mixing Generate,
// UpdateDeformation, Distance and DistanceStream for a fixed time, every loop bounded by a
// deadline and an iteration cap so the run always ends by itself. Reports calls, errors (any
// failed call, or an answer of the wrong size), p50/p99/max latency per RPC, the server's
// resident memory at start (after warm-up), at the end and at its peak, and its disk cache:
// bytes at the end and the most seen (the server's count, sampled each second, and the entry
// files in the directory), evictions and disk errors. Exit status 1 when any call failed, the
// disk tier counted an error, the resident memory grew by more than the cache's memory budget
// (what the server may legitimately keep) plus a fixed allowance for allocator slack, or, with
// --cache-disk-bytes, the disk cache was ever seen above it.
//
//   soak_bench [--seconds S] [--clients N] [--cache-memory-bytes B] [--cache-disk-bytes D] ...
//   (bench/run-soak)
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_format.h"
#include "deformation_sequences.h"
#include "inscribe/client/client.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "support/inscribed_process.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string inscribed = INSCRIBED;
  std::string data_dir = INSCRIBE_SOURCE_DIR "/data";
  std::vector<std::string> models = {"eight", "knot1", "cow", "fandisk", "elephant", "bunny00"};
  double seconds = 600.0;
  int clients = 16;
  int jobs = 2;                                   // the server's --jobs
  std::int64_t cache_memory_bytes = 64ll << 20;   // the server's --cache-memory-bytes
  std::int64_t cache_disk_bytes = 0;              // the server's --cache-disk-bytes (0: none)
  std::int64_t rss_allowance_bytes = 64ll << 20;  // allocator slack on top of the budget
  int variants = 8;                               // voxel sizes per model (cache misses)
  int batch = 200;                                // pose pairs per Distance call
  int frames = 20;                                // frames per DistanceStream session
  int pairs_per_frame = 8;
};

// The four RPCs the soak mixes, with their share of a client's iterations (percent).
enum Rpc { kGenerate, kUpdateDeformation, kDistance, kDistanceStream, kRpcCount };
constexpr const char* kRpcNames[kRpcCount] = {"Generate", "UpdateDeformation", "Distance",
                                              "DistanceStream (session)"};
constexpr int kRpcShare[kRpcCount] = {10, 20, 45, 25};

struct Model {
  std::string name;
  Mesh mesh;
  double extent = 0.0;  // largest bounding-box side
  std::string mesh_sha256;
  std::string base_key;  // sphere set of variant 0, with contacts: deformation reference
};

// Latencies and errors of one client thread, merged at the end (no sharing while running).
struct Record {
  std::vector<double> seconds[kRpcCount];
  std::int64_t errors[kRpcCount] = {};
};

std::mutex error_mutex;
std::int64_t printed_errors = 0;

void Report(Record& record, Rpc rpc, const std::string& what, const absl::Status& status) {
  ++record.errors[rpc];
  std::lock_guard<std::mutex> lock(error_mutex);
  if (printed_errors++ < 20) std::cerr << "soak: " << what << ": " << status << "\n";
}

client::GenerateSettings Settings(const Model& model, int variant) {
  client::GenerateSettings settings;
  settings.parameters.voxel_size =
      model.extent / (16.0 + 2.0 * variant);  // 16..30 voxels along the side
  settings.parameters.evaluate = false;
  return settings;
}

RigidPose RandomPose(std::mt19937_64& random, double scale) {
  std::normal_distribution<double> normal;
  RigidPose pose;
  pose.rotation = Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random))
                      .normalized();
  pose.translation = Vector3(normal(random), normal(random), normal(random)) * scale;
  return pose;
}

// One client: random RPCs until `deadline` (and at most `max_iterations`, so a clock problem
// cannot make it run forever).
void RunClient(const Options& options, const client::Client& client,
               const std::vector<Model>& models, Clock::time_point deadline, std::uint64_t seed,
               Record& record) {
  std::mt19937_64 random(seed);
  std::uniform_int_distribution<int> percent(0, 99);
  std::uniform_int_distribution<std::size_t> pick(0, models.size() - 1);
  const std::int64_t max_iterations = static_cast<std::int64_t>(options.seconds * 1000) + 100;
  const std::vector<sequences::DeformationKind> kinds = sequences::AllDeformationKinds();
  for (std::int64_t i = 0; i < max_iterations && Clock::now() < deadline; ++i) {
    int roll = percent(random);
    Rpc rpc = kGenerate;
    while (roll >= kRpcShare[rpc]) roll -= kRpcShare[rpc], rpc = static_cast<Rpc>(rpc + 1);
    const Model& a = models[pick(random)];
    const Model& b = models[pick(random)];
    const Clock::time_point start = Clock::now();
    switch (rpc) {
      case kGenerate: {
        const int variant = std::uniform_int_distribution<int>(0, options.variants - 1)(random);
        absl::StatusOr<client::GenerateResult> result =
            client.Generate(a.mesh_sha256, Settings(a, variant));
        if (!result.ok())
          Report(record, rpc, "Generate " + a.name, result.status());
        else if (result->set.spheres.empty()) {
          Report(record, rpc, "Generate " + a.name, absl::InternalError("no spheres"));
        }
        break;
      }
      case kUpdateDeformation: {
        const sequences::DeformationKind kind =
            kinds[std::uniform_int_distribution<std::size_t>(0, kinds.size() - 1)(random)];
        const double t = std::uniform_real_distribution<double>(0.05, 1.0)(random);
        client::DeformationSettings settings;
        settings.store = percent(random) < 25;  // some moved sets are cached too
        absl::StatusOr<client::DeformationResult> result = client.UpdateDeformation(
            a.mesh_sha256, a.base_key, sequences::Deform(a.mesh.vertices, kind, t), settings);
        if (!result.ok()) Report(record, rpc, "UpdateDeformation " + a.name, result.status());
        break;
      }
      case kDistance: {
        std::vector<RigidPose> poses_b;
        for (int k = 0; k < options.batch; ++k) poses_b.push_back(RandomPose(random, a.extent));
        absl::StatusOr<client::DistanceBatchResult> result =
            client.Distance(a.base_key, b.base_key, {RigidPose{}}, poses_b);
        if (!result.ok())
          Report(record, rpc, "Distance " + a.name, result.status());
        else if (result->results.size() != poses_b.size()) {
          Report(record, rpc, "Distance " + a.name, absl::InternalError("wrong answer count"));
        }
        break;
      }
      case kDistanceStream: {
        absl::StatusOr<client::DistanceSession> session = client.OpenDistanceSession();
        if (!session.ok()) {
          Report(record, rpc, "OpenDistanceSession", session.status());
          break;
        }
        absl::Status status;
        for (int f = 0; f < options.frames && status.ok(); ++f) {
          std::vector<client::PosePair> pairs;
          for (int k = 0; k < options.pairs_per_frame; ++k) {
            const Model& x = models[pick(random)];
            const Model& y = models[pick(random)];
            pairs.push_back({x.base_key, y.base_key, RandomPose(random, x.extent),
                             RandomPose(random, x.extent)});
          }
          absl::StatusOr<std::vector<DistanceResult>> frame = session->Query(pairs);
          if (!frame.ok())
            status = frame.status();
          else if (frame->size() != pairs.size())
            status = absl::InternalError("frame size");
        }
        if (status.ok()) status = session->Close();
        if (!status.ok()) Report(record, rpc, "DistanceStream", status);
        break;
      }
      case kRpcCount:
        break;
    }
    record.seconds[rpc].push_back(std::chrono::duration<double>(Clock::now() - start).count());
  }
}

double Quantile(std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double MiB(std::int64_t bytes) { return static_cast<double>(bytes) / (1 << 20); }

// Bytes of the cache's entry files (dir/<2 hex>/<64 hex>) and of its temporary files (writes in
// progress), walked while the server writes and deletes: files vanishing meanwhile are skipped.
struct DirectoryBytes {
  std::int64_t entries = 0;
  std::int64_t temporary = 0;
};
DirectoryBytes MeasureDirectory(const std::filesystem::path& dir) {
  DirectoryBytes bytes;
  std::error_code error;
  for (auto it = std::filesystem::recursive_directory_iterator(dir, error);
       !error && it != std::filesystem::recursive_directory_iterator(); it.increment(error)) {
    std::error_code ignored;
    if (!it->is_regular_file(ignored)) continue;
    const std::uintmax_t size = it->file_size(ignored);
    if (ignored) continue;
    const bool temporary = it->path().filename().string().find(".tmp-") != std::string::npos;
    (temporary ? bytes.temporary : bytes.entries) += static_cast<std::int64_t>(size);
  }
  return bytes;
}

// The disk cache over the run: the server's count (CacheStats) and the directory, each second.
struct DiskWatch {
  std::int64_t max_counted = 0;
  std::int64_t max_entries = 0;  // entry files in the directory
  std::int64_t max_total = 0;    // entry and temporary files
  int stats_errors = 0;

  void Sample(const client::Client& client, const std::filesystem::path& dir) {
    absl::StatusOr<client::ServerCacheStats> stats = client.CacheStats();
    if (stats.ok()) {
      max_counted = std::max(max_counted, stats->disk_bytes);
    } else {
      ++stats_errors;
    }
    const DirectoryBytes bytes = MeasureDirectory(dir);
    max_entries = std::max(max_entries, bytes.entries);
    max_total = std::max(max_total, bytes.entries + bytes.temporary);
  }
};

int Run(const Options& options) {
  const std::filesystem::path cache_dir =
      std::filesystem::temp_directory_path() / ("inscribe-soak-" + std::to_string(getpid()));
  std::filesystem::remove_all(cache_dir);
  testing::InscribedProcess server(
      options.inscribed, {"--listen", "127.0.0.1:0", "--jobs", std::to_string(options.jobs),
                          "--log-level", "warn", "--cache-dir", cache_dir.string(),
                          "--cache-memory-bytes", std::to_string(options.cache_memory_bytes),
                          "--cache-disk-bytes", std::to_string(options.cache_disk_bytes)});
  const std::string address = server.WaitUntilListening();
  if (address.empty()) {
    std::cerr << "soak: inscribed did not start:\n" << server.log() << "\n";
    return 2;
  }
  server.DrainLogInBackground();
  client::ClientOptions client_options;
  client_options.default_timeout = std::chrono::minutes(5);
  // One channel per client thread, as separate simulator processes would have.
  std::vector<client::Client> clients;
  for (int c = 0; c < options.clients; ++c) {
    clients.emplace_back(client::MakeGrpcConnection(address), client_options);
  }

  // Warm-up: every mesh stored and its reference set generated once.
  std::vector<Model> models;
  for (const std::string& name : options.models) {
    absl::StatusOr<Mesh> read = ReadMesh(options.data_dir + "/" + name + ".off");
    absl::StatusOr<ValidatedMesh> prepared =
        read.ok() ? PrepareMesh(*std::move(read)) : read.status();
    if (!prepared.ok()) {
      std::cerr << "soak: " << name << ": " << prepared.status() << " (scripts/fetch-meshes)\n";
      return 2;
    }
    Model model{name, std::move(prepared->mesh), prepared->report.bbox.extent().maxCoeff(), "", ""};
    absl::StatusOr<client::GenerateResult> base =
        clients[0].Generate(model.mesh, Settings(model, 0));
    if (!base.ok()) {
      std::cerr << "soak: warm-up Generate " << name << ": " << base.status() << "\n";
      return 2;
    }
    model.mesh_sha256 = base->mesh_sha256;
    model.base_key = base->sphere_set_key;
    models.push_back(std::move(model));
  }
  const testing::ProcessMemory start_memory = testing::ReadProcessMemory(server.pid());

  std::cout << absl::StrFormat(
      "# soak: %d clients, %.0f s, %d models, server --jobs %d --cache-memory-bytes %.0f MiB "
      "--cache-disk-bytes %.1f MiB%s\n",
      options.clients, options.seconds, models.size(), options.jobs,
      MiB(options.cache_memory_bytes), MiB(options.cache_disk_bytes),
      options.cache_disk_bytes == 0 ? " (unbounded)" : "");
  const Clock::time_point began = Clock::now();
  const Clock::time_point deadline = began + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double>(options.seconds));
  std::vector<Record> records(options.clients);
  std::vector<std::thread> threads;
  for (int c = 0; c < options.clients; ++c) {
    threads.emplace_back(
        [&, c] { RunClient(options, clients[c], models, deadline, 0x5eed + c, records[c]); });
  }
  // The disk cache each second, and the server's memory once a minute (and the peak), while
  // the clients run; on a channel of its own.
  const client::Client watcher(client::MakeGrpcConnection(address), client_options);
  DiskWatch disk;
  std::atomic<bool> done{false};
  std::thread monitor([&] {
    Clock::time_point next = began + std::chrono::minutes(1);
    Clock::time_point next_disk = began;
    while (!done.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      if (Clock::now() >= next_disk) {
        next_disk += std::chrono::seconds(1);
        disk.Sample(watcher, cache_dir);
      }
      if (Clock::now() >= next) {
        next += std::chrono::minutes(1);
        const testing::ProcessMemory m = testing::ReadProcessMemory(server.pid());
        std::cout << absl::StrFormat(
                         "  %4.0f s: server RSS %.1f MiB (peak %.1f MiB), disk cache %.2f MiB "
                         "(most seen %.2f MiB)\n",
                         std::chrono::duration<double>(Clock::now() - began).count(),
                         MiB(m.resident), MiB(m.peak_resident),
                         MiB(MeasureDirectory(cache_dir).entries), MiB(disk.max_entries))
                  << std::flush;
      }
    }
  });
  for (std::thread& thread : threads) thread.join();
  done = true;
  monitor.join();
  disk.Sample(watcher, cache_dir);
  const double elapsed = std::chrono::duration<double>(Clock::now() - began).count();
  const testing::ProcessMemory end_memory = testing::ReadProcessMemory(server.pid());

  std::cout << "\n| RPC | calls | errors | calls/s | p50 ms | p99 ms | max ms |\n"
            << "|---|---:|---:|---:|---:|---:|---:|\n";
  std::int64_t calls = 0, errors = 0;
  for (int rpc = 0; rpc < kRpcCount; ++rpc) {
    std::vector<double> all;
    std::int64_t rpc_errors = 0;
    for (Record& r : records) {
      all.insert(all.end(), r.seconds[rpc].begin(), r.seconds[rpc].end());
      rpc_errors += r.errors[rpc];
    }
    const double max = all.empty() ? 0.0 : *std::max_element(all.begin(), all.end());
    std::cout << absl::StrFormat("| %s | %d | %d | %.1f | %.1f | %.1f | %.1f |\n", kRpcNames[rpc],
                                 all.size(), rpc_errors, all.size() / elapsed,
                                 1e3 * Quantile(all, 0.5), 1e3 * Quantile(all, 0.99), 1e3 * max);
    calls += static_cast<std::int64_t>(all.size());
    errors += rpc_errors;
  }
  absl::StatusOr<client::ServerCacheStats> stats = clients[0].CacheStats();
  bool disk_ok = disk.stats_errors == 0;
  if (stats.ok()) {
    std::cout << absl::StrFormat(
        "\ncache: %d entries, %.1f MiB in memory; %d computations, %d evictions, %d memory hits, "
        "%d disk hits, %d disk entries\n",
        stats->entries, MiB(stats->bytes), stats->computations, stats->evictions,
        stats->memory_hits, stats->disk_hits, stats->disk_entries);
    const DirectoryBytes end_bytes = MeasureDirectory(cache_dir);
    std::cout << absl::StrFormat(
        "disk cache: bound %s; end %d bytes (%.2f MiB, %d entries; directory %d bytes), most "
        "seen %d bytes counted, %d in entry files, %d with temporary files; %d evictions "
        "(%.2f MiB), %d too large; disk errors %d corrupt, %d write, %d skipped; %d failed "
        "samples\n",
        options.cache_disk_bytes == 0 ? std::string("none")
                                      : absl::StrFormat("%d bytes", options.cache_disk_bytes),
        stats->disk_bytes, MiB(stats->disk_bytes), stats->disk_entries, end_bytes.entries,
        disk.max_counted, disk.max_entries, disk.max_total, stats->disk_evictions,
        MiB(stats->disk_evicted_bytes), stats->disk_writes_too_large, stats->disk_errors,
        stats->disk_write_errors, stats->disk_writes_skipped, disk.stats_errors);
    disk_ok = disk_ok && stats->disk_errors + stats->disk_write_errors == 0 &&
              stats->disk_bytes == end_bytes.entries;
    // The server's count is exact (kept under its lock); a walk of the directory is not a
    // snapshot (it may see a new file and the old one its write evicted), so it is reported,
    // not checked, while the server runs.
    if (options.cache_disk_bytes > 0) {
      disk_ok = disk_ok && disk.max_counted <= options.cache_disk_bytes;
    }
  } else {
    ++errors;
    std::cerr << "soak: CacheStats: " << stats.status() << "\n";
  }
  const std::int64_t growth = end_memory.resident - start_memory.resident;
  const std::int64_t allowed = options.cache_memory_bytes + options.rss_allowance_bytes;
  std::cout << absl::StrFormat(
      "server RSS: start %.1f MiB, end %.1f MiB, growth %+.1f MiB (allowed %.1f: cache budget "
      "%.1f + %.1f), peak %.1f MiB\n",
      MiB(start_memory.resident), MiB(end_memory.resident), MiB(growth), MiB(allowed),
      MiB(options.cache_memory_bytes), MiB(options.rss_allowance_bytes),
      MiB(end_memory.peak_resident));
  std::cout << absl::StrFormat("total: %d calls in %.0f s, %d errors\n", calls, elapsed, errors);

  const int stopped = server.StopWith(SIGTERM, std::chrono::seconds(30));
  std::filesystem::remove_all(cache_dir);
  if (stopped != 0) {
    std::cerr << "soak: inscribed did not exit cleanly on SIGTERM (wait status " << stopped
              << ")\n";
    return 1;
  }
  if (errors > 0) return 1;
  if (!disk_ok) {
    std::cerr << "soak: the disk cache went over its bound, miscounted or had errors\n";
    return 1;
  }
  if (growth > allowed) {
    std::cerr << "soak: server memory grew by more than the cache budget\n";
    return 1;
  }
  return 0;
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  inscribe::Options options;
  CLI::App app{"soak: concurrent clients mixing RPCs against one inscribed on loopback"};
  app.add_option("--seconds", options.seconds, "how long the clients run")->capture_default_str();
  app.add_option("--clients", options.clients, "concurrent clients (threads, one channel each)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--jobs", options.jobs, "the server's --jobs")->capture_default_str();
  app.add_option("--cache-memory-bytes", options.cache_memory_bytes,
                 "the server's --cache-memory-bytes")
      ->capture_default_str();
  app.add_option("--cache-disk-bytes", options.cache_disk_bytes,
                 "the server's --cache-disk-bytes (0 = unbounded); the disk cache must stay "
                 "within it")
      ->capture_default_str();
  app.add_option("--rss-allowance-bytes", options.rss_allowance_bytes,
                 "resident-memory growth allowed on top of the cache budget")
      ->capture_default_str();
  app.add_option("--models", options.models, "demo meshes (data/NAME.off)")->delimiter(',');
  app.add_option("--inscribed", options.inscribed, "the server binary")->capture_default_str();
  app.add_option("--data-dir", options.data_dir, "where the meshes are")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  return inscribe::Run(options);
}
