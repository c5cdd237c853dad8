// InscribeServer::Reload (inscribed's SIGHUP) on loopback: the token file and the TLS files are
// read again while serving; what fails to read or check keeps the old set in use, and calls
// and connections already open are not touched. The signal itself: inscribed_test.cpp.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <string>
#include <thread>

#include "grpc/impl/codegen/grpc_types.h"
#include "grpcpp/support/channel_arguments.h"
#include "security_fixture.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The fixture's PKI (certs_) plus a second, unrelated one (next_): a new CA, with a server
// certificate of its own, as a rotation would bring.
class ReloadTest : public SecurityTest {
 protected:
  static void SetUpTestSuite() {
    SecurityTest::SetUpTestSuite();
    next_ = new testing::TestCertificates(testing::MakeTestCertificates());
  }
  static void TearDownTestSuite() {
    next_->Remove();
    delete next_;
    SecurityTest::TearDownTestSuite();
  }
  void SetUp() override {
    SecurityTest::SetUp();
    ASSERT_TRUE(next_->error.empty()) << next_->error;
  }

  static std::string Read(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  // Files in the fixture's directory that the server is started on and the test then rewrites,
  // as an operator rotating certificates in place would.
  static void ServeFromLiveFiles(ServerOptions& options) {
    options.tls.cert_file = WriteFile("live-cert.pem", Read(certs_->server_cert));
    options.tls.key_file = WriteFile("live-key.pem", Read(certs_->server_key));
  }
  static void PutLivePair(const testing::TestCertificates& pki) {
    WriteFile("live-cert.pem", Read(pki.server_cert));
    WriteFile("live-key.pem", Read(pki.server_key));
  }

  // Whether one CacheStats call over a new connection with TLS `files` (trusting files.ca) and
  // `authorization` (none when empty) succeeds.
  static bool ServedTo(const InscribeServer& server, const client::TlsFiles& files,
                       const std::string& authorization = "") {
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_USE_LOCAL_SUBCHANNEL_POOL, 1);  // a connection of its own
    auto stub =
        v1::Inscribe::NewStub(grpc::CreateCustomChannel(server.address(), Tls(files), args));
    grpc::ClientContext context;
    context.set_deadline(In(10));
    if (!authorization.empty()) context.AddMetadata("authorization", authorization);
    v1::CacheStatsResponse response;
    return stub->CacheStats(&context, v1::CacheStatsRequest(), &response).ok();
  }
  static bool ServedToClientTrusting(const InscribeServer& server, const std::string& ca) {
    return ServedTo(server, {ca, "", ""});
  }

  // Polls (generously: gRPC picks published files up within kTlsRefreshSeconds = 1 s) until a
  // new client with `files` is served; false if it never is within 30 s.
  static bool EventuallyServedTo(const InscribeServer& server, const client::TlsFiles& files,
                                 const std::string& authorization = "") {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!ServedTo(server, files, authorization)) {
      if (std::chrono::steady_clock::now() > give_up) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return true;
  }
  static bool EventuallyServedToClientTrusting(const InscribeServer& server,
                                               const std::string& ca) {
    return EventuallyServedTo(server, {ca, "", ""});
  }

  static void WriteTokens(const std::string& text) { WriteFile("reload-tokens", text); }
  static void WithReloadTokens(ServerOptions& options) {
    options.auth_tokens_file = WriteFile("reload-tokens", std::string(kTokenA) + "\n");
  }

  static inline testing::TestCertificates* next_ = nullptr;
};

const std::string kBearerA = std::string("Bearer ") + kTokenA;
const std::string kBearerB = std::string("Bearer ") + kTokenB;

// --- Bearer tokens -----------------------------------------------------------------------

