// Scale-out on loopback: inscribed replicas as separate processes, the client library
// routing over them.
//   1. Generate throughput with 1 vs 3 replicas: distinct requests (every one computes), from
//      several client threads, routed by mesh hash.
//   2. Distance throughput with 1 vs 3 replicas: batches of pose pairs on cached sets.
//   3. Cache hit rate over 3 replicas: hash routing (rendezvous) vs round-robin, without a
//      shared tier and with Redis, on a workload that repeats each (mesh, parameters) request.
// All replicas share this machine's cores, so 3 replicas cannot add CPU here: the throughput
// ratio shows the cost of the split (processes, routing), not a cluster's gain. Per-replica
// figures show how the routing spreads the work. Every failed call counts as an error; any
// error makes the exit status 1.
//
//   scale_bench [--quick] [--clients N] [--inscribed PATH] ...   (bench/run-scale)
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "inscribe/client/client.h"
#include "inscribe/client/routing.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/wire/keys.h"
#include "support/inscribed_process.h"
#include "support/redis_process.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string inscribed = INSCRIBED;
  std::string data_dir = INSCRIBE_SOURCE_DIR "/data";
  std::vector<std::string> models = {"eight", "knot1", "cow", "fandisk", "elephant", "bunny00"};
  int clients = 4;
  int jobs = 2;                // each replica's --jobs
  int generate_requests = 36;  // distinct requests per configuration
  double distance_seconds = 5.0;
  int batch = 1000;  // pose pairs per Distance call
  int rounds = 4;    // repeats of every request in the hit-rate workload
  bool quick = false;
};

std::atomic<int> errors{0};

void Fail(const std::string& what, const absl::Status& status) {
  ++errors;
  std::cerr << "scale_bench: " << what << ": " << status << "\n";
}

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Replicas (and optionally Redis) started for one configuration, stopped at its end.
class Cluster {
 public:
  Cluster(const Options& options, int replicas, bool with_redis) {
    if (with_redis) redis_ = std::make_unique<testing::RedisProcess>();
    for (int i = 0; i < replicas; ++i) {
      std::vector<std::string> args = {
          "--listen", "127.0.0.1:0", "--jobs", std::to_string(options.jobs), "--log-level", "warn"};
      if (redis_) {
        args.push_back("--redis");
        args.push_back(redis_->url());
      }
      auto process = std::make_unique<testing::InscribedProcess>(options.inscribed, args);
      const std::string address = process->WaitUntilListening();
      if (address.empty()) {
        std::cerr << "scale_bench: inscribed did not start:\n" << process->log() << "\n";
        std::exit(2);
      }
      process->DrainLogInBackground();
      addresses_.push_back(address);
      processes_.push_back(std::move(process));
    }
  }

  const std::vector<std::string>& addresses() const { return addresses_; }

  client::Client Routed(client::RoutingPolicy policy) const {
    std::vector<client::Endpoint> endpoints;
    for (const std::string& address : addresses_) {
      endpoints.push_back({address, client::MakeGrpcConnection(address)});
    }
    client::RoutingOptions routing;
    routing.policy = policy;
    absl::StatusOr<std::shared_ptr<client::Connection>> routed =
        client::MakeRoutedConnection(std::move(endpoints), routing);
    if (!routed.ok()) {
      std::cerr << "scale_bench: " << routed.status() << "\n";
      std::exit(2);
    }
    client::ClientOptions options;
    options.default_timeout = std::chrono::minutes(10);
    return client::Client(*std::move(routed), options);
  }

  std::vector<client::ServerCacheStats> Stats() const {
    std::vector<client::ServerCacheStats> all;
    for (const std::string& address : addresses_) {
      absl::StatusOr<client::ServerCacheStats> s =
          client::Client(client::MakeGrpcConnection(address)).CacheStats();
      if (!s.ok()) Fail("CacheStats " + address, s.status());
      all.push_back(s.ok() ? *s : client::ServerCacheStats{});
    }
    return all;
  }

 private:
  std::unique_ptr<testing::RedisProcess> redis_;
  std::vector<std::unique_ptr<testing::InscribedProcess>> processes_;
  std::vector<std::string> addresses_;
};

struct Model {
  std::string name;
  Mesh mesh;
  double extent = 0.0;  // largest bounding-box side
};

