// Covers through the service: Generate with cover, and the Client's typed view of it, against
// the real server in-process on loopback (disk cache in a temporary directory).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "inscribe/client/client.h"
#include "inscribe/cover_certificate.h"
#include "inscribe/solid.h"
#include "spheres_rpc_fixture.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

class CoverRpcTest : public SpheresRpcTest {
 protected:
  std::unique_ptr<client::Client> MakeClient() {
    return std::make_unique<client::Client>(client::MakeGrpcConnection(server_->address()));
  }

  static v1::GenerateRequest CoverRequest(const std::string& mesh_key, std::int64_t max_spheres) {
    v1::GenerateRequest request;
    request.set_mesh_sha256(mesh_key);
    request.mutable_parameters()->set_max_spheres(max_spheres);
    request.mutable_parameters()->set_cover(true);
    request.set_skip_quality(true);
    return request;
  }
};

const Mesh& Slab() {
  static const Mesh slab = testing::Box(Vector3::Zero(), Vector3(2.0, 1.0, 0.5));
  return slab;
}

// A generated cover carries its certificate through the cache (memory, then disk after a
// restart), under a key of its own; the certificate is the one core proves for that set.
TEST_F(CoverRpcTest, GenerateMakesACertifiedCoverAndCachesItsCertificate) {
  const std::string mesh = PutMesh(Slab());
  v1::GenerateResult cover, again, restarted, internal;
  ASSERT_TRUE(Generate(CoverRequest(mesh, 30), &cover).ok());
  EXPECT_EQ(cover.cache(), "computed");
  EXPECT_EQ(cover.kind(), v1::SPHERE_SET_KIND_COVER);
  ASSERT_TRUE(cover.has_cover());
  const v1::CoverCertificate& certificate = cover.cover().certificate();
  EXPECT_TRUE(certificate.certified());
  EXPECT_GE(certificate.delta(), 0.0);
  EXPECT_EQ(certificate.failed_cells(), 0);
  EXPECT_EQ(cover.spheres().contact_triangles_size(), 0);
  EXPECT_FALSE(cover.has_quality());

  // Core agrees: the set is a cover with this delta.
  absl::StatusOr<SphereSet> spheres = wire::SphereSetFromProto(cover.spheres());
  ASSERT_TRUE(spheres.ok()) << spheres.status();
  absl::StatusOr<Solid> solid = PrepareSolid(Slab());
  ASSERT_TRUE(solid.ok()) << solid.status();
  absl::StatusOr<CoverCertificate> core = CertifyCover(*solid, spheres->spheres);
  ASSERT_TRUE(core.ok()) << core.status();
  EXPECT_TRUE(core->certified);
  EXPECT_EQ(core->delta, certificate.delta());

  ASSERT_TRUE(Generate(CoverRequest(mesh, 30), &again).ok());
  EXPECT_EQ(again.cache(), "memory");
  EXPECT_EQ(again.cover().SerializeAsString(), cover.cover().SerializeAsString());
  Restart();
  ASSERT_TRUE(Generate(CoverRequest(mesh, 30), &restarted).ok());
  EXPECT_EQ(restarted.cache(), "disk");
  EXPECT_EQ(restarted.kind(), v1::SPHERE_SET_KIND_COVER);
  EXPECT_EQ(restarted.cover().SerializeAsString(), cover.cover().SerializeAsString());

  v1::GenerateRequest plain = CoverRequest(mesh, 30);
  plain.mutable_parameters()->set_cover(false);
  ASSERT_TRUE(Generate(plain, &internal).ok());
  EXPECT_EQ(internal.kind(), v1::SPHERE_SET_KIND_INTERNAL);
  EXPECT_FALSE(internal.has_cover());
  EXPECT_NE(internal.sphere_set_key(), cover.sphere_set_key());
}

TEST_F(CoverRpcTest, ClientGeneratesACoverAndTheServerRefusesBadCombinations) {
  const std::unique_ptr<client::Client> client = MakeClient();
  client::GenerateSettings settings;
  settings.parameters.kind = SphereSetKind::kCover;
  settings.parameters.max_spheres = 30;
  absl::StatusOr<client::GenerateResult> generated = client->Generate(Slab(), settings);
  ASSERT_TRUE(generated.ok()) << generated.status();
  EXPECT_EQ(generated->kind, SphereSetKind::kCover);
  ASSERT_TRUE(generated->cover.has_value());
  EXPECT_TRUE(generated->cover->certificate.certified);
  EXPECT_LE(generated->set.size(), 30u);
  ASSERT_TRUE(generated->quality.has_value());
  EXPECT_EQ(generated->quality->coverage, 1.0);

  // The raw request with the same settings names the same cached set.
  v1::GenerateResult raw;
  v1::GenerateRequest request = CoverRequest(generated->mesh_sha256, 30);
  request.set_skip_quality(false);
  ASSERT_TRUE(Generate(request, &raw).ok());
  EXPECT_EQ(raw.sphere_set_key(), generated->sphere_set_key);
  EXPECT_EQ(raw.cache(), "memory");

  // The client refuses what core refuses, before sending.
  settings.parameters.max_protrusion = 0.1;
  absl::StatusOr<client::GenerateResult> both = client->Generate(Slab(), settings);
  EXPECT_EQ(both.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(both.status().message(), HasSubstr("not both"));
  // The server refuses what the wire can say but core cannot.
  request.mutable_parameters()->set_dilate(true);
  grpc::Status refused = Generate(request, &raw);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("dilate and cover"));
  request.mutable_parameters()->set_dilate(false);
  request.mutable_parameters()->set_cover_resolution(2.0);
  refused = Generate(request, &raw);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("resolution"));
}

}  // namespace
}  // namespace inscribe::server
