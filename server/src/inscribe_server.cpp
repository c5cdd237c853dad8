#include "inscribe/server/inscribe_server.h"

#include <openssl/bio.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/x509.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <fstream>
#include <iterator>
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

// The text of PEM file `path` (given as `flag`), after OpenSSL has parsed what it must hold:
// `certificates` >= 1 certificates, or else one private key. FAILED_PRECONDITION when it cannot
// be read, INVALID_ARGUMENT when it holds something else. Read once at start; a few KiB.
absl::StatusOr<std::string> ReadPemFile(const std::string& path, const char* flag,
                                        bool certificates) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in) {
    return absl::FailedPreconditionError(absl::StrCat("cannot read ", flag, " file ", path, ": ",
                                                      errno != 0 ? std::strerror(errno) : "?"));
  }
  const std::unique_ptr<BIO, decltype(&BIO_free)> bio(
      BIO_new_mem_buf(text.data(), static_cast<int>(text.size())), BIO_free);
  bool parsed = false;
  if (certificates) {
    X509* cert = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr);
    parsed = cert != nullptr;
    X509_free(cert);
  } else {
    // No passphrase callback: an encrypted key fails here rather than prompting a terminal.
    EVP_PKEY* key = PEM_read_bio_PrivateKey(bio.get(), nullptr, nullptr, const_cast<char*>(""));
    parsed = key != nullptr;
    EVP_PKEY_free(key);
  }
  // OpenSSL's per-thread error queue would otherwise hold these for gRPC's next TLS call.
  ERR_clear_error();
  if (!parsed) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, " file ", path, " holds no ",
                     certificates ? "PEM certificate" : "unencrypted PEM private key"));
  }
  return text;
}

// Whether the private key belongs to the first certificate of the chain; a mismatch would
// otherwise only show up as every client's handshake failing.
bool KeyMatchesCertificate(const std::string& chain, const std::string& key_pem) {
  const std::unique_ptr<BIO, decltype(&BIO_free)> cert_bio(
      BIO_new_mem_buf(chain.data(), static_cast<int>(chain.size())), BIO_free);
  const std::unique_ptr<BIO, decltype(&BIO_free)> key_bio(
      BIO_new_mem_buf(key_pem.data(), static_cast<int>(key_pem.size())), BIO_free);
  const std::unique_ptr<X509, decltype(&X509_free)> cert(
      PEM_read_bio_X509(cert_bio.get(), nullptr, nullptr, nullptr), X509_free);
  const std::unique_ptr<EVP_PKEY, decltype(&EVP_PKEY_free)> key(
      PEM_read_bio_PrivateKey(key_bio.get(), nullptr, nullptr, const_cast<char*>("")),
      EVP_PKEY_free);
  const bool matches =
      cert != nullptr && key != nullptr && X509_check_private_key(cert.get(), key.get()) == 1;
  ERR_clear_error();
  return matches;
}

// Plaintext, TLS, or TLS requiring a client certificate signed by --tls-client-ca.
absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MakeServerCredentials(
    const ServerTlsOptions& tls) {
  if (!tls.enabled()) return grpc::InsecureServerCredentials();
  absl::StatusOr<std::string> chain = ReadPemFile(tls.cert_file, "--tls-cert", true);
  if (!chain.ok()) return chain.status();
  absl::StatusOr<std::string> key = ReadPemFile(tls.key_file, "--tls-key", false);
  if (!key.ok()) return key.status();
  if (!KeyMatchesCertificate(*chain, *key)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--tls-key file ", tls.key_file, " is not the key of --tls-cert file ", tls.cert_file));
  }
  grpc::SslServerCredentialsOptions ssl(GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE);
  ssl.pem_key_cert_pairs.push_back({*std::move(key), *std::move(chain)});
  if (!tls.client_ca_file.empty()) {
    absl::StatusOr<std::string> roots = ReadPemFile(tls.client_ca_file, "--tls-client-ca", true);
    if (!roots.ok()) return roots.status();
    ssl.pem_root_certs = *std::move(roots);
    ssl.client_certificate_request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  return grpc::SslServerCredentials(ssl);
}

// The service's view of --auth-tokens; empty (admit all) when not given.
absl::StatusOr<CallAuthenticator> MakeAuthenticator(const std::string& tokens_file) {
  if (tokens_file.empty()) return CallAuthenticator();
  absl::StatusOr<BearerAuthenticator> tokens = BearerAuthenticator::FromFile(tokens_file);
  if (!tokens.ok()) return tokens.status();
  auto shared = std::make_shared<const BearerAuthenticator>(*std::move(tokens));
  return CallAuthenticator(
      [shared](const grpc::CallbackServerContext& context) { return shared->Check(context); });
}

int ResolveJobs(int jobs) {
  if (jobs > 0) return jobs;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

// Declaration order is construction order: the gRPC server is destroyed first, the pool last.
struct InscribeServer::Parts {
  Parts(const JobPoolOptions& pool_options, std::unique_ptr<ResultCache> result_cache,
        const ServiceLimits& limits, CallObserver observer, CallAuthenticator authenticate)
      : pool(pool_options),
        cache(std::move(result_cache)),
        service(&pool, cache.get(), limits, std::move(observer), std::move(authenticate)) {}

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
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(options.tls);
  if (!credentials.ok()) return credentials.status();
  absl::StatusOr<CallAuthenticator> authenticate = MakeAuthenticator(options.auth_tokens_file);
  if (!authenticate.ok()) return authenticate.status();
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
  auto parts =
      std::make_unique<Parts>(JobPoolOptions{jobs, options.max_queue}, *std::move(cache),
                              options.limits, std::move(observe), *std::move(authenticate));
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
  if (!options.listen.empty())
    builder.AddListeningPort(options.listen, *std::move(credentials), &port);
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