std::vector<Model> LoadModels(const Options& options) {
  std::vector<Model> models;
  for (const std::string& name : options.models) {
    absl::StatusOr<Mesh> read = ReadMesh(options.data_dir + "/" + name + ".off");
    if (!read.ok()) {
      std::cerr << "scale_bench: " << read.status() << " (run scripts/fetch-meshes)\n";
      std::exit(2);
    }
    absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(read));
    if (!prepared.ok()) {
      std::cerr << "scale_bench: " << name << ": " << prepared.status() << "\n";
      std::exit(2);
    }
    const double extent = prepared->report.bbox.extent().maxCoeff();
    models.push_back({name, std::move(prepared->mesh), extent});
  }
  return models;
}

// Request i of a workload: a model and a coarse voxel size (16-24 voxels along the largest
// side, so one generation takes a fraction of a second).
client::GenerateSettings Settings(const Model& model, int variant) {
  client::GenerateSettings settings;
  settings.parameters.voxel_size = model.extent / (16.0 + variant);
  settings.parameters.evaluate = false;
  return settings;
}

// Runs `work(i)` for i in [0, count) from `clients` threads; the wall time.
template <typename Work>
double RunParallel(int clients, int count, const Work& work) {
  std::atomic<int> next{0};
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> threads;
  for (int c = 0; c < clients; ++c) {
    threads.emplace_back([&] {
      for (int i = next++; i < count; i = next++) work(i);
    });
  }
  for (std::thread& thread : threads) thread.join();
  return Seconds(Clock::now() - start);
}

std::string PerReplica(const std::vector<std::int64_t>& counts) {
  return absl::StrJoin(counts, " / ");
}

void GenerateThroughput(const Options& options, const std::vector<Model>& models) {
  std::cout << "\n### Generate throughput, distinct requests (" << options.generate_requests
            << " per row, " << options.clients << " clients, --jobs " << options.jobs
            << " per replica)\n\n"
            << "| replicas | requests/s | ratio vs 1 | computations per replica |\n"
            << "|---:|---:|---:|---|\n";
  double single = 0.0;
  for (int replicas : {1, 3}) {
    Cluster cluster(options, replicas, /*with_redis=*/false);
    const client::Client client = cluster.Routed(client::RoutingPolicy::kRendezvous);
    const int count = options.generate_requests;
    const double seconds = RunParallel(options.clients, count, [&](int i) {
      const Model& model = models[i % models.size()];
      absl::StatusOr<client::GenerateResult> result =
          client.Generate(model.mesh, Settings(model, i / static_cast<int>(models.size())));
      if (!result.ok()) Fail("Generate " + model.name, result.status());
    });
    std::vector<std::int64_t> computations;
    for (const client::ServerCacheStats& s : cluster.Stats())
      computations.push_back(s.computations);
    const double rate = count / seconds;
    if (replicas == 1) single = rate;
    std::cout << absl::StrFormat("| %d | %.2f | %.2f | %s |\n", replicas, rate, rate / single,
                                 PerReplica(computations));
  }
}

void DistanceThroughput(const Options& options, const std::vector<Model>& models) {
  std::cout << "\n### Distance throughput, batches of " << options.batch << " pose pairs ("
            << options.clients << " clients, " << options.distance_seconds << " s per row)\n\n"
            << "| replicas | queries/s | ratio vs 1 | calls per replica |\n"
            << "|---:|---:|---:|---|\n";
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double single = 0.0;
  for (int replicas : {1, 3}) {
    Cluster cluster(options, replicas, /*with_redis=*/false);
    const client::Client client = cluster.Routed(client::RoutingPolicy::kRendezvous);
    std::vector<std::string> keys;
    std::vector<std::vector<RigidPose>> poses;
    for (const Model& model : models) {
      absl::StatusOr<client::GenerateResult> result =
          client.Generate(model.mesh, Settings(model, 0));
      if (!result.ok()) return Fail("Generate " + model.name, result.status());
      keys.push_back(result->sphere_set_key);
      std::vector<RigidPose> batch(options.batch);
      for (RigidPose& pose : batch) {
        pose.rotation =
            Eigen::Quaterniond(1.0, unit(random), unit(random), unit(random)).normalized();
        pose.translation = 0.7 * model.extent * Vector3(unit(random), unit(random), unit(random));
      }
      poses.push_back(std::move(batch));
    }
    std::vector<std::int64_t> calls(replicas, 0);
    std::vector<std::string> names = cluster.addresses();
    std::atomic<std::int64_t> queries{0};
    const Clock::time_point end =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(options.distance_seconds));
    std::vector<std::atomic<std::int64_t>> per_key(keys.size());
    const double seconds = RunParallel(options.clients, options.clients, [&](int c) {
      for (std::size_t i = c; Clock::now() < end; ++i) {
        const std::size_t k = i % keys.size();
        absl::StatusOr<client::DistanceBatchResult> answer =
            client.Distance(keys[k], keys[k], {RigidPose{}}, poses[k]);
        if (!answer.ok()) return Fail("Distance", answer.status());
        queries += static_cast<std::int64_t>(answer->results.size());
        ++per_key[k];
      }
    });
    // Where each call went: the owner of its set's route key (no replica failed meanwhile).
    for (std::size_t k = 0; k < keys.size(); ++k) {
      calls[client::RendezvousOrder(wire::RouteKey(keys[k]), names).front()] += per_key[k];
    }
    const double rate = static_cast<double>(queries) / seconds;
    if (replicas == 1) single = rate;
    std::cout << absl::StrFormat("| %d | %.0f | %.2f | %s |\n", replicas, rate, rate / single,
                                 PerReplica(calls));
  }
}

