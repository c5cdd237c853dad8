// TLS, mutual TLS and bearer tokens, end to end on loopback: a real InscribeServer in-process,
// reached through raw stubs (to send exactly the metadata under test) and through the client
// library (to check that its credentials and token reach the server); fixture in
// security_fixture.h.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "grpc/health/v1/health.grpc.pb.h"
#include "security_fixture.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// --- Bearer tokens -----------------------------------------------------------------------

TEST_F(SecurityTest, UnaryCallWithoutTokenIsUnauthenticated) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  const grpc::Status status = CacheStats(*Stub(**server));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("missing bearer token"));
}

TEST_F(SecurityTest, GenerateWithoutTokenIsUnauthenticatedBeforeAnyCheck) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  // With a token this request is NOT_FOUND (no such mesh): the refusal comes first.
  v1::GenerateRequest request;
  request.set_mesh_sha256("sha256:" + std::string(64, 'a'));
  request.mutable_parameters()->set_voxel_size(0.1);
  grpc::ClientContext context;
  context.set_deadline(In(20));
  auto reader = Stub(**server)->Generate(&context, request);
  v1::GenerateResponse message;
  EXPECT_FALSE(reader->Read(&message));
  const grpc::Status status = reader->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("missing bearer token"));
}

TEST_F(SecurityTest, DistanceStreamWithoutTokenIsUnauthenticated) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  grpc::ClientContext context;
  context.set_deadline(In(20));
  auto stream = Stub(**server)->DistanceStream(&context);
  v1::DistanceFrame frame;
  frame.set_frame(1);
  stream->Write(frame);  // may fail already: the server may have ended the call
  v1::DistanceFrameResult result;
  EXPECT_FALSE(stream->Read(&result));
  const grpc::Status status = stream->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("missing bearer token"));
}

TEST_F(SecurityTest, WrongTokenIsUnauthenticatedAndNeverEchoed) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  auto stub = Stub(**server);
  const std::string wrong = "wrong-token-but-long-enough-42";
  const std::string cases[] = {
      "Bearer " + wrong,
      "Bearer " + std::string(kTokenA) + "x",            // an accepted token plus more
      "Bearer " + std::string(kTokenA).substr(0, 20),    // a prefix of one
      "Bearer " + std::string(kTokenA) + " " + kTokenB,  // two at once
  };
  for (const std::string& authorization : cases) {
    const grpc::Status status = CacheStats(*stub, authorization);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << authorization;
    EXPECT_THAT(status.error_message(), HasSubstr("invalid bearer token")) << authorization;
    EXPECT_THAT(status.error_message(), Not(HasSubstr(wrong)));
    EXPECT_THAT(status.error_message(), Not(HasSubstr("token-0123")));
  }
  // Another scheme, or the scheme alone, is no bearer token at all.
  for (const std::string& authorization :
       {std::string("Basic ") + kTokenA, std::string("Bearer ")}) {
    const grpc::Status status = CacheStats(*stub, authorization);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << authorization;
    EXPECT_THAT(status.error_message(), HasSubstr("missing bearer token")) << authorization;
    EXPECT_THAT(status.error_message(), Not(HasSubstr(kTokenA)));
  }
}

TEST_F(SecurityTest, EachAcceptedTokenIsAdmittedOnEveryKindOfCall) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  for (const char* token : {kTokenA, kTokenB}) {
    client::ConnectionOptions options;
    options.bearer_token = token;
    std::shared_ptr<client::Connection> connection =
        client::MakeGrpcConnection((*server)->address(), options);
    EXPECT_TRUE(connection->CacheStats(v1::CacheStatsRequest(), In(20)).ok()) << token;

    v1::GenerateRequest request;
    request.set_mesh_sha256("sha256:" + std::string(64, 'b'));
    request.mutable_parameters()->set_voxel_size(0.1);
    EXPECT_EQ(connection->Generate(request, In(20), nullptr).status().code(),
              absl::StatusCode::kNotFound)
        << token;

    auto stream = connection->OpenDistanceStream(In(20));
    ASSERT_TRUE(stream.ok()) << stream.status();
    EXPECT_TRUE((*stream)->Finish().ok()) << token;
  }
  // The scheme is case-insensitive; spaces after it are allowed.
  auto stub = Stub(**server);
  EXPECT_TRUE(CacheStats(*stub, std::string("bearer ") + kTokenA).ok());
  EXPECT_TRUE(CacheStats(*stub, std::string("BEARER   ") + kTokenB).ok());
}

