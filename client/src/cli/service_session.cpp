#include "service_session.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "inscribe/client/connection.h"
#include "inscribe/client/routing.h"
#include "inscribe/server/inscribe_server.h"

namespace inscribe::cli {
namespace {

// The in-process service: no port, every core, and none of a shared server's request limits
// (the caller owns the machine; core's own checks, such as --max-voxels, still apply).
server::ServerOptions EmbeddedServerOptions() {
  constexpr std::int64_t kUnlimited = std::numeric_limits<std::int64_t>::max();
  server::ServerOptions options;
  options.listen.clear();
  options.max_message_bytes = std::numeric_limits<int>::max();
  options.limits.max_triangles = kUnlimited;
  options.limits.max_voxels = kUnlimited;
  options.limits.max_spheres = kUnlimited;
  options.limits.max_poses = kUnlimited;
  options.limits.max_scene_objects = kUnlimited;
  options.limits.max_scene_pairs = kUnlimited;
  options.limits.max_scene_ignored = kUnlimited;
  options.limits.memory_budget_bytes = 0;
  return options;
}

// Embedded calls have no deadline: a long generation is not a lost server.
constexpr std::chrono::hours kNoDeadline{24 * 365};

}  // namespace

ServiceSession::~ServiceSession() = default;

absl::StatusOr<std::unique_ptr<ServiceSession>> ServiceSession::Open(const RemoteOptions& options) {
  std::unique_ptr<ServiceSession> session(new ServiceSession());
  client::ClientOptions client_options;
  if (!options.enabled()) {
    absl::StatusOr<std::unique_ptr<server::InscribeServer>> started =
        server::InscribeServer::Start(EmbeddedServerOptions());
    if (!started.ok()) return started.status();
    session->local_ = *std::move(started);
    client_options.default_timeout = kNoDeadline;
    session->client_.emplace(client::MakeGrpcConnection(session->local_->InProcessChannel()),
                             client_options);
    return session;
  }

  absl::StatusOr<client::ConnectionOptions> made = ConnectionOptionsFor(options);
  if (!made.ok()) return made.status();
  const client::ConnectionOptions& connection_options = *made;
  client_options.default_timeout = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::duration<double>(options.timeout_seconds));
  const std::vector<std::string> targets = options.servers();
  if (targets.size() == 1) {
    session->client_.emplace(client::MakeGrpcConnection(targets[0], connection_options),
                             client_options);
    return session;
  }
  // Every replica can be reached within one call (each attempt fails over to the next).
  client_options.retry.max_attempts =
      std::max(client_options.retry.max_attempts, static_cast<int>(targets.size()));
  std::vector<client::Endpoint> endpoints;
  for (const std::string& target : targets) {
    endpoints.push_back({target, client::MakeGrpcConnection(target, connection_options)});
  }
  absl::StatusOr<std::shared_ptr<client::Connection>> routed =
      client::MakeRoutedConnection(std::move(endpoints));
  if (!routed.ok()) return routed.status();
  session->client_.emplace(*std::move(routed), client_options);
  return session;
}

}  // namespace inscribe::cli
