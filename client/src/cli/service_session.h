// The service a subcommand calls. With --server it is inscribed there (through the client
// library, routed over the replicas when there are several); without, it is the same service
// started in this process with no port and reached through an in-process channel (embedded
// mode). Commands are written once, against client(): both modes run the same code and the
// same store and write the same files.
#pragma once

#include <memory>
#include <optional>

#include "absl/status/statusor.h"
#include "inscribe/client/client.h"
#include "remote_options.h"

namespace inscribe::server {
class InscribeServer;
}  // namespace inscribe::server

namespace inscribe::cli {

class ServiceSession {
 public:
  // Remote mode: a client for options.server whose calls default to options.timeout_seconds;
  // the channels connect on the first call, so an unreachable server shows up as UNAVAILABLE
  // there. Fails only for unreadable TLS or token files (INVALID_ARGUMENT naming the file).
  // Embedded mode: starts the in-process service (this machine's cores, no request limits,
  // no deadline; --timeout does not apply).
  static absl::StatusOr<std::unique_ptr<ServiceSession>> Open(const RemoteOptions& options);

  ~ServiceSession();
  ServiceSession(const ServiceSession&) = delete;
  ServiceSession& operator=(const ServiceSession&) = delete;

  const client::Client& client() const { return *client_; }

 private:
  ServiceSession() = default;

  // Declared first, destroyed last: the client's channel goes before the server it reaches.
  std::unique_ptr<server::InscribeServer> local_;  // embedded mode only
  std::optional<client::Client> client_;
};

}  // namespace inscribe::cli