TEST_F(ReloadTest, TokenAddedToTheFileIsAcceptedOnlyAfterReload) {
  auto server = Start(WithReloadTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  auto stub = Stub(**server);
  EXPECT_EQ(CacheStats(*stub, kBearerB).error_code(), grpc::StatusCode::UNAUTHENTICATED);

  WriteTokens(std::string(kTokenA) + "\n" + kTokenB + "\n");
  EXPECT_EQ(CacheStats(*stub, kBearerB).error_code(), grpc::StatusCode::UNAUTHENTICATED)
      << "the file is read on Reload, not watched";
  const ReloadResult result = (*server)->Reload();
  ASSERT_TRUE(result.tokens.has_value());
  EXPECT_TRUE(result.tokens->ok()) << *result.tokens;
  EXPECT_FALSE(result.tls.has_value());  // plaintext: nothing to reload
  EXPECT_TRUE(CacheStats(*stub, kBearerB).ok());
  EXPECT_TRUE(CacheStats(*stub, kBearerA).ok());
}

TEST_F(ReloadTest, TokenRemovedFromTheFileIsRefusedAfterReload) {
  auto server = Start(WithReloadTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  WriteTokens(std::string(kTokenA) + "\n" + kTokenB + "\n");
  ASSERT_TRUE((*server)->Reload().tokens->ok());
  auto stub = Stub(**server);
  ASSERT_TRUE(CacheStats(*stub, kBearerA).ok());

  WriteTokens(std::string("# A retired\n") + kTokenB + "\n");
  ASSERT_TRUE((*server)->Reload().tokens->ok());
  const grpc::Status refused = CacheStats(*stub, kBearerA);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(refused.error_message(), HasSubstr("invalid bearer token"));
  EXPECT_TRUE(CacheStats(*stub, kBearerB).ok());
}

TEST_F(ReloadTest, BadTokenFileKeepsTheAcceptedTokens) {
  auto server = Start(WithReloadTokens);
  ASSERT_TRUE(server.ok()) << server.status();
  auto stub = Stub(**server);
  struct Case {
    std::string text;  // empty: the file is removed
    absl::StatusCode code;
    const char* says;
  };
  const Case cases[] = {
      // B is well formed, but a file with a bad line is refused whole.
      {std::string(kTokenB) + "\nshort-token\n", absl::StatusCode::kInvalidArgument, "line 2"},
      {"# everything retired\n", absl::StatusCode::kInvalidArgument, "holds no token"},
      {"", absl::StatusCode::kFailedPrecondition, "cannot read"},
  };
  for (const Case& c : cases) {
    const std::string path = WriteFile("reload-tokens", c.text);
    if (c.text.empty()) std::filesystem::remove(path);
    const ReloadResult result = (*server)->Reload();
    ASSERT_TRUE(result.tokens.has_value());
    EXPECT_EQ(result.tokens->code(), c.code) << c.says;
    EXPECT_THAT(result.tokens->message(), HasSubstr(c.says));
    EXPECT_THAT(result.tokens->message(), HasSubstr(path));
    EXPECT_THAT(result.tokens->message(), Not(HasSubstr(kTokenB)));
    // Neither open to everyone nor locked out: the old set is still the one in use.
    EXPECT_TRUE(CacheStats(*stub, kBearerA).ok()) << c.says;
    EXPECT_EQ(CacheStats(*stub, kBearerB).error_code(), grpc::StatusCode::UNAUTHENTICATED);
    EXPECT_EQ(CacheStats(*stub).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
}

// --- TLS ---------------------------------------------------------------------------------

TEST_F(ReloadTest, NewCertificatePairServesNewClientsAfterReload) {
  auto server = Start(ServeFromLiveFiles);
  ASSERT_TRUE(server.ok()) << server.status();
  ASSERT_TRUE(ServedToClientTrusting(**server, certs_->ca));
  ASSERT_FALSE(ServedToClientTrusting(**server, next_->ca));

  PutLivePair(*next_);
  const ReloadResult result = (*server)->Reload();
  ASSERT_TRUE(result.tls.has_value());
  EXPECT_TRUE(result.tls->ok()) << *result.tls;
  EXPECT_FALSE(result.tokens.has_value());
  EXPECT_TRUE(EventuallyServedToClientTrusting(**server, next_->ca));
  // Once the new pair is served, the old one is not.
  EXPECT_FALSE(ServedToClientTrusting(**server, certs_->ca));

  // And back again: every reload publishes.
  PutLivePair(*certs_);
  ASSERT_TRUE((*server)->Reload().tls->ok());
  EXPECT_TRUE(EventuallyServedToClientTrusting(**server, certs_->ca));
}

TEST_F(ReloadTest, BadCertificatePairKeepsTheOldPairServing) {
  auto server = Start(ServeFromLiveFiles);
  ASSERT_TRUE(server.ok()) << server.status();
  ASSERT_TRUE(ServedToClientTrusting(**server, certs_->ca));
  struct Case {
    std::string cert;  // empty: the file is removed
    std::string key;
    absl::StatusCode code;
    const char* says;
  };
  const Case cases[] = {
      // The new certificate with the old key: mid-rotation, one file copied and not the other.
      {Read(next_->server_cert), Read(certs_->server_key), absl::StatusCode::kInvalidArgument,
       "is not the key of"},
      {Read(next_->server_cert), "-----BEGIN PRIVATE KEY-----\ntruncat",
       absl::StatusCode::kInvalidArgument, "holds no unencrypted PEM private key"},
      {"", Read(next_->server_key), absl::StatusCode::kFailedPrecondition, "cannot read"},
  };
  for (const Case& c : cases) {
    const std::string cert = WriteFile("live-cert.pem", c.cert);
    if (c.cert.empty()) std::filesystem::remove(cert);
    WriteFile("live-key.pem", c.key);
    const ReloadResult result = (*server)->Reload();
    ASSERT_TRUE(result.tls.has_value());
    EXPECT_EQ(result.tls->code(), c.code) << c.says;
    EXPECT_THAT(result.tls->message(), HasSubstr(c.says));
  }
  // Longer than gRPC takes to pick up published files (kTlsRefreshSeconds): nothing was.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  EXPECT_TRUE(ServedToClientTrusting(**server, certs_->ca));
  EXPECT_FALSE(ServedToClientTrusting(**server, next_->ca));
}

TEST_F(ReloadTest, NewClientCaDecidesWhichClientCertificatesAreAccepted) {
  auto server = Start([](ServerOptions& options) {
    ServeFromLiveFiles(options);
    options.tls.client_ca_file = WriteFile("live-client-ca.pem", Read(certs_->ca));
  });
  ASSERT_TRUE(server.ok()) << server.status();
  const auto client_of = [](const testing::TestCertificates& pki) {
    return client::TlsFiles{certs_->ca, pki.client_cert, pki.client_key};
  };
  ASSERT_TRUE(ServedTo(**server, client_of(*certs_)));
  ASSERT_FALSE(ServedTo(**server, client_of(*next_)));

  WriteFile("live-client-ca.pem", Read(next_->ca));
  ASSERT_TRUE((*server)->Reload().tls->ok());
  EXPECT_TRUE(EventuallyServedTo(**server, client_of(*next_)));
  EXPECT_FALSE(ServedTo(**server, client_of(*certs_)));
}

// A server killed before its destructor ran leaves its private directory, with a copy of its
// key; the next server to start removes it, but never one whose lock is held.
TEST_F(ReloadTest, StartRemovesPrivateDirectoriesOfKilledServersOnly) {
  const std::filesystem::path temp = std::filesystem::temp_directory_path();
  const std::string id = std::to_string(std::random_device{}());
  const std::filesystem::path abandoned = temp / ("inscribed-tls-test-abandoned-" + id);
  const std::filesystem::path held = temp / ("inscribed-tls-test-held-" + id);
  for (const std::filesystem::path& dir : {abandoned, held}) {
    std::filesystem::create_directories(dir / "g1");
    std::ofstream(dir / "g1" / "key.pem") << Read(certs_->server_key);
    std::ofstream(dir / "lock") << "";
  }
  const int lock = open((held / "lock").c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(lock, 0);
  ASSERT_EQ(flock(lock, LOCK_EX | LOCK_NB), 0);

  auto server = Start(WithTls);
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_FALSE(std::filesystem::exists(abandoned));
  EXPECT_TRUE(std::filesystem::exists(held / "g1" / "key.pem"));
  close(lock);
  std::filesystem::remove_all(held);
}

// --- Calls in flight ---------------------------------------------------------------------

// A DistanceStream opened with token A over the old certificate runs on after A is retired and
// the certificate replaced: admission and the handshake happened when it opened.
TEST_F(ReloadTest, OpenStreamSurvivesReloadAndKeepsWorking) {
  auto server = Start([](ServerOptions& options) {
    ServeFromLiveFiles(options);
    WithReloadTokens(options);
  });
  ASSERT_TRUE(server.ok()) << server.status();
  auto stub = Stub(**server, Tls({certs_->ca, "", ""}));

  // One unit sphere at the origin; the frames ask for its distance to itself moved along x.
  v1::PutSphereSetRequest put;
  put.mutable_spheres()->add_centers(0);
  put.mutable_spheres()->add_centers(0);
  put.mutable_spheres()->add_centers(0);
  put.mutable_spheres()->add_radii(1);
  v1::PutSphereSetResponse stored;
  {
    grpc::ClientContext context;
    context.set_deadline(In(20));
    context.AddMetadata("authorization", kBearerA);
    const grpc::Status status = stub->PutSphereSet(&context, put, &stored);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  const auto frame_at = [&](int frame, double x) {
    v1::DistanceFrame request;
    request.set_frame(frame);
    v1::DistancePair* pair = request.add_pairs();
    pair->set_sphere_set_a(stored.sphere_set_key());
    pair->set_sphere_set_b(stored.sphere_set_key());
    pair->mutable_pose_a()->set_qw(1);
    pair->mutable_pose_b()->set_qw(1);
    pair->mutable_pose_b()->set_tx(x);
    return request;
  };

  grpc::ClientContext context;
  context.set_deadline(In(60));
  context.AddMetadata("authorization", kBearerA);
  auto stream = stub->DistanceStream(&context);
  v1::DistanceFrameResult result;
  ASSERT_TRUE(stream->Write(frame_at(1, 5.0)));
  ASSERT_TRUE(stream->Read(&result));
  ASSERT_EQ(result.results().distances_size(), 1);
  EXPECT_NEAR(result.results().distances(0), 3.0, 1e-9);

  WriteTokens(std::string(kTokenB) + "\n");
  PutLivePair(*next_);
  const ReloadResult reloaded = (*server)->Reload();
  ASSERT_TRUE(reloaded.tokens.has_value() && reloaded.tokens->ok());
  ASSERT_TRUE(reloaded.tls.has_value() && reloaded.tls->ok());
  ASSERT_TRUE(EventuallyServedTo(**server, {next_->ca, "", ""}, kBearerB));
  // A new call with A is refused now...
  EXPECT_EQ(CacheStats(*Stub(**server, Tls({next_->ca, "", ""})), kBearerA).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);

  // ... while the stream opened with it goes on, on its old connection.
  for (int frame = 2; frame <= 4; ++frame) {
    ASSERT_TRUE(stream->Write(frame_at(frame, 2.0 + frame)));
    ASSERT_TRUE(stream->Read(&result)) << frame;
    EXPECT_EQ(result.frame(), frame);
    ASSERT_EQ(result.results().distances_size(), 1);
    EXPECT_NEAR(result.results().distances(0), frame, 1e-9);
  }
  stream->WritesDone();
  const grpc::Status finished = stream->Finish();
  EXPECT_TRUE(finished.ok()) << finished.error_message();
}

}  // namespace
}  // namespace inscribe::server
