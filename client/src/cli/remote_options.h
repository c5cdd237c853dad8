// `--server ADDR[,ADDR...]`, `--timeout SECONDS` and the TLS and token flags: the option group
// that switches any subcommand from embedded mode (the core library in this process) to remote
// mode (inscribed, through the typed client library). Both modes print the same thing; only
// timings may differ.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "inscribe/client/client.h"
#include "inscribe/client/connection.h"

namespace inscribe::cli {

struct RemoteOptions {
  // "HOST:PORT" (or any gRPC target URI), or several separated by commas: replicas, each
  // call routed by mesh hash with failover (routing.h). Empty = embedded mode.
  std::string server;
  // Time one call may take, all of the client library's retries of UNAVAILABLE included.
  double timeout_seconds = 60.0;
  // TLS (--tls, --tls-ca, --tls-cert, --tls-key): any of them switches to TLS; --tls alone
  // verifies the server against the system's roots.
  bool tls = false;
  client::TlsFiles tls_files;
  // --token-file: bearer token sent with every call (inscribed --auth-tokens).
  std::string token_file;

  bool enabled() const { return !server.empty(); }
  bool tls_enabled() const {
    return tls || !tls_files.ca_file.empty() || !tls_files.cert_file.empty() ||
           !tls_files.key_file.empty();
  }
  // The replicas of `server`, split at commas (blanks dropped).
  std::vector<std::string> servers() const;
};

// Registers --server, --timeout (default `default_timeout_seconds`), --tls, --tls-ca,
// --tls-cert, --tls-key and --token-file on `cmd`. With `server_required`, --server is
// mandatory (`inscribe stats` has no embedded mode).
void AddRemoteOptions(CLI::App* cmd, RemoteOptions* options, double default_timeout_seconds,
                      bool server_required = false);

// The channel settings of `options`: TLS credentials and the bearer token, read from their
// files (INVALID_ARGUMENT naming a file that cannot be read or used).
absl::StatusOr<client::ConnectionOptions> ConnectionOptionsFor(const RemoteOptions& options);

// A client for options.server (routed over the replicas when there are several) whose calls
// default to options.timeout_seconds. The channels connect on the first call, so an
// unreachable server shows up as UNAVAILABLE there; this fails only for unreadable TLS or
// token files (INVALID_ARGUMENT naming the file).
absl::StatusOr<client::Client> MakeClient(const RemoteOptions& options);
// MakeClient for a subcommand: on failure, reports it (ReportRemoteError), sets *exit_code and
// returns nullopt.
std::optional<client::Client> MakeClientOrReport(const RemoteOptions& options, int* exit_code);

int RemoteExitCode(absl::StatusCode code);

// Prints `inscribe: <server's message> (server ADDR: CODE)` on stderr and returns
// RemoteExitCode(status.code()). `status` must not be OK.
int ReportRemoteError(const absl::Status& status, const RemoteOptions& options);

}  // namespace inscribe::cli
