// The real server, in-process on a loopback port chosen by the kernel, called over gRPC.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <memory>

#include "grpc/health/v1/health.grpc.pb.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "inscribe/client/client.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "inscribe/wire/convert.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr std::int64_t kMaxTriangles = 1000;

class InscribeServerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.jobs = 2;
    options.limits.max_triangles = kMaxTriangles;
    absl::StatusOr<std::unique_ptr<InscribeServer>> started = InscribeServer::Start(options);
    ASSERT_TRUE(started.ok()) << started.status();
    server_ = started->release();
  }
  static void TearDownTestSuite() {
    delete server_;
    server_ = nullptr;
  }

  void SetUp() override {
    ASSERT_NE(server_, nullptr);
    channel_ = grpc::CreateChannel(server_->address(), grpc::InsecureChannelCredentials());
    stub_ = v1::Inscribe::NewStub(channel_);
  }

  // One InspectMesh call with a 30 s deadline; the response is written to *response.
  grpc::Status Inspect(const Mesh& mesh, v1::InspectMeshResponse* response) {
    v1::InspectMeshRequest request;
    wire::MeshToProto(mesh, request.mutable_mesh());
    return Inspect(request, response);
  }
  grpc::Status Inspect(const v1::InspectMeshRequest& request, v1::InspectMeshResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->InspectMesh(&context, request, response);
  }

  static InscribeServer* server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::Inscribe::Stub> stub_;
};

InscribeServer* InscribeServerTest::server_ = nullptr;

// The embedded service (the CLI's) runs with every limit at the int64 maximum; deriving the
// deformation's vertex limit from it must not overflow (UBSan found 3 x max once).
TEST(ServiceLimits, DeformVertexLimitIsThreeTimesTrianglesAndSaturates) {
  ServiceLimits limits;
  limits.max_triangles = 1000;
  EXPECT_EQ(limits.MaxDeformVertices(), 3000);
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  for (std::int64_t triangles : {kMax / 3, kMax / 3 + 1, kMax - 1, kMax}) {
    limits.max_triangles = triangles;
    EXPECT_EQ(limits.MaxDeformVertices(), triangles == kMax / 3 ? 3 * triangles : kMax)
        << triangles;
  }
}

TEST_F(InscribeServerTest, BindsTheLoopbackPortItPicked) {
  EXPECT_GT(server_->port(), 0);
  EXPECT_EQ(server_->address(), "127.0.0.1:" + std::to_string(server_->port()));
  EXPECT_EQ(server_->jobs(), 2);
}

