// A running inscribe gRPC server: the service, its job pool, health and reflection.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/service_address.h"

namespace grpc {
class Channel;
}  // namespace grpc

namespace inscribe::server {

// TLS on the listening port. PEM files, read at start and again by InscribeServer::Reload.
struct ServerTlsOptions {
  // --tls-cert and --tls-key: the server's certificate chain and private key. Both or neither;
  // with neither the port is plaintext.
  std::string cert_file;
  std::string key_file;
  // --tls-client-ca: CA certificates; when given, every client must present a certificate
  // signed by one of them (mutual TLS) or the handshake fails.
  std::string client_ca_file;

  bool enabled() const { return !cert_file.empty() || !key_file.empty(); }
};

struct ServerOptions {
  // --listen: HOST:PORT to bind (plaintext unless `tls` is enabled). Loopback by default; port
  // 0 picks a free port (read it back from InscribeServer::port()). Empty: no port at all, the
  // server is reached only through InProcessChannel (the CLI's embedded mode).
  std::string listen = absl::StrCat("127.0.0.1:", wire::kDefaultPort);
  // --jobs: requests computed at the same time. 0 = one per hardware thread.
  int jobs = 0;
  // --max-queue: requests queued or running at once; more get RESOURCE_EXHAUSTED.
  std::int64_t max_queue = 64;
  // --max-message-bytes: largest request accepted, in bytes (256 MiB holds a mesh of ~5M
  // triangles with ~2.5M vertices). gRPC's own default, 4 MiB, is too small for meshes.
  int max_message_bytes = 256 * 1024 * 1024;
  ServiceLimits limits;
  // --cache-memory-bytes, --cache-dir, --redis: the result cache's tiers.
  ResultCacheOptions cache;
  // --tls-cert, --tls-key, --tls-client-ca.
  ServerTlsOptions tls;
  // --auth-tokens: file of accepted bearer tokens, one per line (blank lines and lines
  // starting with '#' ignored); empty = no authentication. When set, every inscribe.v1 call
  // must carry "authorization: Bearer <token>" with one of them, else UNAUTHENTICATED. The
  // health service stays open (probes carry no token). Read at start and again by
  // InscribeServer::Reload.
  std::string auth_tokens_file;
  // --metrics-listen: HOST:PORT of the Prometheus endpoint (GET /metrics); empty = none.
  std::string metrics_listen;
  // Told about every finished call; see CallObserver. May be empty.
  CallObserver on_call;
};

// What InscribeServer::Reload did with each set of files; nullopt for a set the server does not
// use (no --auth-tokens; plaintext).
struct ReloadResult {
  // --auth-tokens: OK when the file's tokens replaced the accepted ones; else why the accepted
  // tokens stay as they were (the errors of InscribeServer::Start for that file).
  std::optional<absl::Status> tokens;
  // --tls-cert, --tls-key, --tls-client-ca: OK when the files are in use for new connections
  // (within ~1 s); else why the files served before stay in use.
  std::optional<absl::Status> tls;
};

// Owns the grpc::Server, the service and the pool, and shuts them down in that order. Serves
// inscribe.v1.Inscribe, grpc.health.v1.Health (the overall status "" and the service name
// "inscribe.v1.Inscribe" are SERVING until shutdown) and reflection (v1alpha).
class InscribeServer {
 public:
  // Binds and starts serving. UNAVAILABLE when the address cannot be bound, INVALID_ARGUMENT
  // for options out of range; for the TLS and token files, FAILED_PRECONDITION naming one that
  // cannot be read and INVALID_ARGUMENT naming one that holds the wrong thing (no PEM
  // certificate, a key not matching the certificate, a malformed token or none). With TLS, also
  // FAILED_PRECONDITION when the private directory of the certificates gRPC watches cannot be
  // made or written (under $TMPDIR; see Reload).
  static absl::StatusOr<std::unique_ptr<InscribeServer>> Start(const ServerOptions& options);

  // Shutdown(now) if not done yet, then waits for running jobs.
  ~InscribeServer();
  InscribeServer(const InscribeServer&) = delete;
  InscribeServer& operator=(const InscribeServer&) = delete;

  // The port actually bound (the one asked for, or the one picked for port 0).
  int port() const { return port_; }
  // HOST:PORT with the bound port, e.g. "127.0.0.1:50051"; suitable as a client target. Empty
  // when there is no port (ServerOptions::listen empty).
  const std::string& address() const { return address_; }
  // A channel to this server inside this process, with no socket and no TLS (--auth-tokens
  // still apply). The server must outlive it.
  std::shared_ptr<grpc::Channel> InProcessChannel() const;
  // The port of the Prometheus endpoint (--metrics-listen), 0 when there is none.
  int metrics_port() const;
  // Jobs (requests) used by the pool after resolving jobs = 0.
  int jobs() const { return jobs_; }
  // Jobs queued or running on the pool now (each has released what it held once it no longer
  // counts); for tests and harnesses that wait for the server to be idle.
  std::int64_t jobs_in_flight() const;
  // SceneStream calls open now, each holding its scene; a call's scene is freed when the call
  // is done (finished, cancelled, or its client gone).
  std::int64_t open_scenes() const;

  // Reads the token file and the TLS files again (inscribed does on SIGHUP) and uses what
  // passes Start's checks; a set that fails keeps what was in use, so a bad file never leaves
  // the server open or locked out. Calls and connections already open are not touched: a call
  // admitted with a token that is no longer accepted runs on, a connection keeps the
  // certificate it was made with. TLS files that pass are copied into a private directory
  // (mode 0700, under $TMPDIR, removed with the server) that gRPC re-reads every second.
  // Thread-safe.
  ReloadResult Reload();

  // Graceful stop: marks health NOT_SERVING, answers new calls with UNAVAILABLE, lets accepted
  // calls finish until `deadline`, then cancels what is left, closes every connection and waits
  // for the pool's jobs. Returns as soon as the calls are done, not at `deadline`. Jobs already
  // running are not interrupted (core has no cancellation points yet), so a job that outlives
  // `deadline` delays the return. Idempotent; thread-safe.
  void Shutdown(std::chrono::system_clock::time_point deadline);

  // Blocks until Shutdown has completed (from another thread).
  void Wait();

 private:
  struct Parts;
  explicit InscribeServer(std::unique_ptr<Parts> parts, int port, std::string address, int jobs);

  std::unique_ptr<Parts> parts_;
  int port_ = 0;
  std::string address_;
  int jobs_ = 0;
};

}  // namespace inscribe::server
