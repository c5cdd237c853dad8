// The fixture of the loopback RPC tests: a real InscribeServer in-process on 127.0.0.1:0 with
// a disk cache in a temporary directory, a raw stub, and helpers for the common calls.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "inscribe/wire/convert.h"
#include "support/inscribed_process.h"

namespace inscribe::server {

class SpheresRpcTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_dir_ = std::filesystem::temp_directory_path() /
                 ("inscribe-rpc-" + std::to_string(std::random_device{}()));
    Restart();
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(cache_dir_);
  }

  // A fresh server process state (new memory tier) on the same cache directory.
  void Restart() {
    server_.reset();
    ServerOptions options;
    options.on_call = observer_;
    options.listen = "127.0.0.1:0";
    options.jobs = 2;
    options.max_queue = 64;
    options.cache.disk_dir = cache_dir_.string();
    options.limits.max_poses = 5000;
    if (configure_) configure_(options);
    absl::StatusOr<std::unique_ptr<InscribeServer>> started = InscribeServer::Start(options);
    ASSERT_TRUE(started.ok()) << started.status();
    server_ = *std::move(started);
    stub_ = v1::Inscribe::NewStub(
        grpc::CreateChannel(server_->address(), grpc::InsecureChannelCredentials()));
  }

  // A context whose deadline is `seconds` from now (longer under a sanitizer).
  std::unique_ptr<grpc::ClientContext> Context(double seconds = 60.0) {
    auto context = std::make_unique<grpc::ClientContext>();
    context->set_deadline(std::chrono::system_clock::now() +
                          testing::Stretched(std::chrono::duration<double>(seconds)));
    return context;
  }

  std::string PutMesh(const Mesh& mesh) {
    v1::PutMeshRequest request;
    wire::MeshToProto(mesh, request.mutable_mesh());
    v1::PutMeshResponse response;
    const grpc::Status status = stub_->PutMesh(Context().get(), request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.mesh_sha256();
  }

  // Runs Generate to its end; the last message's result, progress messages counted.
  grpc::Status Generate(const v1::GenerateRequest& request, v1::GenerateResult* result,
                        int* progress_messages = nullptr, double seconds = 60.0) {
    auto context = Context(seconds);
    std::unique_ptr<grpc::ClientReader<v1::GenerateResponse>> reader =
        stub_->Generate(context.get(), request);
    v1::GenerateResponse message;
    int progress = 0;
    while (reader->Read(&message)) {
      if (message.has_progress()) ++progress;
      if (message.has_result()) *result = message.result();
    }
    if (progress_messages != nullptr) *progress_messages = progress;
    return reader->Finish();
  }

  v1::GenerateRequest SphereRequest(const std::string& mesh_key, double voxel_size) {
    v1::GenerateRequest request;
    request.set_mesh_sha256(mesh_key);
    request.mutable_parameters()->set_voxel_size(voxel_size);
    return request;
  }

  v1::CacheStatsResponse Stats() {
    v1::CacheStatsResponse response;
    EXPECT_TRUE(stub_->CacheStats(Context().get(), v1::CacheStatsRequest(), &response).ok());
    return response;
  }

  // Set before Restart() to change the server's options or watch its calls.
  std::function<void(ServerOptions&)> configure_;
  CallObserver observer_;
  std::filesystem::path cache_dir_;
  std::unique_ptr<InscribeServer> server_;
  std::unique_ptr<v1::Inscribe::Stub> stub_;
};

}  // namespace inscribe::server
