// The fixture of the TLS and bearer-token tests: a real InscribeServer in-process on loopback,
// reached through raw stubs (to send exactly the metadata under test) and through the client
// library. The certificates are made once per suite with the openssl command line.
#pragma once

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "inscribe/client/connection.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "support/test_certificates.h"

namespace inscribe::server {

inline constexpr char kTokenA[] = "alpha-token-0123456789abcdef";
inline constexpr char kTokenB[] = "bravo-token-fedcba9876543210";

inline client::Deadline In(int seconds) {
  return std::chrono::system_clock::now() + std::chrono::seconds(seconds);
}

class SecurityTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    certs_ = new testing::TestCertificates(testing::MakeTestCertificates());
    tokens_file_ = WriteFile("tokens", std::string("# accepted tokens\n\n") + kTokenA + "\r\n  " +
                                           kTokenB + "  \n# " + "retired-token-000000000000\n");
  }
  static void TearDownTestSuite() {
    certs_->Remove();
    delete certs_;
  }
  void SetUp() override { ASSERT_TRUE(certs_->error.empty()) << certs_->error; }

  static std::string WriteFile(const std::string& name, const std::string& text) {
    return certs_->Write(name, text);
  }

  // A server on 127.0.0.1:0 (memory cache only) with `configure` applied; its calls are
  // recorded in calls_.
  absl::StatusOr<std::unique_ptr<InscribeServer>> Start(
      const std::function<void(ServerOptions&)>& configure) {
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.jobs = 2;
    options.on_call = [this](const CallRecord& call) {
      std::lock_guard<std::mutex> lock(calls_mutex_);
      calls_.emplace_back(call.method, call.status.code());
      calls_changed_.notify_all();
    };
    configure(options);
    return InscribeServer::Start(options);
  }

  static void WithTokens(ServerOptions& options) { options.auth_tokens_file = tokens_file_; }
  static void WithTls(ServerOptions& options) {
    options.tls.cert_file = certs_->server_cert;
    options.tls.key_file = certs_->server_key;
  }
  static void WithMutualTls(ServerOptions& options) {
    WithTls(options);
    options.tls.client_ca_file = certs_->ca;
  }

  // TLS channel credentials from the client library; fails the test on error.
  static std::shared_ptr<grpc::ChannelCredentials> Tls(const client::TlsFiles& files) {
    absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> credentials =
        client::MakeTlsCredentials(files);
    EXPECT_TRUE(credentials.ok()) << credentials.status();
    return credentials.ok() ? *credentials : grpc::InsecureChannelCredentials();
  }

  static std::unique_ptr<v1::Inscribe::Stub> Stub(
      const InscribeServer& server,
      std::shared_ptr<grpc::ChannelCredentials> credentials = grpc::InsecureChannelCredentials()) {
    return v1::Inscribe::NewStub(grpc::CreateChannel(server.address(), credentials));
  }

  // One CacheStats call carrying `authorization` (none when empty).
  static grpc::Status CacheStats(v1::Inscribe::Stub& stub, const std::string& authorization = "") {
    grpc::ClientContext context;
    context.set_deadline(In(20));
    if (!authorization.empty()) context.AddMetadata("authorization", authorization);
    v1::CacheStatsResponse response;
    return stub.CacheStats(&context, v1::CacheStatsRequest(), &response);
  }

  // Waits (up to 10 s: the streaming observer runs after the client has its status) until
  // `count` calls have been recorded; returns them.
  std::vector<std::pair<std::string, grpc::StatusCode>> WaitForCalls(std::size_t count) {
    std::unique_lock<std::mutex> lock(calls_mutex_);
    calls_changed_.wait_for(lock, std::chrono::seconds(10), [&] { return calls_.size() >= count; });
    std::vector<std::pair<std::string, grpc::StatusCode>> out;
    for (const auto& [method, code] : calls_) {
      out.emplace_back(method, static_cast<grpc::StatusCode>(code));
    }
    return out;
  }

  static inline testing::TestCertificates* certs_ = nullptr;
  static inline std::string tokens_file_;

  std::mutex calls_mutex_;
  std::condition_variable calls_changed_;
  std::vector<std::pair<std::string, absl::StatusCode>> calls_;  // guarded by calls_mutex_
};

}  // namespace inscribe::server
