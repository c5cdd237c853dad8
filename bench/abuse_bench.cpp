// Latency isolation under abuse: one inscribed process, a light client doing small
// Distance calls (10 pose pairs) on a cached sphere set back to back, measured alone for T
// seconds and then again while abusive clients send attacks in loops: broken meshes, a
// billion-voxel Generate, 10^6-pose Distance calls, garbage bytes and oversized messages.
// Prints the light client's p50/p99 in both phases and their ratio, calls and statuses per
// attack kind, and the server's peak RSS (VmHWM) against its --memory-budget. A failed light
// call, or an attack answered with anything but its expected status, is an error; any error
// makes the exit status 1.
//
//   abuse_bench [--quick] [--seconds S] [--abusers N] [--inscribed PATH] ...   (bench/run-abuse)
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <future>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_format.h"
#include "inscribe/client/client.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "inscribe/wire/convert.h"
#include "support/inscribed_process.h"
#include "support/synthetic_meshes.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

struct Options {
  std::string inscribed = INSCRIBED;
  double seconds = 60.0;  // per phase
  int abusers = 3;
  int jobs = 2;
  int light_pairs = 10;  // pose pairs per light Distance call
  std::int64_t memory_budget = std::int64_t{1} << 30;
  std::int64_t max_message_bytes = 64 << 20;
  int big_poses = 1'000'000;
  bool quick = false;
};

std::atomic<int> errors{0};

void Fail(const std::string& what) {
  ++errors;
  std::cerr << "abuse_bench: " << what << "\n";
}

double Seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Peak resident memory of `pid` (VmHWM), bytes.
std::int64_t PeakRss(pid_t pid) { return testing::ReadProcessMemory(pid).peak_resident; }

struct Latencies {
  std::vector<double> us;
  double Percentile(double p) const {
    if (us.empty()) return 0.0;
    std::vector<double> sorted = us;
    std::sort(sorted.begin(), sorted.end());
    return sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(p * sorted.size()))];
  }
};

// The light client: Distance calls of `pairs` pose pairs on `set` until `stop`.
Latencies RunLight(const std::string& address, const std::string& set, int pairs,
                   Clock::time_point stop) {
  client::Client light(client::MakeGrpcConnection(address));
  std::vector<RigidPose> poses_b(pairs);
  for (int i = 0; i < pairs; ++i) poses_b[i].translation = Vector3(3.0 + 0.1 * i, 0.0, 0.0);
  Latencies latencies;
  while (Clock::now() < stop) {
    const Clock::time_point start = Clock::now();
    absl::StatusOr<client::DistanceBatchResult> r =
        light.Distance(set, set, {RigidPose()}, poses_b);
    latencies.us.push_back(1e6 * Seconds(Clock::now() - start));
    if (!r.ok() || r->results.size() != static_cast<std::size_t>(pairs)) {
      Fail("light Distance: " + (r.ok() ? std::string("wrong count") : r.status().ToString()));
    }
  }
  return latencies;
}

// What each attack kind got back, by status code.
struct KindCounts {
  std::map<grpc::StatusCode, int> codes;
  int calls = 0;
};

enum Kind { kInvalidMesh, kBillionVoxels, kMillionPoses, kGarbage, kOversized, kKinds };
const char* const kKindNames[kKinds] = {"invalid mesh (NaN, 20k triangles)",
                                        "billion-voxel Generate", "10^6-pose Distance",
                                        "garbage bytes", "oversized message"};

