// The service over loopback: what a simulator pays for calling inscribed instead of
// linking the core.
//   1. Distance RPC with batches of 1, 100 and 10,000 pose pairs against the same queries
//      in-process (SeparationDistances on the same hierarchies): throughput ratio.
//   2. DistanceStream round trip per frame (10 object pairs), p50 / p99 / max, with 1, 4 and
//      16 clients each on its own channel and session: closed loop (each client sends its next
//      frame the moment the reply arrives; 10,000 frames shared by the clients) and paced
//      (each client sends at a fixed --frame-rates rate for --paced-seconds, as a simulator
//      does; the round trip counts from the frame's scheduled time, so a client that fell
//      behind is charged for it). With the process's CPU time and context switches per frame.
//   3. What a frame's round trip is made of: the frame's compute in-process, a TCP round trip
//      on loopback, and an empty frame's round trip (gRPC and the client library's cost).
//   4. Generate answered from the cache (memory hit): p50 / p99 with 1, 4 and 16 clients.
// Every answer is checked (distances against the in-process ones, cache hits as hits); any
// mismatch or failed call counts as an error and makes the exit status 1.
//
//   service_bench [--server HOST:PORT] [--frames N] [--frame-rates 100,1000]
//                 [--sections batch,stream,floor,generate] [--quick] ...   (bench/run-service)
#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "inscribe/client/client.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/solid/mesh_validation.h"
#include "machine_probes.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string server;  // empty: an in-process server on a free loopback port
  std::string data_dir = INSCRIBE_SOURCE_DIR "/data";
  std::vector<std::string> models = {"eight", "knot1"};
  std::int64_t max_spheres = 1000;
  std::vector<int> batches = {1, 100, 10'000};
  std::int64_t batch_queries = 100'000;  // queries per batch size (calls = this / size)
  int frames = 10'000;                   // per client count, shared among the clients
  int pairs = 10;                        // object pairs per frame
  std::vector<int> clients = {1, 4, 16};
  std::vector<double> frame_rates = {100, 1000};  // paced rows, frames/s per client
  double paced_seconds = 5.0;                     // length of each paced row
  std::vector<std::string> sections = {"batch", "stream", "floor", "generate"};
  int generate_calls = 2'000;  // per client count
  int jobs = 0;                // in-process server's pool; 0 = one per core
  bool quick = false;          // smoke: small counts, same checks
};

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// p in [0, 1] of unsorted samples (nearest rank).
double Percentile(std::vector<double> samples, double p) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(samples.size())));
  return samples[std::min(samples.size() - 1, rank == 0 ? 0 : rank - 1)];
}

RigidPose RandomPose(std::mt19937_64& rng, double distance) {
  std::normal_distribution<double> normal;
  RigidPose pose;
  pose.rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng));
  pose.rotation.normalize();
  pose.translation = Vector3(normal(rng), normal(rng), normal(rng)).normalized() * distance;
  return pose;
}

// Table II's 'near' and 'far' centre distances mixed: 0.4-1.5 bounding-box diagonals.
std::vector<RigidPose> PoseSet(int count, double diagonal, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> fraction(0.4, 1.5);
  std::vector<RigidPose> poses;
  for (int i = 0; i < count; ++i) poses.push_back(RandomPose(rng, fraction(rng) * diagonal));
  return poses;
}

struct Model {
  std::string name;
  std::string key;       // the dilated set's cache key
  std::string mesh_key;  // the mesh's, as stored
  std::shared_ptr<const SphereHierarchy> hierarchy;
  double diagonal = 0.0;
  client::GenerateSettings settings;
};

std::atomic<std::int64_t> g_errors{0};

void Error(const std::string& what) {
  ++g_errors;
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  std::cerr << "service_bench: error: " << what << "\n";
}

bool SameDistance(const DistanceResult& got, const DistanceResult& want) {
  return std::abs(got.distance - want.distance) <= 1e-12 * std::max(1.0, std::abs(want.distance));
}

