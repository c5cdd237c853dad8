#include "remote_options.h"

#include <chrono>
#include <cmath>
#include <iostream>

#include "absl/strings/str_format.h"
#include "exit_codes.h"
#include "inscribe/client/connection.h"

namespace inscribe::cli {

void AddRemoteOptions(CLI::App* cmd, RemoteOptions* options, double default_timeout_seconds,
                      bool server_required) {
  options->timeout_seconds = default_timeout_seconds;
  CLI::Option* server = cmd->add_option(
      "--server", options->server,
      "Run on the inscribed server at HOST:PORT (plaintext gRPC) instead of in this process; "
      "the output is the same");
  if (server_required) server->required();
  cmd->add_option("--timeout", options->timeout_seconds,
                  "With --server: seconds a call may take, retries included (exit 69 when "
                  "exceeded or the server cannot be reached)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

client::Client MakeClient(const RemoteOptions& options) {
  client::ClientOptions client_options;
  client_options.default_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options.timeout_seconds));
  return client::Client(client::MakeGrpcConnection(options.server), client_options);
}

int RemoteExitCode(absl::StatusCode code) {
  switch (code) {
    case absl::StatusCode::kUnavailable:
    case absl::StatusCode::kDeadlineExceeded:
      return kExitServerUnavailable;
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kOutOfRange:
    case absl::StatusCode::kResourceExhausted:
      return kExitBadInput;
    case absl::StatusCode::kFailedPrecondition:
      return kExitUnusableMesh;
    default:
      return kExitInternal;
  }
}

int ReportRemoteError(const absl::Status& status, const RemoteOptions& options) {
  std::cerr << absl::StrFormat("inscribe: %s (server %s: %s)\n", status.message(), options.server,
                               absl::StatusCodeToString(status.code()));
  return RemoteExitCode(status.code());
}

}  // namespace inscribe::cli