// The attacks, each built once and sent as often as the abusers manage.
class Attacks {
 public:
  Attacks(const Options& options, const std::string& address, const std::string& cube_key,
          const std::string& set)
      : options_(options) {
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(-1);
    args.SetMaxSendMessageSize(-1);
    channel_ = grpc::CreateCustomChannel(address, grpc::InsecureChannelCredentials(), args);
    stub_ = v1::Inscribe::NewStub(channel_);
    Mesh broken = testing::Icosphere(5);
    broken.vertices(7, 1) = std::numeric_limits<double>::quiet_NaN();
    wire::MeshToProto(broken, invalid_mesh_.mutable_mesh());
    billion_voxels_.set_mesh_sha256(cube_key);
    billion_voxels_.mutable_parameters()->set_voxel_size(1e-3);
    million_poses_.set_sphere_set_a(set);
    million_poses_.set_sphere_set_b(set);
    for (double v : {1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0})
      million_poses_.mutable_poses_a()->add_values(v);
    million_poses_.mutable_poses_b()->mutable_values()->Reserve(7 * options.big_poses);
    for (int i = 0; i < options.big_poses; ++i) {
      for (double v : {1.0, 0.0, 0.0, 0.0, 3.0 + i % 50, 0.0, 0.0}) {
        million_poses_.mutable_poses_b()->add_values(v);
      }
    }
    for (int i = 0; i < 50'000; ++i) garbage_ += '\x0b';  // start-group tags never closed
    oversized_.assign(static_cast<std::size_t>(options.max_message_bytes) + 1024, '\0');
  }

  // One attack of `kind`; its status code, checked against what it must get.
  grpc::StatusCode Send(Kind kind) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(5));
    grpc::Status status;
    std::vector<grpc::StatusCode> expected;
    switch (kind) {
      case kInvalidMesh: {
        v1::PutMeshResponse response;
        status = stub_->PutMesh(&context, invalid_mesh_, &response);
        expected = {grpc::StatusCode::FAILED_PRECONDITION};
        break;
      }
      case kBillionVoxels: {
        auto reader = stub_->Generate(&context, billion_voxels_);
        v1::GenerateResponse message;
        while (reader->Read(&message)) {
        }
        status = reader->Finish();
        expected = {grpc::StatusCode::INVALID_ARGUMENT};
        break;
      }
      case kMillionPoses: {
        v1::DistanceResponse response;
        status = stub_->Distance(&context, million_poses_, &response);
        if (status.ok() && response.results().distances_size() != options_.big_poses) {
          Fail("10^6-pose Distance: wrong count");
        }
        // Computed, or refused by --memory-budget (or --max-queue) when others hold it.
        expected = {grpc::StatusCode::OK, grpc::StatusCode::RESOURCE_EXHAUSTED};
        break;
      }
      case kGarbage:
        status = SendRaw(&context, "/inscribe.v1.Inscribe/PutMesh", garbage_);
        // gRPC 1.51's callback API answers a request it cannot parse with UNIMPLEMENTED.
        expected = {grpc::StatusCode::UNIMPLEMENTED};
        break;
      case kOversized:
        status = SendRaw(&context, "/inscribe.v1.Inscribe/Distance", oversized_);
        expected = {grpc::StatusCode::RESOURCE_EXHAUSTED};
        break;
      case kKinds:
        break;
    }
    if (std::find(expected.begin(), expected.end(), status.error_code()) == expected.end()) {
      Fail(absl::StrFormat("%s: unexpected status %d %s", kKindNames[kind], status.error_code(),
                           status.error_message()));
    }
    return status.error_code();
  }

 private:
  grpc::Status SendRaw(grpc::ClientContext* context, const std::string& method,
                       const std::string& bytes) {
    grpc::GenericStub stub(channel_);
    grpc::Slice slice(bytes);
    grpc::ByteBuffer request(&slice, 1), response;
    std::promise<grpc::Status> done;
    stub.UnaryCall(context, method, grpc::StubOptions(), &request, &response,
                   [&done](grpc::Status status) { done.set_value(std::move(status)); });
    return done.get_future().get();
  }

  const Options& options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Inscribe::Stub> stub_;
  v1::PutMeshRequest invalid_mesh_;
  v1::GenerateRequest billion_voxels_;
  v1::DistanceRequest million_poses_;
  std::string garbage_, oversized_;
};

void PrintLatency(const char* phase, const Latencies& l, double seconds) {
  std::cout << absl::StrFormat("| %s | %d | %.0f | %.0f | %.0f | %.0f |\n", phase, l.us.size(),
                               l.us.size() / seconds, l.Percentile(0.5), l.Percentile(0.99),
                               l.us.empty() ? 0.0 : *std::max_element(l.us.begin(), l.us.end()));
}