absl::StatusOr<Model> LoadModel(const client::Client& client, const Options& options,
                                const std::string& name) {
  absl::StatusOr<Mesh> read = ReadMesh(options.data_dir + "/" + name + ".off");
  if (!read.ok()) return read.status();
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(read));
  if (!prepared.ok()) return prepared.status();
  Model model;
  model.name = name;
  model.diagonal = prepared->report.bbox.diagonal();
  model.settings.parameters.max_spheres = options.max_spheres;
  model.settings.parameters.kind = inscribe::SphereSetKind::kDilated;
  model.settings.parameters.evaluate = false;
  client::GenerateOptions call;
  call.timeout = std::chrono::minutes(10);
  absl::StatusOr<client::GenerateResult> generated =
      client.Generate(prepared->mesh, model.settings, call);
  if (!generated.ok()) return generated.status();
  model.key = generated->sphere_set_key;
  model.mesh_key = generated->mesh_sha256;
  // The server's own hierarchy: the in-process runs query exactly the same tree.
  absl::StatusOr<SphereHierarchy> h = client.GetHierarchy(model.key, HierarchyVolume::kSphere);
  if (!h.ok()) return h.status();
  model.hierarchy = std::make_shared<const SphereHierarchy>(*std::move(h));
  return model;
}

// Section 1: one batch size; RPC and in-process throughput over the same poses.
void BatchRow(const client::Client& client, const Model& a, const Model& b, int size,
              std::int64_t total) {
  const int calls = static_cast<int>(std::max<std::int64_t>(3, total / size));
  const std::vector<RigidPose> poses = PoseSet(size, std::max(a.diagonal, b.diagonal), 17 + size);
  const std::vector<RigidPose> identity(1);

  absl::StatusOr<std::vector<DistanceResult>> local;
  std::vector<double> local_times;
  for (int i = 0; i < calls; ++i) {
    const Clock::time_point start = Clock::now();
    local = SeparationDistances(*a.hierarchy, *b.hierarchy, poses);
    local_times.push_back(Seconds(Clock::now() - start));
    if (!local.ok()) return Error(std::string(local.status().message()));
  }
  std::vector<double> rpc_times;
  double server_seconds = 0.0;
  for (int i = 0; i < calls; ++i) {
    const Clock::time_point start = Clock::now();
    absl::StatusOr<client::DistanceBatchResult> remote =
        client.Distance(a.key, b.key, identity, poses);
    rpc_times.push_back(Seconds(Clock::now() - start));
    if (!remote.ok()) return Error(std::string(remote.status().message()));
    server_seconds += remote->server_seconds;
    for (int q = 0; q < size; ++q) {
      if (!SameDistance(remote->results[q], (*local)[q])) {
        return Error(absl::StrFormat("Distance batch %d query %d: %.17g remote, %.17g local", size,
                                     q, remote->results[q].distance, (*local)[q].distance));
      }
    }
  }
  const double local_median = Percentile(local_times, 0.5);
  const double rpc_median = Percentile(rpc_times, 0.5);
  const double local_rate = size / local_median, rpc_rate = size / rpc_median;
  std::cout << absl::StrFormat(
      "| %d | %d | %.1f | %.1f | %.0f | %.0f | %.2f |%s\n", size, calls, 1e6 * rpc_median,
      1e6 * local_median, rpc_rate, local_rate, rpc_rate / local_rate,
      size == 10'000 ? (rpc_rate >= 0.5 * local_rate ? " pass" : " MISS") : "");
  (void)server_seconds;
}

// One frame's pairs for frame number f: models alternate so that every frame names both.
std::vector<client::PosePair> Frame(const std::vector<const Model*>& models,
                                    const std::vector<RigidPose>& pool, int pairs, int f) {
  std::vector<client::PosePair> frame;
  for (int p = 0; p < pairs; ++p) {
    const Model& a = *models[p % models.size()];
    const Model& b = *models[(p / models.size() + f) % models.size()];
    const std::size_t i = (static_cast<std::size_t>(f) * pairs + p) % (pool.size() / 2);
    frame.push_back({a.key, b.key, pool[2 * i], pool[2 * i + 1]});
  }
  return frame;
}

// Runs `per_client(client_index)` on `count` threads, each with its own Client and channel.
void OnClients(const std::string& address, int count,
               const std::function<void(const client::Client&, int)>& per_client) {
  std::vector<std::thread> threads;
  for (int c = 0; c < count; ++c) {
    threads.emplace_back([&, c] {
      const client::Client client(client::MakeGrpcConnection(address));
      per_client(client, c);
    });
  }
  for (std::thread& t : threads) t.join();
}

// The process's CPU time (all threads: the clients and, in-process, the server) and context
// switches, for per-frame costs.
struct ProcessUsage {
  double cpu_seconds = 0.0;
  std::int64_t switches = 0;

  static ProcessUsage Now() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const auto seconds = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
    return {seconds(usage.ru_utime) + seconds(usage.ru_stime),
            static_cast<std::int64_t>(usage.ru_nvcsw + usage.ru_nivcsw)};
  }
};

