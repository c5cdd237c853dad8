#include "health_command.h"

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "cli_help.h"
#include "command_outcome.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "inscribe/wire/convert.h"
#include "inscribe/wire/service_address.h"
#include "remote_options.h"

namespace inscribe::cli {
namespace {

using grpc::health::v1::HealthCheckResponse;

struct HealthCliOptions {
  std::string service = "inscribe.v1.Inscribe";
  RemoteOptions remote;
};

// One server's answer: "SERVING", "NOT_SERVING", ... or the call's error.
absl::StatusOr<HealthCheckResponse::ServingStatus> Check(const std::string& target,
                                                         const client::ConnectionOptions& channel,
                                                         const HealthCliOptions& options) {
  const auto credentials =
      channel.credentials ? channel.credentials : grpc::InsecureChannelCredentials();
  auto stub = grpc::health::v1::Health::NewStub(
      grpc::CreateChannel(wire::TargetWithDefaultPort(target), credentials));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() +
                       std::chrono::duration_cast<std::chrono::system_clock::duration>(
                           std::chrono::duration<double>(options.remote.timeout_seconds)));
  // The health service needs no token; one is sent anyway when given, so a proxy in front that
  // insists on it is satisfied too.
  if (!channel.bearer_token.empty()) {
    context.AddMetadata("authorization", "Bearer " + channel.bearer_token);
  }
  grpc::health::v1::HealthCheckRequest request;
  request.set_service(options.service);
  HealthCheckResponse response;
  const grpc::Status status = stub->Check(&context, request, &response);
  if (!status.ok()) return wire::FromGrpcStatus(status);
  return response.status();
}

absl::Status RunHealth(const HealthCliOptions& options) {
  absl::StatusOr<client::ConnectionOptions> channel = ConnectionOptionsFor(options.remote);
  if (!channel.ok()) return channel.status();
  const std::vector<std::string> targets = options.remote.servers();
  std::size_t not_serving = 0;
  for (const std::string& target : targets) {
    absl::StatusOr<HealthCheckResponse::ServingStatus> status = Check(target, *channel, options);
    if (!status.ok()) {
      const absl::StatusCode code = status.status().code();
      const bool unreachable =
          code == absl::StatusCode::kUnavailable || code == absl::StatusCode::kDeadlineExceeded;
      std::cout << absl::StrFormat("%s %s (%s: %s)\n", target,
                                   unreachable ? "UNREACHABLE" : "ERROR",
                                   absl::StatusCodeToString(code), status.status().message());
      ++not_serving;
      continue;
    }
    std::cout << absl::StrFormat("%s %s\n", target,
                                 HealthCheckResponse::ServingStatus_Name(*status));
    if (*status != HealthCheckResponse::SERVING) ++not_serving;
  }
  if (not_serving > 0) {
    return CommandError(
        absl::StatusCode::kUnavailable,
        absl::StrFormat("%d of %d servers not serving", not_serving, targets.size()),
        kExitServerUnavailable);
  }
  return absl::OkStatus();
}

}  // namespace

void AddHealthCommand(CLI::App& app, CommandOutcome* outcome) {
  auto options = std::make_shared<HealthCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "health",
      "Ask each server's gRPC health service whether it is serving (exit 0 when all are, 69 "
      "when one is not or cannot be reached); the probe of container health checks");
  cmd->add_option("--service", options->service,
                  "Service to ask about; empty = the server as a whole")
      ->capture_default_str();
  AddRemoteOptions(cmd, &options->remote, 5.0, /*server_required=*/true);
  SetExitStatusHelp(cmd, "");
  cmd->callback([options, outcome] {
    *outcome = CommandOutcome{RunHealth(*options), options->remote.server};
  });
}

}  // namespace inscribe::cli
