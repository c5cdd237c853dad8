// `--server ADDR[,ADDR...]`, `--timeout SECONDS` and the TLS and token flags: the option group
// that switches a subcommand from embedded mode (the service in this process) to remote mode
// (inscribed at --server); service_session.h opens either. Both modes print the same thing;
// only timings and the remote-only figures (server, cache) differ.
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

}  // namespace inscribe::cli