// Checks a frame's answers against the core, pair by pair.
void CheckFrame(const std::vector<const Model*>& models, const std::vector<client::PosePair>& frame,
                const std::vector<DistanceResult>& results, int f) {
  const auto model = [&](const std::string& key) {
    return *std::find_if(models.begin(), models.end(),
                         [&](const Model* m) { return m->key == key; });
  };
  for (std::size_t p = 0; p < frame.size(); ++p) {
    absl::StatusOr<DistanceResult> want =
        SeparationDistance(*model(frame[p].sphere_set_a)->hierarchy, frame[p].pose_a,
                           *model(frame[p].sphere_set_b)->hierarchy, frame[p].pose_b);
    if (!want.ok() || !SameDistance(results[p], *want)) {
      Error(absl::StrFormat("stream frame %d pair %d differs from the core", f, p));
    }
  }
}

// One row of the stream table: `clients` sessions, closed loop (`rate` 0) or each paced at
// `rate` frames/s (phases spread evenly over one period). Round trips of frames after each
// client's 50 warm-up frames.
void StreamRow(const std::string& address, const std::vector<const Model*>& models,
               const Options& options, int clients, double rate, int pairs) {
  const double diagonal = std::max(models[0]->diagonal, models.back()->diagonal);
  const std::vector<RigidPose> pool = PoseSet(2 * 4096, diagonal, 99);
  const int frames_each = rate > 0 ? std::max(1, static_cast<int>(rate * options.paced_seconds))
                                   : std::max(1, options.frames / clients);
  constexpr int kWarmUp = 50;
  std::mutex mutex;
  std::vector<double> round_trips;
  std::atomic<int> warm{0};
  ProcessUsage before;
  Clock::time_point start;
  OnClients(address, clients, [&](const client::Client& client, int c) {
    absl::StatusOr<client::DistanceSession> session = client.OpenDistanceSession();
    if (!session.ok()) return Error(std::string(session.status().message()));
    std::vector<double> mine;
    mine.reserve(static_cast<std::size_t>(frames_each));
    const auto query = [&](int f) -> absl::StatusOr<std::vector<DistanceResult>> {
      const std::vector<client::PosePair> frame =
          Frame(models, pool, pairs, f + c * (frames_each + kWarmUp));
      absl::StatusOr<std::vector<DistanceResult>> results = session->Query(frame);
      if (results.ok() && f % 97 == 0) CheckFrame(models, frame, *results, f);
      return results;
    };
    for (int f = 0; f < kWarmUp; ++f) {
      if (absl::Status s = query(f).status(); !s.ok()) return Error(std::string(s.message()));
    }
    // Every client starts measuring together, once all are warm.
    {
      std::unique_lock<std::mutex> lock(mutex);
      if (++warm == clients) {
        before = ProcessUsage::Now();
        start = Clock::now();
      }
    }
    while (warm.load() < clients) std::this_thread::sleep_for(std::chrono::microseconds(200));
    const Clock::duration period =
        rate > 0
            ? std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1 / rate))
            : Clock::duration::zero();
    const Clock::time_point first = Clock::now() + period * c / clients;
    for (int f = 0; f < frames_each; ++f) {
      Clock::time_point sent = first + period * f;
      if (rate > 0) {
        std::this_thread::sleep_until(sent);
      } else {
        sent = Clock::now();
      }
      absl::StatusOr<std::vector<DistanceResult>> results = query(kWarmUp + f);
      mine.push_back(Seconds(Clock::now() - sent));
      if (!results.ok()) return Error(std::string(results.status().message()));
    }
    if (absl::Status closed = session->Close(); !closed.ok()) {
      Error(std::string(closed.message()));
    }
    std::lock_guard<std::mutex> lock(mutex);
    round_trips.insert(round_trips.end(), mine.begin(), mine.end());
  });
  const double wall = Seconds(Clock::now() - start);
  const ProcessUsage after = ProcessUsage::Now();
  const double frames = static_cast<double>(round_trips.size());
  const double p99 = Percentile(round_trips, 0.99);
  std::cout << absl::StrFormat(
      "| %d | %s | %d | %d | %.0f | %.0f | %.0f | %.0f | %.0f | %.1f |%s\n", clients,
      rate > 0 ? absl::StrFormat("paced %.0f Hz", rate) : std::string("closed loop"),
      static_cast<int>(round_trips.size()), pairs, 1e6 * Percentile(round_trips, 0.5), 1e6 * p99,
      1e6 * Percentile(round_trips, 1.0), frames / wall,
      1e6 * (after.cpu_seconds - before.cpu_seconds) / frames,
      static_cast<double>(after.switches - before.switches) / frames,
      p99 < 1e-3 ? " pass" : " MISS");
}

