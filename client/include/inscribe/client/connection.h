// The transport under inscribe::client::Client: one attempt of each RPC, nothing more.
//
// Retry and failover policy, in one layer: the Client retries idempotent unary calls
// (RetryPolicy) and every Connection call is exactly one RPC to one server. A routed connection
// (routing.h) picks the server for each call; when it answers UNAVAILABLE the routed
// connection marks it down and returns the error with kRetryElsewherePayload, so the Client's
// next attempt goes to the next replica at once. The one exception is a DistanceStream, which
// the Client does not retry: a routed stream that breaks is reopened on the next replica and
// its frame resent (a frame is a pure query); a SceneStream, whose scene lives on one server,
// is opened on the first replica of its route key that answers its first message and ends
// with UNAVAILABLE if that replica goes away.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "inscribe/v1/service.pb.h"

namespace grpc {
class Channel;
class ChannelCredentials;
}  // namespace grpc

namespace inscribe::client {

// Type URL of the payload an UNAVAILABLE status carries when another server can take the call
// now (a routed connection has marked the unreachable one down): the Client then makes its
// next attempt without waiting for the backoff.
inline constexpr char kRetryElsewherePayload[] = "type.inscribe.dev/retry-elsewhere";

// Absolute time by which a call must be answered (the clock gRPC deadlines use).
using Deadline = std::chrono::system_clock::time_point;

// One open bidirectional call that answers each message with one reply, in order: a
// DistanceStream (Message = DistanceFrame) or a SceneStream (Message = SceneMessage).
// Not thread-safe: one simulator loop drives one stream.
template <typename Message, typename Reply>
class FrameStream {
 public:
  // Ends the call (cancelling it if Finish was not reached).
  virtual ~FrameStream() = default;

  // Sends `message` and waits for its reply until `deadline`. An error ends the stream: the
  // server's status (NOT_FOUND, INVALID_ARGUMENT, ...), UNAVAILABLE when the connection broke,
  // DEADLINE_EXCEEDED when the reply did not come in time (the call is then cancelled).
  virtual absl::StatusOr<Reply> RoundTrip(const Message& message, Deadline deadline) = 0;

  // Half-closes the stream and returns the server's final status (OK after a clean end).
  virtual absl::Status Finish() = 0;
};

using DistanceStreamConnection = FrameStream<v1::DistanceFrame, v1::DistanceFrameResult>;
using SceneStreamConnection = FrameStream<v1::SceneMessage, v1::SceneReply>;

// One method per RPC of inscribe.v1.Inscribe. Each call is a single attempt (one RPC) with the
// given deadline: retries, backoff and default deadlines belong to Client. Errors carry the gRPC
// code unchanged (UNAVAILABLE when the server cannot be reached, DEADLINE_EXCEEDED, the server's
// INVALID_ARGUMENT / RESOURCE_EXHAUSTED, ...). Implementations are thread-safe.
//
// An interface so that code using Client can be tested against a mock (gmock) Connection.
class Connection {
 public:
  virtual ~Connection() = default;

