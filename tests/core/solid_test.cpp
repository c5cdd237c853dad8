// PrepareSolid and its one inside-test rule, the one SHA-256 and the one sphere check.
#include "inscribe/solid/solid.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "inscribe/base/sha256.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/geometry/sphere.h"
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
  repair.validate.repair.level = MeshRepair::kFill;
  EXPECT_TRUE(PrepareSolid(testing::OpenUnitCube(), repair).ok());
  Mesh nan = testing::UnitCube();
  nan.vertices(0, 1) = std::nan("");
  EXPECT_EQ(PrepareSolid(nan).status().code(), absl::StatusCode::kFailedPrecondition);
}

// Two cubes overlapping in [0.5, 1]^3: the mesh intersects itself, so the solid takes the
// exact winding test, and the doubly covered region (winding number 2) is inside: the solid is
// the union. A plain cube keeps the pseudonormal.
TEST(Solid, ASelfIntersectingMeshIsTheUnionUnderTheExactTest) {
  const Mesh overlapping = testing::Concatenate(
      testing::UnitCube(), testing::Box(Vector3::Constant(0.5), Vector3::Constant(1.5)));
  absl::StatusOr<Solid> solid = PrepareSolid(overlapping);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_GT(solid->report.self_intersecting_pairs, 0);
  EXPECT_EQ(InsideTestFor(solid->report), InsideTest::kExactWinding);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.2, 1.7);
  auto in_box = [](const Vector3& p, double lo, double hi) {
    return (p.array() > lo).all() && (p.array() < hi).all();
  };
  for (int i = 0; i < 2000; ++i) {
    const Vector3 p(u(rng), u(rng), u(rng));
    const Side expected =
        in_box(p, 0.0, 1.0) || in_box(p, 0.5, 1.5) ? Side::kInside : Side::kOutside;
    EXPECT_EQ(solid->oracle.Classify(p), expected) << p.transpose();
  }
  EXPECT_EQ(solid->oracle.Classify(Vector3::Constant(0.75)), Side::kInside);
  EXPECT_EQ(solid->oracle.Classify(Vector3::Constant(0.25)), Side::kInside);
  EXPECT_EQ(solid->oracle.Classify(Vector3(1.25, 0.25, 0.25)), Side::kOutside);

  absl::StatusOr<Solid> cube = PrepareSolid(testing::UnitCube());
  ASSERT_TRUE(cube.ok());
  EXPECT_EQ(InsideTestFor(cube->report), InsideTest::kPseudonormal);
}

// The pseudonormal is kept only where validation proved its conditions: a vertex where two
// bodies touch, or a mesh whose self-intersections were not checked, takes the exact test.
TEST(Solid, ThePseudonormalNeedsItsConditionsProved) {
  // The second cube's corner at (1, 1, 1) is the first one's vertex: one vertex, two fans.
  const Mesh cube_a = testing::UnitCube();
  Mesh touching =
      testing::Concatenate(cube_a, testing::Box(Vector3::Ones(), Vector3::Constant(2.0)));
  Eigen::Index shared = -1, copy = -1;
  for (Eigen::Index v = 0; v < touching.num_vertices(); ++v) {
    if (touching.vertices.row(v).transpose() != Vector3::Ones()) continue;
    (v < cube_a.num_vertices() ? shared : copy) = v;
  }
  ASSERT_GE(shared, 0);
  ASSERT_GE(copy, 0);
  touching.triangles = (touching.triangles.array() == copy)
                           .select(static_cast<std::int32_t>(shared), touching.triangles);
  absl::StatusOr<Solid> pinned = PrepareSolid(touching);
  ASSERT_TRUE(pinned.ok()) << pinned.status();
  EXPECT_GT(pinned->report.non_manifold_vertices, 0);
  EXPECT_EQ(InsideTestFor(pinned->report), InsideTest::kExactWinding);
  SolidOptions unchecked;
  unchecked.validate.check_self_intersections = false;
  absl::StatusOr<Solid> cube = PrepareSolid(testing::UnitCube(), unchecked);
  ASSERT_TRUE(cube.ok());
  EXPECT_EQ(InsideTestFor(cube->report), InsideTest::kExactWinding);
}

TEST(Solid, RealMeshesKeepTheirHash) {
  INSCRIBE_REQUIRE_MESH("cow.off");
  const Mesh cow = testing::LoadTestMesh("cow.off");
  absl::StatusOr<Solid> solid = PrepareSolid(cow);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_EQ(InsideTestFor(solid->report), solid->report.self_intersecting_pairs > 0
                                              ? InsideTest::kExactWinding
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
