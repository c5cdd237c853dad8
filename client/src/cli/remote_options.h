// `--server ADDR` and `--timeout SECONDS`: the option group that switches any subcommand from
// embedded mode (the core library in this process) to remote mode (inscribed, through the
// typed client library). Both modes print the same thing; only timings may differ.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "absl/status/status.h"
#include "inscribe/client/client.h"

namespace inscribe::cli {

struct RemoteOptions {
  std::string server;  // "HOST:PORT" (or any gRPC target URI); empty = embedded mode
  // Time one call may take, all of the client library's retries of UNAVAILABLE included.
  double timeout_seconds = 60.0;

  bool enabled() const { return !server.empty(); }
};

// Registers --server and --timeout (default `default_timeout_seconds`) on `cmd`. With
// `server_required`, --server is mandatory (`inscribe stats` has no embedded mode).
void AddRemoteOptions(CLI::App* cmd, RemoteOptions* options, double default_timeout_seconds,
                      bool server_required = false);

// A plaintext client for options.server whose calls default to options.timeout_seconds.
// Never fails: the channel connects on the first call, so an unreachable server shows up as
// UNAVAILABLE there.
client::Client MakeClient(const RemoteOptions& options);

// The exit status of a failed remote call: kExitServerUnavailable for UNAVAILABLE and
// DEADLINE_EXCEEDED, kExitBadInput for requests the server refuses (INVALID_ARGUMENT,
// NOT_FOUND, OUT_OF_RANGE, RESOURCE_EXHAUSTED: a limit or a full queue, the message says which),
// kExitUnusableMesh for FAILED_PRECONDITION, kExitInternal for everything else.
int RemoteExitCode(absl::StatusCode code);

// Prints `inscribe: <server's message> (server ADDR: CODE)` on stderr and returns
// RemoteExitCode(status.code()). `status` must not be OK.
int ReportRemoteError(const absl::Status& status, const RemoteOptions& options);

}  // namespace inscribe::cli
