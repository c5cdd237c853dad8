#include "inscribe/server/inscribe_server.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "bearer_auth.h"
#include "grpc/grpc.h"
#include "grpcpp/channel.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server.h"
#include "grpcpp/server_builder.h"
#include "grpcpp/support/channel_arguments.h"
#include "reloadable_server_tls.h"
#include "service_metrics.h"

namespace inscribe::server {
namespace {

constexpr char kServiceName[] = "inscribe.v1.Inscribe";

absl::Status CheckOptions(const ServerOptions& options) {
  if (!options.listen.empty() && options.listen.rfind(':') == std::string::npos) {
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
  if (options.limits.max_scene_objects < 1 || options.limits.max_scene_pairs < 1 ||
      options.limits.max_scene_ignored < 0) {
    return absl::InvalidArgumentError(
        "--max-scene-objects and --max-scene-pairs must be >= 1, --max-scene-ignored >= 0");
  }
  if (options.tls.cert_file.empty() != options.tls.key_file.empty()) {
    return absl::InvalidArgumentError("--tls-cert and --tls-key go together: give both or neither");
  }
  if (!options.tls.client_ca_file.empty() && !options.tls.enabled()) {
    return absl::InvalidArgumentError(
        "--tls-client-ca needs --tls-cert and --tls-key: client certificates are checked in "
        "the TLS handshake");
  }
  return absl::OkStatus();
}

// The service's view of `tokens`; empty (admit all) when there are none.
CallAuthenticator MakeAuthenticator(std::shared_ptr<const BearerAuthenticator> tokens) {
  if (tokens == nullptr) return CallAuthenticator();
  return CallAuthenticator(
      [tokens](const grpc::CallbackServerContext& context) { return tokens->Check(context); });
}

int ResolveJobs(int jobs) {
  if (jobs > 0) return jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

// Declaration order is construction order: the gRPC server is destroyed first, then the
// service, cache and pool, and last the TLS files gRPC watches and the accepted tokens.
struct InscribeServer::Parts {
  Parts(const JobPoolOptions& pool_options, std::unique_ptr<ResultCache> result_cache,
        const ServiceLimits& limits, CallObserver observer,
        std::shared_ptr<BearerAuthenticator> bearer_tokens,
        std::unique_ptr<ReloadableServerTls> server_tls)
      : tls(std::move(server_tls)),
        tokens(std::move(bearer_tokens)),
        pool(pool_options),
        cache(std::move(result_cache)),
        service(&pool, cache.get(), limits, std::move(observer), MakeAuthenticator(tokens)) {}

  std::unique_ptr<ReloadableServerTls> tls;     // null: plaintext
  std::shared_ptr<BearerAuthenticator> tokens;  // null: no --auth-tokens
  JobPool pool;
  std::unique_ptr<ResultCache> cache;
  int metrics_port = 0;       // 0: no metrics endpoint
  int max_message_bytes = 0;  // --max-message-bytes, for in-process channels too
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
  std::unique_ptr<ReloadableServerTls> tls;
  if (options.tls.enabled()) {
    absl::StatusOr<std::unique_ptr<ReloadableServerTls>> started =
        ReloadableServerTls::Start(options.tls);
    if (!started.ok()) return started.status();
    tls = *std::move(started);
  }
  std::shared_ptr<BearerAuthenticator> tokens;
  if (!options.auth_tokens_file.empty()) {
    absl::StatusOr<BearerAuthenticator> read =
        BearerAuthenticator::FromFile(options.auth_tokens_file);
    if (!read.ok()) return read.status();
    tokens = std::make_shared<BearerAuthenticator>(*std::move(read));
  }
  absl::StatusOr<std::unique_ptr<ResultCache>> cache = ResultCache::Open(options.cache);
  if (!cache.ok()) return cache.status();
  // The metrics see every call the caller's observer sees. They are made after the parts they
  // read (cache, pool) and owned by the observer, which the service holds: so they stop before
  // the cache and the pool go.
  auto metrics = std::make_shared<std::unique_ptr<ServiceMetrics>>();
  CallObserver observe = [metrics, user = options.on_call](const CallRecord& call) {
    if (*metrics) (*metrics)->RecordCall(call);
    if (user) user(call);
  };
  auto parts = std::make_unique<Parts>(JobPoolOptions{jobs, options.max_queue}, *std::move(cache),
                                       options.limits, std::move(observe), std::move(tokens),
                                       std::move(tls));
  if (!options.metrics_listen.empty()) {
    // Set before the server starts, so call threads read it without a lock.
    absl::StatusOr<std::unique_ptr<ServiceMetrics>> started = ServiceMetrics::Start(
        options.metrics_listen, parts->cache.get(), &parts->pool, &parts->service);
    if (!started.ok()) return started.status();
    parts->metrics_port = (*started)->port();
    *metrics = *std::move(started);
  }

  // Both are process-wide switches read by the builder; setting them again is harmless.
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();

  grpc::ServerBuilder builder;
  int port = 0;
  if (!options.listen.empty()) {
    builder.AddListeningPort(
        options.listen,
        parts->tls != nullptr ? parts->tls->credentials() : grpc::InsecureServerCredentials(),
        &port);
  }
  builder.RegisterService(&parts->service);
  builder.SetMaxReceiveMessageSize(options.max_message_bytes);
  // gRPC sets SO_REUSEPORT by default on Linux, which would let a second server silently share
  // (and steal calls from) a port that is in use; an occupied port must be an error instead.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  parts->server = builder.BuildAndStart();
  if (parts->server == nullptr || (port == 0 && !options.listen.empty())) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", options.listen,
                                               " (address in use, or not a local address?)"));
  }
  parts->server->GetHealthCheckService()->SetServingStatus(kServiceName, true);

  parts->max_message_bytes = options.max_message_bytes;
  const std::string address =
      options.listen.empty()
          ? std::string()
          : absl::StrCat(options.listen.substr(0, options.listen.rfind(':')), ":", port);
  return std::unique_ptr<InscribeServer>(new InscribeServer(std::move(parts), port, address, jobs));
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

ReloadResult InscribeServer::Reload() {
  ReloadResult result;
  if (parts_->tokens != nullptr) result.tokens = parts_->tokens->Reload();
  if (parts_->tls != nullptr) result.tls = parts_->tls->Reload();
  return result;
}

int InscribeServer::metrics_port() const { return parts_->metrics_port; }

std::shared_ptr<grpc::Channel> InscribeServer::InProcessChannel() const {
  grpc::ChannelArguments args;
  args.SetMaxReceiveMessageSize(parts_->max_message_bytes);
  args.SetMaxSendMessageSize(parts_->max_message_bytes);
  return parts_->server->InProcessChannel(args);
}

std::int64_t InscribeServer::jobs_in_flight() const { return parts_->pool.jobs_in_flight(); }

std::int64_t InscribeServer::open_scenes() const { return parts_->service.open_scenes(); }

void InscribeServer::Wait() {
  std::unique_lock<std::mutex> lock(parts_->mutex);
  parts_->stopped.wait(lock, [this] { return parts_->shutdown_done; });
}

}  // namespace inscribe::server