  virtual absl::StatusOr<v1::InspectMeshResponse> InspectMesh(const v1::InspectMeshRequest& request,
                                                              Deadline deadline) = 0;
  virtual absl::StatusOr<v1::PutMeshResponse> PutMesh(const v1::PutMeshRequest& request,
                                                      Deadline deadline) = 0;
  // Reads the whole Generate stream: `on_progress` (may be null) gets each progress fraction
  // as it arrives, on the calling thread; the result is the stream's last message. INTERNAL
  // when the stream ends OK without a result.
  virtual absl::StatusOr<v1::GenerateResult> Generate(
      const v1::GenerateRequest& request, Deadline deadline,
      const std::function<void(double fraction)>& on_progress) = 0;
  virtual absl::StatusOr<v1::PutSphereSetResponse> PutSphereSet(
      const v1::PutSphereSetRequest& request, Deadline deadline) = 0;
  virtual absl::StatusOr<v1::GetSphereSetResponse> GetSphereSet(
      const v1::GetSphereSetRequest& request, Deadline deadline) = 0;
  virtual absl::StatusOr<v1::GetHierarchyResponse> GetHierarchy(
      const v1::GetHierarchyRequest& request, Deadline deadline) = 0;
  virtual absl::StatusOr<v1::UpdateDeformationResponse> UpdateDeformation(
      const v1::UpdateDeformationRequest& request, Deadline deadline) = 0;
  virtual absl::StatusOr<v1::DistanceResponse> Distance(const v1::DistanceRequest& request,
                                                        Deadline deadline) = 0;
  virtual absl::StatusOr<v1::EvaluateResponse> Evaluate(const v1::EvaluateRequest& request,
                                                        Deadline deadline) = 0;
  virtual absl::StatusOr<v1::CertifyCoverResponse> CertifyCover(
      const v1::CertifyCoverRequest& request, Deadline deadline) = 0;
  virtual absl::StatusOr<v1::CacheStatsResponse> CacheStats(const v1::CacheStatsRequest& request,
                                                            Deadline deadline) = 0;
  // Opens a DistanceStream call that must end by `deadline` (Deadline::max() for none). Never
  // fails for an unreachable server: the first RoundTrip reports UNAVAILABLE.
  virtual absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> OpenDistanceStream(
      Deadline deadline) = 0;
  // Opens a SceneStream call that must end by `deadline`, as OpenDistanceStream. A routed
  // connection sends it to the replica of the first message's first object's set.
  virtual absl::StatusOr<std::unique_ptr<SceneStreamConnection>> OpenSceneStream(
      Deadline deadline) = 0;
};

struct ConnectionOptions {
  // Channel credentials; nullptr means plaintext (grpc::InsecureChannelCredentials), which is
  // what inscribed serves by default on loopback. MakeTlsCredentials builds TLS ones.
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  // Sent on every call as "authorization: Bearer <token>" (inscribed --auth-tokens); empty =
  // none; printable ASCII without spaces (ReadBearerToken checks). Over plaintext the token
  // travels in the clear: use TLS beyond loopback.
  std::string bearer_token;
  // Largest message sent or received, in bytes. Matches inscribed's --max-message-bytes
  // default (256 MiB); gRPC's own 4 MiB receive default is too small for meshes.
  int max_message_bytes = 256 * 1024 * 1024;
};

// PEM files for a TLS channel (inscribed --tls-cert/--tls-key/--tls-client-ca).
struct TlsFiles {
  // CA certificates the server's certificate must chain to; empty = the system's roots.
  std::string ca_file;
  // The client's certificate chain and key, for servers that verify clients (mutual TLS).
  // Both or neither.
  std::string cert_file;
  std::string key_file;
};

// TLS channel credentials from PEM files. INVALID_ARGUMENT naming a file that cannot be read
// or is not PEM, or when only one of cert_file and key_file is given.
absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> MakeTlsCredentials(const TlsFiles& files);

// The token of a token file: its first line that is neither blank nor a '#' comment, without
// surrounding whitespace. INVALID_ARGUMENT naming the file when it cannot be read, holds no
// token, or the token has a character outside printable ASCII (or a space).
absl::StatusOr<std::string> ReadBearerToken(const std::string& path);

// A Connection over one gRPC channel to `target` ("HOST:PORT", "HOST" for the default port
// 50051 (wire::TargetWithDefaultPort), or any gRPC target URI such as "dns:///host:port"). The
// channel connects lazily on the first call, so this never fails; an
// unreachable server shows up as UNAVAILABLE from the calls.
std::shared_ptr<Connection> MakeGrpcConnection(const std::string& target,
                                               const ConnectionOptions& options = {});
// A Connection over an existing channel, e.g. an in-process one
// (inscribe::server::InscribeServer::InProcessChannel), sending `bearer_token` when not empty.
std::shared_ptr<Connection> MakeGrpcConnection(std::shared_ptr<grpc::Channel> channel,
                                               const std::string& bearer_token = "");

}  // namespace inscribe::client
