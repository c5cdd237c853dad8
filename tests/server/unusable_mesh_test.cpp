// One unusable mesh, every path a mesh reaches the service by: PutMesh on the raw stub, the
// Client's PutMesh and Generate(mesh) (which uploads it), and, for non-finite coordinates, a
// frame of UpdateDeformation. Each refuses it with the same code, FAILED_PRECONDITION, and a
// message naming the problem; InspectMesh, which is never refused for the mesh's own problems,
// reports that problem as its first error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "inscribe/client/client.h"
#include "inscribe/client/connection.h"
#include "spheres_rpc_fixture.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

struct UnusableMesh {
  const char* name;
  Mesh mesh;
  const char* problem;  // what every refusal's message must name
};

class UnusableMeshTest : public SpheresRpcTest {
 protected:
  void SetUp() override {
    SpheresRpcTest::SetUp();
    client_ = std::make_unique<client::Client>(client::MakeGrpcConnection(server_->address()));
  }

  // The refusal of every upload path for `bad`, each expected FAILED_PRECONDITION naming the
  // problem, and the report's first error, which is what they all say.
  void ExpectRefusedEverywhere(const UnusableMesh& bad) {
    SCOPED_TRACE(bad.name);
    v1::InspectMeshRequest inspect;
    wire::MeshToProto(bad.mesh, inspect.mutable_mesh());
    v1::InspectMeshResponse inspected;
    const grpc::Status reported = stub_->InspectMesh(Context().get(), inspect, &inspected);
    ASSERT_TRUE(reported.ok()) << reported.error_message();
    EXPECT_FALSE(inspected.report().usable());
    std::string first_error;
    for (const v1::MeshIssue& issue : inspected.report().issues()) {
      if (issue.severity() == v1::MeshIssue::ERROR) {
        first_error = issue.message();
        break;
      }
    }
    EXPECT_THAT(first_error, HasSubstr(bad.problem));

    v1::PutMeshRequest put;
    wire::MeshToProto(bad.mesh, put.mutable_mesh());
    v1::PutMeshResponse stored;
    const grpc::Status raw = stub_->PutMesh(Context().get(), put, &stored);
    EXPECT_EQ(raw.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << raw.error_message();
    EXPECT_EQ(raw.error_message(), first_error);

    const absl::Status through_client = client_->PutMesh(bad.mesh).status();
    EXPECT_EQ(through_client.code(), absl::StatusCode::kFailedPrecondition) << through_client;
    EXPECT_THAT(through_client.message(), HasSubstr(bad.problem));

    client::GenerateSettings settings;
    settings.parameters.voxel_size = 0.1;
    const absl::Status generated = client_->Generate(bad.mesh, settings).status();
    EXPECT_EQ(generated.code(), absl::StatusCode::kFailedPrecondition) << generated;
    EXPECT_THAT(generated.message(), HasSubstr(bad.problem));
  }

  std::unique_ptr<client::Client> client_;
};

TEST_F(UnusableMeshTest, AnOpenBoxIsFailedPreconditionNamingItsBorderOnEveryPath) {
  ExpectRefusedEverywhere({"open box", testing::OpenUnitCube(), "not closed"});
}

TEST_F(UnusableMeshTest, NonFiniteCoordinatesAreFailedPreconditionOnEveryPath) {
  Mesh with_nan = testing::UnitCube();
  with_nan.vertices(6, 2) = std::numeric_limits<double>::quiet_NaN();
  ExpectRefusedEverywhere({"NaN vertex", with_nan, "non-finite"});

  // The same cube with the same NaN, sent as a deformed frame of the stored cube.
  const Mesh cube = testing::UnitCube();
  v1::GenerateResult set;
  v1::GenerateRequest generate = SphereRequest(PutMesh(cube), 0.25);
  generate.set_skip_quality(true);
  ASSERT_TRUE(Generate(generate, &set).ok());
  v1::UpdateDeformationRequest frame;
  frame.set_sphere_set_key(set.sphere_set_key());
  for (int v = 0; v < with_nan.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) frame.add_vertices(with_nan.vertices(v, k));
  }
  v1::UpdateDeformationResponse moved;
  const grpc::Status refused = stub_->UpdateDeformation(Context().get(), frame, &moved);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << refused.error_message();
  EXPECT_THAT(refused.error_message(), AllOf(HasSubstr("non-finite"), HasSubstr("vertex 6")));
}

}  // namespace
}  // namespace inscribe::server