int Run(const Options& options) {
  const std::int64_t cache_bytes = 256 << 20;
  testing::InscribedProcess server(
      options.inscribed,
      {"--listen", "127.0.0.1:0", "--jobs", std::to_string(options.jobs), "--memory-budget",
       std::to_string(options.memory_budget), "--cache-memory-bytes", std::to_string(cache_bytes),
       "--max-message-bytes", std::to_string(options.max_message_bytes), "--log-level", "error"});
  const std::string address = server.WaitUntilListening();
  if (address.empty()) {
    std::cerr << "abuse_bench: inscribed did not start:\n" << server.log() << "\n";
    return 2;
  }
  server.DrainLogInBackground();

  // The light client's cached set: spheres of a sphere mesh; and a cube for the Generate attack.
  client::ClientOptions client_options;
  client_options.default_timeout = std::chrono::minutes(5);
  client::Client setup(client::MakeGrpcConnection(address), client_options);
  client::GenerateSettings settings;
  settings.parameters.voxel_size = 0.1;
  settings.parameters.evaluate = false;
  absl::StatusOr<client::GenerateResult> set = setup.Generate(testing::Icosphere(3), settings);
  absl::StatusOr<client::PutMeshResult> cube = setup.PutMesh(testing::UnitCube());
  if (!set.ok() || !cube.ok()) {
    std::cerr << "abuse_bench: setup failed: " << (set.ok() ? cube.status() : set.status()) << "\n";
    return 2;
  }
  const std::int64_t baseline = PeakRss(server.pid());
  std::cout << absl::StrFormat(
      "inscribed --jobs %d --memory-budget %d --cache-memory-bytes %d --max-message-bytes %d; "
      "light client: Distance of %d pairs on %d spheres; %d abusers; %.0f s per phase\n\n",
      options.jobs, options.memory_budget, cache_bytes, options.max_message_bytes,
      options.light_pairs, set->set.size(), options.abusers, options.seconds);

  const Latencies alone =
      RunLight(address, set->sphere_set_key, options.light_pairs,
               Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                  std::chrono::duration<double>(options.seconds)));

  Attacks attacks(options, address, cube->mesh_sha256, set->sphere_set_key);
  std::vector<KindCounts> counts(kKinds);
  std::mutex counts_mutex;
  std::atomic<bool> stop{false};
  std::vector<std::thread> abusers;
  for (int a = 0; a < options.abusers; ++a) {
    abusers.emplace_back([&, a] {
      for (int i = a; !stop.load(); ++i) {
        const Kind kind = static_cast<Kind>(i % kKinds);
        const grpc::StatusCode code = attacks.Send(kind);
        std::lock_guard<std::mutex> lock(counts_mutex);
        ++counts[kind].calls;
        ++counts[kind].codes[code];
      }
    });
  }
  const Latencies abused =
      RunLight(address, set->sphere_set_key, options.light_pairs,
               Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                  std::chrono::duration<double>(options.seconds)));
  stop.store(true);
  for (std::thread& t : abusers) t.join();
  const std::int64_t peak = PeakRss(server.pid());

  std::cout << "| light client | calls | calls/s | p50 us | p99 us | max us |\n"
               "|---|---:|---:|---:|---:|---:|\n";
  PrintLatency("alone", alone, options.seconds);
  PrintLatency("under abuse", abused, options.seconds);
  std::cout << absl::StrFormat("\np50 ratio (abuse / alone): %.2f; p99 ratio: %.2f\n\n",
                               abused.Percentile(0.5) / alone.Percentile(0.5),
                               abused.Percentile(0.99) / alone.Percentile(0.99));
  std::cout << "| attack | calls | statuses |\n|---|---:|---|\n";
  for (int k = 0; k < kKinds; ++k) {
    std::string statuses;
    for (const auto& [code, n] : counts[k].codes) {
      static const std::map<grpc::StatusCode, const char*> names = {
          {grpc::StatusCode::OK, "OK"},
          {grpc::StatusCode::INVALID_ARGUMENT, "INVALID_ARGUMENT"},
          {grpc::StatusCode::FAILED_PRECONDITION, "FAILED_PRECONDITION"},
          {grpc::StatusCode::RESOURCE_EXHAUSTED, "RESOURCE_EXHAUSTED"},
          {grpc::StatusCode::UNIMPLEMENTED, "UNIMPLEMENTED"}};
      const auto name = names.find(code);
      statuses += absl::StrFormat("%s%s %d", statuses.empty() ? "" : ", ",
                                  name != names.end() ? name->second : std::to_string(code), n);
    }
    std::cout << absl::StrFormat("| %s | %d | %s |\n", kKindNames[k], counts[k].calls, statuses);
  }
  std::cout << absl::StrFormat(
      "\nserver peak RSS %.0f MiB (idle after setup %.0f MiB); --memory-budget %.0f MiB + cache "
      "%.0f MiB\n",
      peak / 1048576.0, baseline / 1048576.0, options.memory_budget / 1048576.0,
      cache_bytes / 1048576.0);
  std::cout << "\nErrors: " << errors << "\n";
  return errors == 0 ? 0 : 1;
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  inscribe::Options options;
  CLI::App app{"inscribe latency isolation: a light client's p50/p99 alone and under abuse"};
  app.add_option("--inscribed", options.inscribed, "inscribed executable")->capture_default_str();
  app.add_option("--seconds", options.seconds, "length of each phase")->capture_default_str();
  app.add_option("--abusers", options.abusers, "abusive client threads")->capture_default_str();
  app.add_option("--jobs", options.jobs, "--jobs of the server")->capture_default_str();
  app.add_option("--memory-budget", options.memory_budget, "--memory-budget of the server")
      ->capture_default_str();
  app.add_option("--max-message-bytes", options.max_message_bytes,
                 "--max-message-bytes of the server")
      ->capture_default_str();
  app.add_flag("--quick", options.quick, "smoke: 4 s per phase, 2 abusers, 200,000-pose calls");
  CLI11_PARSE(app, argc, argv);
  if (options.quick) {
    options.seconds = 4.0;
    options.abusers = 2;
    options.big_poses = 200'000;
    options.max_message_bytes = 16 << 20;
  }
  return inscribe::Run(options);
}