// What one client's frame round trip is made of (medians): the frame's queries in-process on
// the same hierarchies, a bare TCP round trip on loopback, and the round trip of an empty frame
// (gRPC's per-message cost both ways and the client library's). Each is measured back to back
// and again after a pause of a paced client's period (10 ms), which on a shared machine finds
// the caches cold; a pointer chase through 256 KB shows how cold.
void FloorRows(const std::string& address, const std::vector<const Model*>& models,
               const Options& options) {
  const double diagonal = std::max(models[0]->diagonal, models.back()->diagonal);
  const std::vector<RigidPose> pool = PoseSet(2 * 4096, diagonal, 99);
  constexpr int kPausedFrames = 200;
  constexpr auto kPause = std::chrono::milliseconds(10);
  std::vector<double> compute;
  std::vector<double> compute_paused;
  for (int f = 0; f < 2000 + kPausedFrames; ++f) {
    const std::vector<client::PosePair> frame = Frame(models, pool, options.pairs, f);
    std::vector<PosedPair> pairs;
    for (const client::PosePair& p : frame) {
      const auto model = [&](const std::string& key) {
        return *std::find_if(models.begin(), models.end(),
                             [&](const Model* m) { return m->key == key; });
      };
      pairs.push_back({model(p.sphere_set_a)->hierarchy.get(),
                       model(p.sphere_set_b)->hierarchy.get(), p.pose_a, p.pose_b});
    }
    const bool paused = f >= 2000;
    if (paused) std::this_thread::sleep_for(kPause);
    const Clock::time_point start = Clock::now();
    absl::StatusOr<std::vector<DistanceResult>> results = PairSeparationDistances(pairs);
    (paused ? compute_paused : compute).push_back(Seconds(Clock::now() - start));
    if (!results.ok()) return Error(std::string(results.status().message()));
  }
  std::cout << absl::StrFormat("| frame of %d pairs computed in-process | %.1f |\n", options.pairs,
                               1e6 * Percentile(compute, 0.5));
  std::cout << absl::StrFormat("| the same, each after a 10 ms pause | %.1f |\n",
                               1e6 * Percentile(compute_paused, 0.5));
  std::cout << absl::StrFormat(
      "| 20,000 dependent loads within 256 KB | %.1f |\n",
      1e6 * Percentile(bench::PointerChases(200, Clock::duration::zero()), 0.5));
  std::cout << absl::StrFormat("| the same, each after a 10 ms pause | %.1f |\n",
                               1e6 * Percentile(bench::PointerChases(200, kPause), 0.5));
  std::cout << absl::StrFormat(
      "| TCP round trip on loopback (1 byte each way) | %.1f |\n",
      1e6 * Percentile(bench::LoopbackRoundTrips(5000, Clock::duration::zero()), 0.5));
  std::cout << absl::StrFormat(
      "| the same, each after a 10 ms pause | %.1f |\n",
      1e6 * Percentile(bench::LoopbackRoundTrips(kPausedFrames, kPause), 0.5));
  const client::Client client(client::MakeGrpcConnection(address));
  absl::StatusOr<client::DistanceSession> session = client.OpenDistanceSession();
  if (!session.ok()) return Error(std::string(session.status().message()));
  std::vector<double> empty;
  std::vector<double> empty_paused;
  for (int f = 0; f < 5050 + kPausedFrames; ++f) {
    const bool paused = f >= 5050;
    if (paused) std::this_thread::sleep_for(kPause);
    const Clock::time_point start = Clock::now();
    absl::StatusOr<std::vector<DistanceResult>> results = session->Query({});
    if (f >= 50) (paused ? empty_paused : empty).push_back(Seconds(Clock::now() - start));
    if (!results.ok()) return Error(std::string(results.status().message()));
  }
  std::cout << absl::StrFormat("| DistanceStream round trip of an empty frame | %.1f |\n",
                               1e6 * Percentile(empty, 0.5));
  std::cout << absl::StrFormat("| the same, each after a 10 ms pause | %.1f |\n",
                               1e6 * Percentile(empty_paused, 0.5));
  if (absl::Status closed = session->Close(); !closed.ok()) Error(std::string(closed.message()));
}

