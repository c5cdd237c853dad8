// ClipMeshByPlane: the kept part of a solid is a closed solid with the volume it should have.
#include "inscribe/mesh/mesh_clip.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;

TEST(ClipMeshByPlane, ACubeCutAnywhereKeepsTheExactVolumeAndIsClosed) {
  const Mesh cube = testing::Box(Vector3::Constant(-1), Vector3::Ones());
  for (const double offset : {-0.75, 0.0, 0.3}) {
    const absl::StatusOr<Mesh> half = ClipMeshByPlane(cube, Vector3(0, 0, 2), 2 * offset);
    ASSERT_TRUE(half.ok()) << half.status();
    const ValidatedMesh validated = ValidateMesh(*half);
    EXPECT_TRUE(validated.report.usable()) << validated.report.first_error();
    EXPECT_NEAR(validated.report.volume, 4.0 * (offset + 1.0), 1e-12) << offset;
    EXPECT_LE(half->vertices.col(2).maxCoeff(), offset + 1e-15);
  }
  // A slanted plane through the centre halves it.
  const absl::StatusOr<Mesh> slanted = ClipMeshByPlane(cube, Vector3(1, 2, 3), 0.0);
  ASSERT_TRUE(slanted.ok());
  EXPECT_NEAR(ValidateMesh(*slanted).report.volume, 4.0, 1e-12);
}

TEST(ClipMeshByPlane, PlanesPastTheMeshKeepAllOrNothing) {
  const Mesh cube = testing::Box(Vector3::Constant(-1), Vector3::Ones());
  const absl::StatusOr<Mesh> all = ClipMeshByPlane(cube, Vector3::UnitX(), 1.0);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->vertices, cube.vertices);
  EXPECT_EQ(all->triangles, cube.triangles);
  const absl::StatusOr<Mesh> none = ClipMeshByPlane(cube, Vector3::UnitX(), -1.0);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none->num_triangles(), 0);
  for (const Vector3& normal : {Vector3(0, 0, 0), Vector3(std::nan(""), 0, 1)}) {
    const absl::StatusOr<Mesh> bad = ClipMeshByPlane(cube, normal, 0.0);
    ASSERT_FALSE(bad.ok());
    EXPECT_THAT(bad.status().message(), HasSubstr("non-zero finite"));
  }
  EXPECT_FALSE(ClipMeshByPlane(cube, Vector3::UnitX(), std::nan("")).ok());
}

TEST(ClipMeshByPlane, RealMeshesCutInTwoAddUpToTheWhole) {
  for (const char* name : {"elephant.off", "knot1.off", "bunny00.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    SCOPED_TRACE(name);
    const ValidatedMesh whole = ValidateMesh(testing::LoadTestMesh(name));
    ASSERT_TRUE(whole.report.usable());
    const Vector3 centre = 0.5 * (whole.report.bbox.min + whole.report.bbox.max);
    const Vector3 normal(0.3, -1.0, 0.4);
    const double offset = normal.dot(centre);
    const absl::StatusOr<Mesh> below = ClipMeshByPlane(whole.mesh, normal, offset);
    const absl::StatusOr<Mesh> above = ClipMeshByPlane(whole.mesh, -normal, -offset);
    ASSERT_TRUE(below.ok()) << below.status();
    ASSERT_TRUE(above.ok()) << above.status();
    const ValidatedMesh a = ValidateMesh(*below), b = ValidateMesh(*above);
    EXPECT_TRUE(a.report.usable()) << a.report.first_error();
    EXPECT_TRUE(b.report.usable()) << b.report.first_error();
    EXPECT_NEAR(a.report.volume + b.report.volume, whole.report.volume, 1e-9 * whole.report.volume);
  }
}

}  // namespace
}  // namespace inscribe
