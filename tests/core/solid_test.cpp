// PrepareSolid and its one inside-test rule, the one SHA-256 and the one sphere check.
#include "inscribe/solid.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "inscribe/mesh_hash.h"
#include "inscribe/sha256.h"
#include "inscribe/sphere.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;

TEST(Solid, IsTheValidatedMeshWithItsHashAndOracle) {
  const Mesh inverted = testing::Inverted(testing::UnitCube());
  absl::StatusOr<Solid> solid = PrepareSolid(inverted);
  ASSERT_TRUE(solid.ok()) << solid.status();
  const ValidatedMesh validated = ValidateMesh(inverted);
  EXPECT_EQ(solid->sha256, FormatSha256(MeshSha256(validated.mesh)));
  EXPECT_NE(solid->sha256, FormatSha256(MeshSha256(inverted)));  // orientation was fixed
  EXPECT_EQ(solid->mesh().triangles, validated.mesh.triangles);
  EXPECT_EQ(solid->report.flipped_triangles, validated.report.flipped_triangles);
  EXPECT_EQ(solid->oracle.Classify(Vector3(0.5, 0.5, 0.5)), Side::kInside);
  EXPECT_EQ(solid->oracle.Classify(Vector3(1.5, 0.5, 0.5)), Side::kOutside);
}

TEST(Solid, AnUnusableMeshIsRefusedWithTheReportsFirstError) {
  absl::StatusOr<Solid> open = PrepareSolid(testing::OpenUnitCube());
  EXPECT_EQ(open.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(open.status().message(), HasSubstr("not closed"));
  SolidOptions repair;
  repair.validate.fill_holes = true;
  EXPECT_TRUE(PrepareSolid(testing::OpenUnitCube(), repair).ok());
  Mesh nan = testing::UnitCube();
  nan.vertices(0, 1) = std::nan("");
  EXPECT_EQ(PrepareSolid(nan).status().code(), absl::StatusCode::kFailedPrecondition);
}

// Two cubes overlapping in [0.5, 1]^3: the mesh intersects itself, so the solid takes the
// ray-parity test, which calls the doubly covered region outside as CGAL's Side_of_triangle_mesh
// does; a plain cube keeps the pseudonormal.
TEST(Solid, ASelfIntersectingMeshGetsTheRayParityTest) {
  const Mesh overlapping = testing::Concatenate(
      testing::UnitCube(), testing::Box(Vector3::Constant(0.5), Vector3::Constant(1.5)));
  absl::StatusOr<Solid> solid = PrepareSolid(overlapping);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_GT(solid->report.self_intersecting_pairs, 0);
  EXPECT_EQ(InsideTestFor(solid->report), InsideTest::kRayParity);
  absl::StatusOr<BoundaryOracle> parity =
      BoundaryOracle::Build(solid->mesh(), {InsideTest::kRayParity});
  ASSERT_TRUE(parity.ok());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 1.7);
  for (int i = 0; i < 2000; ++i) {
    const Vector3 p(u(rng), u(rng), u(rng));
    EXPECT_EQ(solid->oracle.Classify(p), parity->Classify(p)) << p.transpose();
  }
  EXPECT_EQ(solid->oracle.Classify(Vector3::Constant(0.75)), Side::kOutside);
  EXPECT_EQ(solid->oracle.Classify(Vector3::Constant(0.25)), Side::kInside);

  absl::StatusOr<Solid> cube = PrepareSolid(testing::UnitCube());
  ASSERT_TRUE(cube.ok());
  EXPECT_EQ(InsideTestFor(cube->report), InsideTest::kPseudonormal);
}

TEST(Solid, RealMeshesKeepTheirHash) {
  INSCRIBE_REQUIRE_MESH("cow.off");
  const Mesh cow = testing::LoadTestMesh("cow.off");
  absl::StatusOr<Solid> solid = PrepareSolid(cow);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_EQ(InsideTestFor(solid->report), solid->report.self_intersecting_pairs > 0
                                              ? InsideTest::kRayParity
                                              : InsideTest::kPseudonormal);
  absl::StatusOr<Solid> again = MakeSolid(ValidateMesh(cow));
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->sha256, solid->sha256);
}

TEST(Sha256, KnownVectorsAndIncrementalUpdates) {
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string text = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  Sha256Hasher hasher;
  for (std::size_t i = 0; i < text.size(); i += 7) hasher.Update(text.substr(i, 7));
  EXPECT_EQ(HexDigits(hasher.Finish()),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(HexDigits(Sha256(text)), Sha256Hex(text));
}

TEST(CheckSphere, AcceptsFiniteCentresWithPositiveRadiiOnly) {
  EXPECT_TRUE(CheckSphere(Sphere{Vector3(1, 2, 3), 1e-300}, 0).ok());
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  const struct {
    Sphere sphere;
    const char* message;
  } bad[] = {{{Vector3(nan, 0, 0), 1}, "sphere 4: center x nan is not finite"},
             {{Vector3(0, 0, -inf), 1}, "sphere 4: center z -inf is not finite"},
             {{Vector3::Zero(), 0}, "sphere 4: radius 0 is not positive"},
             {{Vector3::Zero(), -0.5}, "sphere 4: radius -0.5 is not positive"},
             {{Vector3::Zero(), inf}, "sphere 4: radius inf is not finite"},
             {{Vector3::Zero(), nan}, "sphere 4: radius nan is not finite"}};
  for (const auto& b : bad) {
    const absl::Status s = CheckSphere(b.sphere, 4);
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
    EXPECT_EQ(s.message(), b.message);
  }
  EXPECT_TRUE(CheckSpheres({}).ok());
  EXPECT_THAT(CheckSpheres({Sphere{Vector3::Zero(), 1}, Sphere{Vector3::Zero(), 0}}).message(),
              HasSubstr("sphere 1:"));
}

}  // namespace
}  // namespace inscribe