void GenerateRow(const std::string& address, const Model& model, const Options& options,
                 int clients) {
  const int calls_each = std::max(1, options.generate_calls / clients);
  std::mutex mutex;
  std::vector<double> latencies;
  OnClients(address, clients, [&](const client::Client& client, int) {
    std::vector<double> mine;
    for (int i = 0; i < calls_each + 10; ++i) {
      const Clock::time_point start = Clock::now();
      // By key (the mesh is stored): what a simulator that already uploaded it sends.
      absl::StatusOr<client::GenerateResult> r = client.Generate(model.mesh_key, model.settings);
      const double seconds = Seconds(Clock::now() - start);
      if (!r.ok()) return Error(std::string(r.status().message()));
      if (r->cache != "memory") Error("cache-hit Generate came from " + r->cache);
      if (i >= 10) mine.push_back(seconds);
    }
    std::lock_guard<std::mutex> lock(mutex);
    latencies.insert(latencies.end(), mine.begin(), mine.end());
  });
  const double p50 = Percentile(latencies, 0.5);
  std::cout << absl::StrFormat("| %d | %d | %.0f | %.0f | %.0f |%s\n", clients,
                               static_cast<int>(latencies.size()), 1e6 * p50,
                               1e6 * Percentile(latencies, 0.99), 1e6 * Percentile(latencies, 1.0),
                               p50 < 2e-3 ? " pass" : " MISS");
}

