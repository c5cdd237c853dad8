// The gRPC implementation of Connection: a channel and the generated stub.
#include <memory>
#include <string>
#include <utility>

#include "grpcpp/channel.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/channel_arguments.h"
#include "inscribe/client/connection.h"
#include "inscribe/server/convert.h"
#include "inscribe/v1/service.grpc.pb.h"

namespace inscribe::client {
namespace {

class GrpcConnection final : public Connection {
 public:
  explicit GrpcConnection(std::shared_ptr<grpc::Channel> channel)
      : stub_(v1::Inscribe::NewStub(std::move(channel))) {}

  absl::StatusOr<v1::InspectMeshResponse> InspectMesh(const v1::InspectMeshRequest& request,
                                                      Deadline deadline) override {
    grpc::ClientContext context;
    context.set_deadline(deadline);
    v1::InspectMeshResponse response;
    const grpc::Status status = stub_->InspectMesh(&context, request, &response);
    if (!status.ok()) return server::FromGrpcStatus(status);
    return response;
  }

 private:
  // Generated stubs are thread-safe; one serves every caller.
  const std::unique_ptr<v1::Inscribe::Stub> stub_;
};

}  // namespace

std::shared_ptr<Connection> MakeGrpcConnection(const std::string& target,
                                               const ConnectionOptions& options) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(options.max_message_bytes);
  arguments.SetMaxSendMessageSize(options.max_message_bytes);
  std::shared_ptr<grpc::ChannelCredentials> credentials =
      options.credentials ? options.credentials : grpc::InsecureChannelCredentials();
  return std::make_shared<GrpcConnection>(
      grpc::CreateCustomChannel(target, credentials, arguments));
}

}  // namespace inscribe::client