TEST_F(SecurityTest, ObserverSeesRefusedCallsWithMethodAndCode) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  client::ConnectionOptions options;
  options.bearer_token = "not-an-accepted-token-123";
  std::shared_ptr<client::Connection> connection =
      client::MakeGrpcConnection((*server)->address(), options);
  EXPECT_EQ(connection->CacheStats(v1::CacheStatsRequest(), In(20)).status().code(),
            absl::StatusCode::kUnauthenticated);
  v1::GenerateRequest request;
  request.set_mesh_sha256("sha256:" + std::string(64, 'c'));
  EXPECT_EQ(connection->Generate(request, In(20), nullptr).status().code(),
            absl::StatusCode::kUnauthenticated);
  auto stream = connection->OpenDistanceStream(In(20));
  ASSERT_TRUE(stream.ok());
  EXPECT_EQ((*stream)->Finish().code(), absl::StatusCode::kUnauthenticated);

  const auto calls = WaitForCalls(3);
  EXPECT_THAT(calls, ::testing::UnorderedElementsAre(
                         std::make_pair(std::string("CacheStats"), grpc::UNAUTHENTICATED),
                         std::make_pair(std::string("Generate"), grpc::UNAUTHENTICATED),
                         std::make_pair(std::string("DistanceStream"), grpc::UNAUTHENTICATED)));
}

TEST_F(SecurityTest, ConcurrentCallersAreEachJudgedOnTheirOwnToken) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  auto stub = Stub(**server);  // one channel shared by all threads, as clients do
  constexpr int kThreads = 4;
  constexpr int kCalls = 25;
  std::vector<int> wrong_answers(kThreads, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kCalls; ++i) {
        const int kind = (t + i) % 3;  // 0: token A, 1: token B, 2: a wrong one
        const std::string token = kind == 0 ? kTokenA : kind == 1 ? kTokenB : "wrong-token-abcdef";
        const grpc::Status status = CacheStats(*stub, "Bearer " + token);
        const bool expected =
            kind == 2 ? status.error_code() == grpc::UNAUTHENTICATED : status.ok();
        if (!expected) ++wrong_answers[t];
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(wrong_answers[t], 0) << "thread " << t;
}