int Run(const Options& options) {
  std::unique_ptr<server::InscribeServer> local;
  std::string address = options.server;
  if (address.empty()) {
    server::ServerOptions server_options;
    server_options.listen = "127.0.0.1:0";
    server_options.jobs = options.jobs;
    server_options.max_queue = 1024;
    absl::StatusOr<std::unique_ptr<server::InscribeServer>> started =
        server::InscribeServer::Start(server_options);
    if (!started.ok()) {
      std::cerr << "service_bench: " << started.status().message() << "\n";
      return 2;
    }
    local = *std::move(started);
    address = local->address();
  }
  const client::Client client(client::MakeGrpcConnection(address));
  std::vector<Model> models;
  for (const std::string& name : options.models) {
    absl::StatusOr<Model> model = LoadModel(client, options, name);
    if (!model.ok()) {
      std::cerr << "service_bench: " << name << ": " << model.status().message() << "\n";
      return 2;
    }
    models.push_back(*std::move(model));
  }
  std::vector<const Model*> pointers;
  for (const Model& m : models) pointers.push_back(&m);

  std::cout << absl::StrFormat(
      "# inscribed on %s (%s), %d hardware threads; models %s, %d spheres each (dilated, "
      "sphere hierarchy)\n\n",
      address, local ? absl::StrFormat("in-process, %d jobs", local->jobs()) : "remote",
      std::thread::hardware_concurrency(), absl::StrJoin(options.models, ", "),
      static_cast<int>(models[0].hierarchy->spheres().size()));

  const auto section = [&](const char* name) {
    return std::find(options.sections.begin(), options.sections.end(), name) !=
           options.sections.end();
  };
  if (section("batch")) {
    std::cout << "## Distance RPC vs in-process (" << models[0].name << " vs " << models.back().name
              << ", median per call; target: batch 10,000 at >= 50% of in-process)\n\n"
              << "| batch | calls | RPC us | in-process us | RPC queries/s | in-process queries/s "
                 "| ratio |\n|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const int size : options.batches) {
      BatchRow(client, models[0], models.back(), size, options.batch_queries);
    }
    std::cout << "\n";
  }

  if (section("stream")) {
    std::cout << "## DistanceStream round trip per frame (target: p99 < 1 ms)\n\n"
              << "CPU and context switches are the whole process's per frame"
              << (local ? " (clients and server)" : " (the clients only)") << ".\n\n"
              << "| clients | mode | frames | pairs/frame | p50 us | p99 us | max us | frames/s "
                 "| CPU us/frame | switches/frame |\n"
                 "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const int clients : options.clients) {
      StreamRow(address, pointers, options, clients, 0.0, options.pairs);
    }
    for (const double rate : options.frame_rates) {
      for (const int clients : options.clients) {
        StreamRow(address, pointers, options, clients, rate, options.pairs);
      }
    }
    std::cout << "\n";
  }

  if (section("floor")) {
    std::cout << "## What one frame's round trip is made of (1 client, medians)\n\n"
              << "| part | us |\n|---|---:|\n";
    FloorRows(address, pointers, options);
    std::cout << "\n";
  }

  if (section("generate")) {
    std::cout << "## Generate answered from the cache (target: p50 < 2 ms)\n\n"
              << "| clients | calls | p50 us | p99 us | max us |\n|---:|---:|---:|---:|---:|\n";
    for (const int clients : options.clients) GenerateRow(address, models[0], options, clients);
  }

  absl::StatusOr<client::ServerCacheStats> stats = client.CacheStats();
  if (stats.ok()) {
    std::cout << absl::StrFormat(
        "\nCache: %d entries, %d bytes, %d hits, %d misses, %d computations\n", stats->entries,
        stats->bytes, stats->hits, stats->misses, stats->computations);
  }
  std::cout << "\nErrors: " << g_errors.load() << "\n";
  return g_errors.load() == 0 ? 0 : 1;
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  inscribe::Options options;
  if (const char* env = std::getenv("INSCRIBE_DATA_DIR")) options.data_dir = env;
  CLI::App app{
      "The inscribe service over loopback: Distance batches, DistanceStream frames "
      "and cache-hit Generate, against the core in-process"};
  app.add_option("--server", options.server,
                 "HOST:PORT of a running inscribed (default: start one in-process)");
  app.add_option("--data-dir", options.data_dir, "Directory of the demo meshes (.off)");
  app.add_option("--models", options.models, "Two models (demo mesh names)")->delimiter(',');
  app.add_option("--max-spheres", options.max_spheres, "Sphere budget per model");
  app.add_option("--batches", options.batches, "Distance batch sizes")->delimiter(',');
  app.add_option("--batch-queries", options.batch_queries,
                 "Queries per batch size (calls = this / size, at least 3)");
  app.add_option("--frames", options.frames, "Stream frames per client count");
  app.add_option("--pairs", options.pairs, "Object pairs per frame");
  app.add_option("--clients", options.clients, "Concurrent client counts")->delimiter(',');
  app.add_option("--frame-rates", options.frame_rates,
                 "Paced stream rows: frames/s each client sends (closed loop is always run)")
      ->delimiter(',');
  app.add_option("--paced-seconds", options.paced_seconds, "Length of each paced stream row");
  app.add_option("--sections", options.sections, "What to run, of batch, stream, floor, generate")
      ->delimiter(',');
  app.add_option("--generate-calls", options.generate_calls, "Cache-hit Generates per count");
  app.add_option("--jobs", options.jobs, "In-process server's job pool (0 = one per core)");
  app.add_flag("--quick", options.quick, "Smoke run: small counts, the same checks");
  CLI11_PARSE(app, argc, argv);
  if (options.quick) {
    options.max_spheres = 200;
    options.batch_queries = 2'000;
    options.frames = 200;
    options.paced_seconds = 0.2;
    options.generate_calls = 40;
    options.clients = {1, 4};
  }
  return inscribe::Run(options);
}
