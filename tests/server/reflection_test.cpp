// Server reflection (grpc.reflection.v1alpha, the version gRPC 1.51 serves), called through the
// generic stub with hand-encoded bytes: Debian ships the reflection library but not its
// generated headers, and a second copy of reflection.proto would clash with the library's.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "grpcpp/completion_queue.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/generic/generic_stub.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/byte_buffer.h"
#include "inscribe/server/inscribe_server.h"

namespace inscribe::server {
namespace {

// Waits for the next completion and reports whether it succeeded.
bool Await(grpc::CompletionQueue& queue) {
  void* tag = nullptr;
  bool ok = false;
  return queue.Next(&tag, &ok) && ok;
}

TEST(Reflection, ListsTheInscribeService) {
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  absl::StatusOr<std::unique_ptr<InscribeServer>> server = InscribeServer::Start(options);
  ASSERT_TRUE(server.ok()) << server.status();

  grpc::GenericStub stub(
      grpc::CreateChannel((*server)->address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  grpc::CompletionQueue queue;
  auto call = stub.PrepareCall(
      &context, "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo", &queue);
  call->StartCall(nullptr);
  ASSERT_TRUE(Await(queue));

  // ServerReflectionRequest{list_services: ""}: field 7, wire type 2 (length-delimited), length 0.
  const char request_bytes[] = {0x3a, 0x00};
  grpc::Slice slice(request_bytes, sizeof request_bytes);
  grpc::ByteBuffer request(&slice, 1);
  call->Write(request, nullptr);
  ASSERT_TRUE(Await(queue));
  grpc::ByteBuffer response;
  call->Read(&response, nullptr);
  ASSERT_TRUE(Await(queue));
  call->WritesDone(nullptr);
  ASSERT_TRUE(Await(queue));
  grpc::Status status;
  call->Finish(&status, nullptr);
  ASSERT_TRUE(Await(queue));
  ASSERT_TRUE(status.ok()) << status.error_message();

  // The response lists service names as plain strings inside nested messages.
  grpc::Slice bytes;
  ASSERT_TRUE(response.DumpToSingleSlice(&bytes).ok());
  const std::string text(reinterpret_cast<const char*>(bytes.begin()), bytes.size());
  EXPECT_NE(text.find("inscribe.v1.Inscribe"), std::string::npos);
  EXPECT_NE(text.find("grpc.health.v1.Health"), std::string::npos);
}

}  // namespace
}  // namespace inscribe::server