void HitRate(const Options& options, const std::vector<Model>& models) {
  std::cout << "\n### Cache hit rate over 3 replicas: each of " << models.size() * 3
            << " (mesh, parameters) requests " << options.rounds << " times\n\n"
            << "| routing | shared tier | lookups | hits (memory / redis) | hit rate | "
               "computations | computations per replica |\n"
            << "|---|---|---:|---:|---:|---:|---|\n";
  struct Row {
    const char* name;
    client::RoutingPolicy policy;
    bool redis;
  };
  for (const Row& row : {Row{"rendezvous", client::RoutingPolicy::kRendezvous, false},
                         Row{"round-robin", client::RoutingPolicy::kRoundRobin, false},
                         Row{"rendezvous", client::RoutingPolicy::kRendezvous, true},
                         Row{"round-robin", client::RoutingPolicy::kRoundRobin, true}}) {
    Cluster cluster(options, 3, row.redis);
    const client::Client client = cluster.Routed(row.policy);
    // Sequential, in rounds: the order is the same for both policies.
    const int distinct = static_cast<int>(models.size()) * 3;
    for (int round = 0; round < options.rounds; ++round) {
      for (int i = 0; i < distinct; ++i) {
        const Model& model = models[i % models.size()];
        absl::StatusOr<client::GenerateResult> result =
            client.Generate(model.mesh, Settings(model, i / static_cast<int>(models.size())));
        if (!result.ok()) Fail("Generate " + model.name, result.status());
      }
    }
    std::int64_t lookups = 0, memory = 0, shared = 0, computed = 0;
    std::vector<std::int64_t> computations;
    for (const client::ServerCacheStats& s : cluster.Stats()) {
      memory += s.memory_hits + s.disk_hits;
      shared += s.shared_hits;
      lookups += s.memory_hits + s.disk_hits + s.shared_hits + s.misses + s.joined;
      computed += s.computations;
      computations.push_back(s.computations);
    }
    std::cout << absl::StrFormat("| %s | %s | %d | %d / %d | %.1f%% | %d | %s |\n", row.name,
                                 row.redis ? "redis" : "none", lookups, memory, shared,
                                 100.0 * (memory + shared) / std::max<std::int64_t>(1, lookups),
                                 computed, PerReplica(computations));
  }
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  inscribe::Options options;
  CLI::App app{"inscribe scale-out on loopback: 1 vs 3 replicas, hash routing vs round-robin"};
  app.add_option("--inscribed", options.inscribed, "inscribed executable")->capture_default_str();
  app.add_option("--data", options.data_dir, "directory of the demo meshes")->capture_default_str();
  app.add_option("--clients", options.clients, "client threads")->capture_default_str();
  app.add_option("--jobs", options.jobs, "--jobs of each replica")->capture_default_str();
  app.add_option("--requests", options.generate_requests, "Generate requests per row")
      ->capture_default_str();
  app.add_option("--seconds", options.distance_seconds, "Distance run per row")
      ->capture_default_str();
  app.add_option("--rounds", options.rounds, "repeats in the hit-rate workload")
      ->capture_default_str();
  app.add_flag("--quick", options.quick, "smoke: two models, a few requests, same checks");
  CLI11_PARSE(app, argc, argv);
  if (options.quick) {
    options.models = {"eight", "knot1"};
    options.generate_requests = 4;
    options.distance_seconds = 0.5;
    options.batch = 100;
    options.rounds = 2;
  }
  const std::vector<inscribe::Model> models = inscribe::LoadModels(options);
  inscribe::GenerateThroughput(options, models);
  inscribe::DistanceThroughput(options, models);
  inscribe::HitRate(options, models);
  std::cout << "\nErrors: " << inscribe::errors << "\n";
  return inscribe::errors == 0 ? 0 : 1;
}
