#include "inscribe/server/inscribe_server.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "grpc/grpc.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server.h"
#include "grpcpp/server_builder.h"

namespace inscribe::server {
namespace {

constexpr char kServiceName[] = "inscribe.v1.Inscribe";

absl::Status CheckOptions(const ServerOptions& options) {
  if (options.listen.rfind(':') == std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat("--listen must be HOST:PORT, got \"", options.listen, "\""));
  }
  if (options.jobs < 0) return absl::InvalidArgumentError("--jobs must be >= 0 (0 = all cores)");
  if (options.max_queue < 1) return absl::InvalidArgumentError("--max-queue must be >= 1");
  if (options.max_message_bytes < 1) {
    return absl::InvalidArgumentError("--max-message-bytes must be >= 1");
  }
  if (options.limits.max_triangles < 1) {
    return absl::InvalidArgumentError("--max-triangles must be >= 1");
  }
  if (options.limits.max_voxels < 1 || options.limits.max_spheres < 1 ||
      options.limits.max_poses < 1) {
    return absl::InvalidArgumentError("--max-voxels, --max-spheres and --max-poses must be >= 1");
  }
  return absl::OkStatus();
}

int ResolveJobs(int jobs) {
  if (jobs > 0) return jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

// Declaration order is construction order: the gRPC server is destroyed first, the pool last.
struct InscribeServer::Parts {
  Parts(const JobPoolOptions& pool_options, std::unique_ptr<ResultCache> result_cache,
        const ServiceLimits& limits, CallObserver observer)
      : pool(pool_options),
        cache(std::move(result_cache)),
        service(&pool, cache.get(), limits, std::move(observer)) {}

  JobPool pool;
  std::unique_ptr<ResultCache> cache;
  InscribeService service;
  std::unique_ptr<grpc::Server> server;

  std::mutex mutex;
  std::condition_variable stopped;
  bool shutdown_started = false;  // guarded by mutex
  bool shutdown_done = false;     // guarded by mutex
};

absl::StatusOr<std::unique_ptr<InscribeServer>> InscribeServer::Start(
    const ServerOptions& options) {
  if (absl::Status s = CheckOptions(options); !s.ok()) return s;
  const int jobs = ResolveJobs(options.jobs);
  absl::StatusOr<std::unique_ptr<ResultCache>> cache = ResultCache::Open(options.cache);
  if (!cache.ok()) return cache.status();
  auto parts = std::make_unique<Parts>(JobPoolOptions{jobs, options.max_queue}, *std::move(cache),
                                       options.limits, options.on_call);

  // Both are process-wide switches read by the builder; setting them again is harmless.
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  grpc::ServerBuilder builder;
  int port = 0;
  builder.AddListeningPort(options.listen, grpc::InsecureServerCredentials(), &port);
  builder.RegisterService(&parts->service);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  // gRPC sets SO_REUSEPORT by default on Linux, which would let a second server silently share
  // (and steal calls from) a port that is in use; an occupied port must be an error instead.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  parts->server = builder.BuildAndStart();
  if (parts->server == nullptr || port == 0) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen,
                                               " (address in use, or not a local address?)"));
  }
  parts->server->GetHealthCheckService()->SetServingStatus(kServiceName, true);

  const std::string host = options.listen.substr(0, options.listen.rfind(':'));
  return std::unique_ptr<InscribeServer>(
      new InscribeServer(std::move(parts), port, absl::StrCat(host, ":", port), jobs));
}

InscribeServer::InscribeServer(std::unique_ptr<Parts> parts, int port, std::string address,
                               int jobs)
    : parts_(std::move(parts)), port_(port), address_(std::move(address)), jobs_(jobs) {}

InscribeServer::~InscribeServer() { Shutdown(std::chrono::system_clock::now()); }

void InscribeServer::Shutdown(std::chrono::system_clock::time_point deadline) {
  {
    std::unique_lock<std::mutex> lock(parts_->mutex);
    if (parts_->shutdown_started) {
      parts_->stopped.wait(lock, [this] { return parts_->shutdown_done; });
      return;
    }
    parts_->shutdown_started = true;
  }
  // Load balancers and health probes see NOT_SERVING while calls in progress drain.
  parts_->server->GetHealthCheckService()->Shutdown();
  parts_->service.StartDraining();
  parts_->service.WaitForCalls(deadline);
  // Every call has been answered, or the grace period is over: cancel what is left (calls past
  // the deadline, whose jobs notice before they start; health watches; idle connections, which
  // gRPC would otherwise wait on until the deadline). Returns once every call has finished.
  parts_->server->Shutdown(std::min(deadline, std::chrono::system_clock::now()));
  // A job may still be returning from its last callback; nothing may be destroyed under it.
  parts_->pool.WaitIdle();
  {
    std::lock_guard<std::mutex> lock(parts_->mutex);
    parts_->shutdown_done = true;
  }
  parts_->stopped.notify_all();
}

void InscribeServer::Wait() {
  std::unique_lock<std::mutex> lock(parts_->mutex);
  parts_->stopped.wait(lock, [this] { return parts_->shutdown_done; });
}

}  // namespace inscribe::server