TEST_F(InscribeServerTest, UnitCubeIsUsableWithItsHashAndVolume) {
  const Mesh cube = testing::UnitCube();
  v1::InspectMeshResponse response;
  const grpc::Status status = Inspect(cube, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  const v1::MeshReport& report = response.report();
  EXPECT_TRUE(report.usable());
  EXPECT_TRUE(report.closed());
  EXPECT_EQ(report.vertices(), 8);
  EXPECT_EQ(report.triangles(), 12);
  EXPECT_EQ(report.components(), 1);
  EXPECT_TRUE(report.self_intersections_checked());
  EXPECT_EQ(report.issues_size(), 0);
  EXPECT_DOUBLE_EQ(report.volume(), 1.0);
  EXPECT_THAT(report.bbox_min(), ::testing::ElementsAre(0.0, 0.0, 0.0));
  EXPECT_THAT(report.bbox_max(), ::testing::ElementsAre(1.0, 1.0, 1.0));
  EXPECT_EQ(response.mesh_sha256(), FormatSha256(MeshSha256(ValidateMesh(cube).mesh)));
  EXPECT_THAT(response.mesh_sha256(), StartsWith("sha256:"));
}

TEST_F(InscribeServerTest, InvertedCubeIsFixedAndHashedAfterTheFix) {
  const Mesh inverted = testing::Inverted(testing::UnitCube());
  v1::InspectMeshResponse response;
  const grpc::Status status = Inspect(inverted, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();

  const v1::MeshReport& report = response.report();
  EXPECT_TRUE(report.usable());
  EXPECT_EQ(report.flipped_triangles(), 12);
  ASSERT_EQ(report.issues_size(), 1);
  EXPECT_EQ(report.issues(0).code(), "orientation_fixed");
  EXPECT_EQ(report.issues(0).severity(), v1::MeshIssue::FIXED);
  EXPECT_EQ(report.issues(0).count(), 12);
  EXPECT_DOUBLE_EQ(report.volume(), 1.0);
  // The hash is of the repaired mesh: the same as validating locally gives.
  EXPECT_EQ(response.mesh_sha256(), FormatSha256(MeshSha256(ValidateMesh(inverted).mesh)));
  EXPECT_NE(response.mesh_sha256(), FormatSha256(MeshSha256(inverted)));
}

TEST_F(InscribeServerTest, OpenCubeIsNotUsableAndSaysWhy) {
  v1::InspectMeshResponse response;
  const grpc::Status status = Inspect(testing::OpenUnitCube(), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();  // a bad mesh is not a failed call

  const v1::MeshReport& report = response.report();
  EXPECT_FALSE(report.usable());
  EXPECT_FALSE(report.closed());
  EXPECT_EQ(report.border_edges(), 3);
  const auto not_closed =
      std::find_if(report.issues().begin(), report.issues().end(),
                   [](const v1::MeshIssue& issue) { return issue.code() == "not_closed"; });
  ASSERT_NE(not_closed, report.issues().end());
  EXPECT_EQ(not_closed->severity(), v1::MeshIssue::ERROR);
  EXPECT_EQ(not_closed->count(), 3);
}

TEST_F(InscribeServerTest, SkipSelfIntersectionsIsHonoured) {
  v1::InspectMeshRequest request;
  wire::MeshToProto(testing::UnitCube(), request.mutable_mesh());
  request.set_skip_self_intersections(true);
  v1::InspectMeshResponse response;
  ASSERT_TRUE(Inspect(request, &response).ok());
  EXPECT_FALSE(response.report().self_intersections_checked());
}

TEST_F(InscribeServerTest, MeshOverTriangleLimitIsResourceExhaustedNamingTheLimit) {
  Mesh big;
  big.vertices = testing::UnitCube().vertices;
  big.triangles.resize(kMaxTriangles + 1, 3);
  big.triangles.rowwise() = Eigen::RowVector3i(0, 1, 2);
  v1::InspectMeshResponse response;
  const grpc::Status status = Inspect(big, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_EQ(status.error_message(),
            "mesh has 1001 triangles; this server's limit "
            "(--max-triangles) is 1000");
}

TEST_F(InscribeServerTest, VerticesOfLengthSevenAreInvalidArgument) {
  v1::InspectMeshRequest request;
  for (int i = 0; i < 7; ++i) request.mutable_mesh()->add_vertices(0.5 * i);
  v1::InspectMeshResponse response;
  const grpc::Status status = Inspect(request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("mesh.vertices has length 7"));
}

TEST_F(InscribeServerTest, HealthIsServingForServerAndService) {
  auto health = grpc::health::v1::Health::NewStub(channel_);
  for (const char* service : {"", "inscribe.v1.Inscribe"}) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    grpc::health::v1::HealthCheckRequest request;
    request.set_service(service);
    grpc::health::v1::HealthCheckResponse response;
    const grpc::Status status = health->Check(&context, request, &response);
    ASSERT_TRUE(status.ok()) << service << ": " << status.error_message();
    EXPECT_EQ(response.status(), grpc::health::v1::HealthCheckResponse::SERVING) << service;
  }
}

TEST_F(InscribeServerTest, ClientLibraryOverGrpcReturnsCoreTypes) {
  client::Client client(client::MakeGrpcConnection(server_->address()));
  const Mesh cube = testing::Inverted(testing::UnitCube());
  absl::StatusOr<client::InspectMeshResult> result = client.InspectMesh(cube);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->mesh_sha256, FormatSha256(MeshSha256(ValidateMesh(cube).mesh)));
  EXPECT_TRUE(result->report.usable());
  EXPECT_DOUBLE_EQ(result->report.volume, 1.0);
  ASSERT_EQ(result->report.issues.size(), 1u);
  EXPECT_EQ(result->report.issues[0].severity, Severity::kFixed);

  absl::StatusOr<client::InspectMeshResult> big = client.InspectMesh([] {
    Mesh m;
    m.vertices = testing::UnitCube().vertices;
    m.triangles.setZero(kMaxTriangles + 1, 3);
    return m;
  }());
  EXPECT_EQ(big.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(big.status().message(), HasSubstr("--max-triangles"));
}

TEST(InscribeServerStart, AddressInUseIsUnavailable) {
  ServerOptions options;
  options.listen = "127.0.0.1:0";
  absl::StatusOr<std::unique_ptr<InscribeServer>> first = InscribeServer::Start(options);
  ASSERT_TRUE(first.ok()) << first.status();
  options.listen = (*first)->address();
  absl::StatusOr<std::unique_ptr<InscribeServer>> second = InscribeServer::Start(options);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(second.status().message(), HasSubstr(options.listen));
}

TEST(InscribeServerStart, RejectsOptionsOutOfRange) {
  ServerOptions options;
  options.listen = "no-port";
  EXPECT_EQ(InscribeServer::Start(options).status().code(), absl::StatusCode::kInvalidArgument);
  options.listen = "127.0.0.1:0";
  options.max_queue = 0;
  EXPECT_EQ(InscribeServer::Start(options).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inscribe::server