TEST_F(SecurityTest, HealthNeedsNoToken) {
  auto server = Start(WithTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  auto health = grpc::health::v1::Health::NewStub(
      grpc::CreateChannel((*server)->address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(In(20));
  grpc::health::v1::HealthCheckRequest request;
  request.set_service("inscribe.v1.Inscribe");
  grpc::health::v1::HealthCheckResponse response;
  const grpc::Status status = health->Check(&context, request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.status(), grpc::health::v1::HealthCheckResponse::SERVING);
}

TEST_F(SecurityTest, BadTokenFilesFailStartNamingTheFile) {
  const std::string comments = WriteFile("comments-only", "# nothing yet\n\n   \n#x\n");
  auto empty = Start([&](ServerOptions& o) { o.auth_tokens_file = comments; });
  EXPECT_EQ(empty.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(empty.status().message(), HasSubstr(comments));
  EXPECT_THAT(empty.status().message(), HasSubstr("holds no token"));

  const std::string short_file = WriteFile("short", "# ok\nshort-secret\n");
  auto too_short = Start([&](ServerOptions& o) { o.auth_tokens_file = short_file; });
  EXPECT_EQ(too_short.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(too_short.status().message(), HasSubstr("line 2"));
  EXPECT_THAT(too_short.status().message(), Not(HasSubstr("short-secret")));

  const std::string spaced = WriteFile("spaced", "a token with spaces in the middle\n");
  auto with_space = Start([&](ServerOptions& o) { o.auth_tokens_file = spaced; });
  EXPECT_EQ(with_space.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(with_space.status().message(), Not(HasSubstr("spaces in")));

  const std::string missing = (certs_->dir / "no-such-file").string();
  auto unreadable = Start([&](ServerOptions& o) { o.auth_tokens_file = missing; });
  EXPECT_EQ(unreadable.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(unreadable.status().message(), HasSubstr(missing));
}

// --- TLS ---------------------------------------------------------------------------------

TEST_F(SecurityTest, TlsClientTrustingTheCaIsServed) {
  auto server = Start(WithTls);
  ASSERT_TRUE(server.ok()) << server.status();
  const grpc::Status status = CacheStats(*Stub(**server, Tls({certs_->ca, "", ""})));
  EXPECT_TRUE(status.ok()) << status.error_message();
}

TEST_F(SecurityTest, PlaintextClientCannotTalkToTlsServer) {
  auto server = Start(WithTls);
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_EQ(CacheStats(*Stub(**server)).error_code(), grpc::StatusCode::UNAVAILABLE);
}

TEST_F(SecurityTest, TlsClientCannotTalkToPlaintextServer) {
  auto server = Start([](ServerOptions&) {});
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_EQ(CacheStats(*Stub(**server, Tls({certs_->ca, "", ""}))).error_code(),
            grpc::StatusCode::UNAVAILABLE);
}

TEST_F(SecurityTest, TlsClientTrustingAnotherCaRefusesTheServer) {
  auto server = Start(WithTls);
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_EQ(CacheStats(*Stub(**server, Tls({certs_->rogue_ca, "", ""}))).error_code(),
            grpc::StatusCode::UNAVAILABLE);
}

TEST_F(SecurityTest, BadTlsFilesFailStartNamingTheFile) {
  auto cert_only = Start([](ServerOptions& o) { o.tls.cert_file = certs_->server_cert; });
  EXPECT_EQ(cert_only.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(cert_only.status().message(), HasSubstr("--tls-key"));

  auto ca_only = Start([](ServerOptions& o) { o.tls.client_ca_file = certs_->ca; });
  EXPECT_EQ(ca_only.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(ca_only.status().message(), HasSubstr("--tls-client-ca"));

  const std::string missing = (certs_->dir / "missing.pem").string();
  auto unreadable = Start([&](ServerOptions& o) {
    WithTls(o);
    o.tls.cert_file = missing;
  });
  EXPECT_EQ(unreadable.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(unreadable.status().message(), HasSubstr(missing));

  const std::string not_pem = WriteFile("not.pem", "just some text\n");
  auto key_not_pem = Start([&](ServerOptions& o) {
    WithTls(o);
    o.tls.key_file = not_pem;
  });
  EXPECT_EQ(key_not_pem.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(key_not_pem.status().message(), HasSubstr(not_pem));
  auto ca_not_pem = Start([&](ServerOptions& o) {
    WithTls(o);
    o.tls.client_ca_file = not_pem;
  });
  EXPECT_EQ(ca_not_pem.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(ca_not_pem.status().message(), HasSubstr(not_pem));

  auto key_swapped = Start([](ServerOptions& o) {
    WithTls(o);
    o.tls.key_file = certs_->server_cert;  // a certificate where the key belongs
  });
  EXPECT_EQ(key_swapped.status().code(), absl::StatusCode::kInvalidArgument);

  auto wrong_key = Start([](ServerOptions& o) {
    WithTls(o);
    o.tls.key_file = certs_->client_key;
  });
  EXPECT_EQ(wrong_key.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(wrong_key.status().message(), HasSubstr("is not the key of"));
}

// --- Mutual TLS --------------------------------------------------------------------------

TEST_F(SecurityTest, MutualTlsRefusesClientWithoutCertificate) {
  auto server = Start(WithMutualTls);
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_EQ(CacheStats(*Stub(**server, Tls({certs_->ca, "", ""}))).error_code(),
            grpc::StatusCode::UNAVAILABLE);
}

TEST_F(SecurityTest, MutualTlsRefusesCertificateFromAnotherCa) {
  auto server = Start(WithMutualTls);
  ASSERT_TRUE(server.ok()) << server.status();
  const grpc::Status status =
      CacheStats(*Stub(**server, Tls({certs_->ca, certs_->rogue_cert, certs_->rogue_key})));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE) << status.error_message();
}

TEST_F(SecurityTest, MutualTlsServesCertificateFromTheCa) {
  auto server = Start(WithMutualTls);
  ASSERT_TRUE(server.ok()) << server.status();
  const grpc::Status status =
      CacheStats(*Stub(**server, Tls({certs_->ca, certs_->client_cert, certs_->client_key})));
  EXPECT_TRUE(status.ok()) << status.error_message();
}

TEST_F(SecurityTest, MutualTlsAndTokensTogether) {
  auto server = Start([](ServerOptions& o) {
    WithMutualTls(o);
    WithTokens(o);
  });
  ASSERT_TRUE(server.ok()) << server.status();
  auto stub = Stub(**server, Tls({certs_->ca, certs_->client_cert, certs_->client_key}));
  EXPECT_EQ(CacheStats(*stub).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(CacheStats(*stub, std::string("Bearer ") + kTokenB).ok());
}

}  // namespace
}  // namespace inscribe::server
