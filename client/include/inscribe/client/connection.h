// The transport under inscribe::client::Client: one attempt of each RPC, nothing more.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "inscribe/v1/service.pb.h"

namespace grpc {
class ChannelCredentials;
}  // namespace grpc

namespace inscribe::client {

// Absolute time by which a call must be answered (the clock gRPC deadlines use).
using Deadline = std::chrono::system_clock::time_point;

// One method per RPC of inscribe.v1.Inscribe. Each call is a single attempt with the given
// deadline: retries, backoff and default deadlines belong to Client. Errors carry the gRPC code
// unchanged (UNAVAILABLE when the server cannot be reached, DEADLINE_EXCEEDED, the server's
// INVALID_ARGUMENT / RESOURCE_EXHAUSTED, ...). Implementations are thread-safe.
//
// An interface so that code using Client can be tested against a mock (gmock) Connection.
class Connection {
 public:
  virtual ~Connection() = default;

  virtual absl::StatusOr<v1::InspectMeshResponse> InspectMesh(const v1::InspectMeshRequest& request,
                                                              Deadline deadline) = 0;
};

struct ConnectionOptions {
  // Channel credentials; nullptr means plaintext (grpc::InsecureChannelCredentials), which is
  // what inscribed serves by default on loopback.
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  // Largest message sent or received, in bytes. Matches inscribed's --max-message-bytes
  // default (256 MiB); gRPC's own 4 MiB receive default is too small for meshes.
  int max_message_bytes = 256 * 1024 * 1024;
};

// A Connection over one gRPC channel to `target` ("HOST:PORT", or any gRPC target URI such as
// "dns:///host:port"). The channel connects lazily on the first call, so this never fails; an
// unreachable server shows up as UNAVAILABLE from the calls.
std::shared_ptr<Connection> MakeGrpcConnection(const std::string& target,
                                               const ConnectionOptions& options = {});

}  // namespace inscribe::client
