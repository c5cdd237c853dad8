#include "inscribe/solid/mesh_validation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "inscribe/mesh/mesh_io.h"
#include "mesh/mesh_topology.h"  // private: core/src
#include "support/mesh_issues.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::Box;
using testing::Concatenate;
using testing::HasIssue;
using ::testing::HasSubstr;
using testing::Icosphere;
using testing::Inverted;
using testing::UnitCube;

TEST(ValidateMesh, CleanCube) {
  const ValidatedMesh v = ValidateMesh(UnitCube());
  EXPECT_TRUE(v.report.usable());
  EXPECT_TRUE(v.report.closed());
  EXPECT_TRUE(v.report.issues.empty()) << v.report.issues.front().message;
  EXPECT_EQ(v.report.components, 1);
  EXPECT_TRUE(v.report.self_intersections_checked);
  EXPECT_NEAR(v.report.volume, 1.0, 1e-15);
  EXPECT_EQ(v.mesh.triangles, UnitCube().triangles);
}

// Found by fuzz_mesh: a vertex at -1e308 gave an infinite volume on a usable mesh, and hole
// filling near 1.8e308 aborted inside CGAL (GMP on an infinity); see also the hole case.
TEST(ValidateMesh, CoordinatesThatOverflowAreAnError) {
  for (const auto& [lo, hi] : {std::pair{Vector3(0, 0, -1e308), Vector3(1, 1, 1)},
                               std::pair{Vector3(0, 0, 0), Vector3(1e110, 1e110, 1e110)},
                               std::pair{Vector3(-1.5e308, 0, 0), Vector3(1.5e308, 1, 1)}}) {
    const ValidatedMesh v = ValidateMesh(Box(lo, hi));
    EXPECT_FALSE(v.report.usable()) << hi.transpose();
    EXPECT_TRUE(HasIssue(v.report, "coordinates_too_large", Severity::kError)) << hi.transpose();
    EXPECT_THAT(v.report.first_error(), HasSubstr("scale the mesh down"));
  }
  // A hole next to a huge vertex: refused before CGAL's hole filling runs.
  Mesh open = UnitCube();
  open.vertices(6, 1) = 1.7976931348623157e308;
  open.triangles.conservativeResize(open.num_triangles() - 1, 3);
  ValidateOptions fill;
  fill.repair.level = MeshRepair::kFill;
  const ValidatedMesh refused = ValidateMesh(open, fill);
  EXPECT_TRUE(HasIssue(refused.report, "coordinates_too_large", Severity::kError));
  EXPECT_EQ(refused.report.holes_filled, 0);
  // At the bound: usable, with the exact figures.
  const ValidatedMesh big = ValidateMesh(Box(Vector3::Zero(), Vector3(1e100, 1e100, 1e100)));
  EXPECT_TRUE(big.report.usable()) << big.report.first_error();
  EXPECT_NEAR(big.report.volume / 1e300, 1.0, 1e-12);
}

TEST(ValidateMesh, InvertedMeshIsFixed) {
  const Mesh sphere = Icosphere(3);
  const ValidatedMesh v = ValidateMesh(Inverted(sphere));
  EXPECT_TRUE(v.report.usable());
  EXPECT_EQ(v.report.flipped_triangles, sphere.num_triangles());
  EXPECT_TRUE(HasIssue(v.report, "orientation_fixed", Severity::kFixed));
  EXPECT_NEAR(v.report.volume, SignedVolume(sphere), 1e-12);
  EXPECT_EQ(v.mesh.triangles, sphere.triangles);
}

TEST(ValidateMesh, InconsistentTrianglesAreFixed) {
  Mesh sphere = Icosphere(2);
  Mesh broken = sphere;
  for (int t : {3, 50, 51, 200}) std::swap(broken.triangles(t, 1), broken.triangles(t, 2));
  const ValidatedMesh v = ValidateMesh(broken);
  EXPECT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_GT(v.report.inconsistent_edges, 0);
  EXPECT_EQ(v.report.flipped_triangles, 4);
  EXPECT_EQ(v.mesh.triangles, sphere.triangles);
}

TEST(ValidateMesh, NoFixWhenAsked) {
  ValidateOptions options;
  options.fix_orientation = false;
  const ValidatedMesh v = ValidateMesh(Inverted(UnitCube()), options);
  EXPECT_FALSE(v.report.usable());  // negative volume
  EXPECT_THAT(v.report.first_error(), HasSubstr("no volume"));
}

TEST(ValidateMesh, CavityFacesInward) {
  // A hollow box: the inner shell must face into the cavity, whatever it was given as.
  const Mesh outer = Box(Vector3(-2, -2, -2), Vector3(2, 2, 2));
  const Mesh inner = Box(Vector3(-1, -1, -1), Vector3(1, 1, 1));
  for (const Mesh& given : {Concatenate(outer, inner), Concatenate(Inverted(outer), inner),
                            Concatenate(outer, Inverted(inner))}) {
    const ValidatedMesh v = ValidateMesh(given);
    EXPECT_TRUE(v.report.usable()) << v.report.first_error();
    EXPECT_EQ(v.report.components, 2);
    EXPECT_NEAR(v.report.volume, 64.0 - 8.0, 1e-12);
  }
  // Two separate boxes both face out.
  const ValidatedMesh apart =
      ValidateMesh(Concatenate(Inverted(inner), Box(Vector3(5, 5, 5), Vector3(6, 6, 6))));
  EXPECT_NEAR(apart.report.volume, 9.0, 1e-12);
}

TEST(ValidateMesh, OpenMesh) {
  const Mesh open = testing::OpenUnitCube();
  const ValidatedMesh v = ValidateMesh(open);
  EXPECT_FALSE(v.report.usable());
  EXPECT_FALSE(v.report.closed());
  EXPECT_EQ(v.report.border_edges, 3);
  EXPECT_THAT(v.report.first_error(), HasSubstr("mesh is not closed: 3 border edges"));
  EXPECT_FALSE(PrepareMesh(open).ok());
}

TEST(ValidateMesh, NonManifoldEdge) {
  // Two cubes sharing one edge (x = 1, y = 1): that edge is in four triangles.
  const Mesh v = Concatenate(UnitCube(), Box(Vector3(1, 1, 0), Vector3(2, 2, 1)));
  // Weld the duplicated edge vertices so the edge is really shared.
  Mesh welded = v;
  for (Eigen::Index t = 0; t < welded.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t i = welded.triangles(t, k);
      if (i < 8) continue;
      for (std::int32_t j = 0; j < 8; ++j) {
        if (welded.vertices.row(i) == welded.vertices.row(j)) welded.triangles(t, k) = j;
      }
    }
  }
  const ValidatedMesh r = ValidateMesh(welded);
  EXPECT_FALSE(r.report.usable());
  EXPECT_EQ(r.report.non_manifold_edges, 1);
  EXPECT_THAT(r.report.first_error(), HasSubstr("not edge-manifold: 1 edge is shared by more"));
}

TEST(ValidateMesh, NonManifoldVertexIsAWarning) {
  // Two cubes touching at one corner (1, 1, 1), welded there.
  Mesh touching = Concatenate(UnitCube(), Box(Vector3(1, 1, 1), Vector3(2, 2, 2)));
  for (Eigen::Index t = 0; t < touching.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (touching.triangles(t, k) == 8) touching.triangles(t, k) = 7;
    }
  }
  const ValidatedMesh v = ValidateMesh(touching);
  EXPECT_EQ(v.report.non_manifold_vertices, 1);
  EXPECT_TRUE(HasIssue(v.report, "non_manifold_vertices", Severity::kWarning));
  EXPECT_TRUE(v.report.usable());
}

// The slow obvious count: a vertex is non-manifold when its triangles fall into more than one
// group linked through edges that exactly two triangles use.
std::vector<std::int32_t> BruteForceNonManifoldVertices(const Mesh& mesh) {
  std::map<std::pair<std::int32_t, std::int32_t>, int> edge_uses;
  std::vector<std::vector<std::int32_t>> around(static_cast<std::size_t>(mesh.num_vertices()));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      ++edge_uses[std::minmax(mesh.triangles(t, k), mesh.triangles(t, (k + 1) % 3))];
      around[static_cast<std::size_t>(mesh.triangles(t, k))].push_back(
          static_cast<std::int32_t>(t));
    }
  }
  std::vector<std::int32_t> bad;
  for (std::size_t v = 0; v < around.size(); ++v) {
    const std::vector<std::int32_t>& ts = around[v];
    if (ts.size() < 2) continue;
    auto linked = [&](std::int32_t a, std::int32_t b) {
      for (int i = 0; i < 3; ++i) {
        const std::int32_t w = mesh.triangles(a, i);
        if (w == static_cast<std::int32_t>(v)) continue;
        bool in_b = false;
        for (int j = 0; j < 3; ++j) in_b = in_b || mesh.triangles(b, j) == w;
        if (in_b && edge_uses[std::minmax(static_cast<std::int32_t>(v), w)] == 2) return true;
      }
      return false;
    };
    std::vector<char> reached(ts.size(), 0);
    std::vector<std::size_t> stack = {0};
    reached[0] = 1;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      for (std::size_t j = 0; j < ts.size(); ++j) {
        if (!reached[j] && linked(ts[i], ts[j])) {
          reached[j] = 1;
          stack.push_back(j);
        }
      }
    }
    if (std::count(reached.begin(), reached.end(), 0) > 0)
      bad.push_back(static_cast<std::int32_t>(v));
  }
  return bad;
}

// Real meshes side by side, pinched: random vertex pairs of different shells merged into one
// vertex (two fans meeting there) and vertex pairs of one shell merged (fans, or non-manifold
// edges when they were neighbours). Validation's count and first vertex are the brute force's.
TEST(ValidateMesh, NonManifoldVerticesAreThoseTheBruteForceFinds) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh eight = testing::LoadTestMesh("eight.off");
  std::mt19937_64 random(3);
  for (int round = 0; round < 12; ++round) {
    Mesh moved = eight;
    moved.vertices.rowwise() += Vector3(3.0, 0.5 * round, 0.0).transpose();
    Mesh mesh = Concatenate(eight, moved);
    std::uniform_int_distribution<std::int32_t> vertex(
        0, static_cast<std::int32_t>(mesh.num_vertices()) - 1);
    for (int merge = 0; merge < 1 + round; ++merge) {
      const std::int32_t from = vertex(random), to = vertex(random);
      for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
        for (int k = 0; k < 3; ++k) {
          if (mesh.triangles(t, k) == from) mesh.triangles(t, k) = to;
        }
      }
    }
    ValidateOptions options;
    options.check_self_intersections = false;
    options.repair.level = MeshRepair::kNone;  // the brute force counts on the mesh as validated
    const ValidatedMesh v = ValidateMesh(mesh, options);
    const std::vector<std::int32_t> expected = BruteForceNonManifoldVertices(v.mesh);
    EXPECT_EQ(v.report.non_manifold_vertices, static_cast<std::int64_t>(expected.size())) << round;
    if (!expected.empty()) {
      const auto issue =
          std::find_if(v.report.issues.begin(), v.report.issues.end(),
                       [](const MeshIssue& i) { return i.code == "non_manifold_vertices"; });
      ASSERT_NE(issue, v.report.issues.end()) << round;
      EXPECT_THAT(issue->message, HasSubstr(absl::StrCat("(first: vertex ", expected.front(), ")")))
          << round;
    }
  }
}

TEST(ValidateMesh, NonFiniteCoordinates) {
  Mesh mesh = UnitCube();
  mesh.vertices(5, 2) = std::numeric_limits<double>::quiet_NaN();
  mesh.vertices(6, 0) = std::numeric_limits<double>::infinity();
  const ValidatedMesh v = ValidateMesh(mesh);
  EXPECT_FALSE(v.report.usable());
  EXPECT_EQ(v.report.non_finite_vertices, 2);
  EXPECT_THAT(v.report.first_error(), HasSubstr("2 vertices have non-finite"));
  EXPECT_THAT(v.report.first_error(), HasSubstr("vertex 5"));
}

TEST(ValidateMesh, IndicesOutOfRange) {
  Mesh mesh = UnitCube();
  mesh.triangles(4, 1) = 8;
  mesh.triangles(7, 0) = -3;
  const ValidatedMesh v = ValidateMesh(mesh);
  EXPECT_FALSE(v.report.usable());
  EXPECT_EQ(v.report.out_of_range_indices, 2);
  EXPECT_THAT(v.report.first_error(), HasSubstr("triangle 4 corner 1 = 8"));
}

TEST(ValidateMesh, EmptyMesh) {
  const ValidatedMesh v = ValidateMesh(Mesh{});
  EXPECT_FALSE(v.report.usable());
  EXPECT_THAT(v.report.first_error(), HasSubstr("no triangles"));
}

TEST(ValidateMesh, DegenerateTrianglesAreWarnings) {
  // Split the cube's first triangle (0, 2, 1) at the midpoint of edge 2-1 with a zero-area
  // sliver so the surface stays closed: add vertex m on edge 2-1.
  Mesh mesh = UnitCube();
  mesh.vertices.conservativeResize(9, 3);
  mesh.vertices.row(8) = 0.5 * (mesh.vertices.row(2) + mesh.vertices.row(1));
  // (0,2,1) -> (0,2,8) + (0,8,1); neighbour (1,2,3) -> (1,8,3) + (8,2,3).
  mesh.triangles.row(0) << 0, 2, 8;
  mesh.triangles.row(1) << 1, 8, 3;
  mesh.triangles.conservativeResize(15, 3);
  mesh.triangles.row(12) << 0, 8, 1;
  mesh.triangles.row(13) << 8, 2, 3;
  mesh.triangles.row(14) << 2, 8, 2;  // repeats a corner
  const ValidatedMesh v = ValidateMesh(mesh);
  EXPECT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_EQ(v.report.degenerate_triangles, 1);
  EXPECT_TRUE(HasIssue(v.report, "degenerate_triangles", Severity::kWarning));
  EXPECT_NEAR(v.report.volume, 1.0, 1e-15);
}

TEST(ValidateMesh, SelfIntersectionsAreReported) {
  // Corner (1, 1, 1) pushed through the bottom face.
  Mesh pierced = UnitCube();
  pierced.vertices.row(7) << 0.3, 0.3, -0.5;
  const ValidatedMesh v = ValidateMesh(pierced);
  EXPECT_TRUE(v.report.self_intersections_checked);
  EXPECT_GT(v.report.self_intersecting_pairs, 0);
  EXPECT_TRUE(HasIssue(v.report, "self_intersections", Severity::kWarning));
  EXPECT_TRUE(v.report.usable());
  ValidateOptions skip;
  skip.check_self_intersections = false;
  EXPECT_FALSE(ValidateMesh(pierced, skip).report.self_intersections_checked);
}

TEST(ValidateMesh, OverlappingShellsAreNotCavities) {
  // Two overlapping boxes given as one mesh (an unresolved union): both must face out.
  const Mesh overlapping =
      Concatenate(UnitCube(), Inverted(Box(Vector3(0.5, 0.5, 0.5), Vector3(1.5, 1.5, 1.5))));
  const ValidatedMesh v = ValidateMesh(overlapping);
  EXPECT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_NEAR(v.report.volume, 2.0, 1e-12);
  EXPECT_EQ(v.report.self_intersecting_pairs, 18);
}

TEST(ValidateMesh, DuplicatedFaceIsNonManifold) {
  // A tetrahedron with one face listed again, reversed: its three edges are in three triangles.
  Mesh tet;
  tet.vertices.resize(4, 3);
  tet.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  tet.triangles.resize(5, 3);
  tet.triangles << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 1, 3, 2;
  ValidateOptions none;
  none.repair.level = MeshRepair::kNone;
  const ValidatedMesh v = ValidateMesh(tet, none);
  EXPECT_FALSE(v.report.usable());
  EXPECT_EQ(v.report.duplicate_triangles, 1);
  EXPECT_EQ(v.report.non_manifold_edges, 3);
  EXPECT_THAT(v.report.first_error(), HasSubstr("--repair safe removes duplicate triangles"));
  // The safe fixes drop the later copy (its edges are in three triangles, not four: a face
  // listed twice, not a wall between two bodies), and the tetrahedron is whole.
  const ValidatedMesh safe = ValidateMesh(tet);
  ASSERT_TRUE(safe.report.usable()) << safe.report.first_error();
  EXPECT_EQ(safe.report.duplicate_triangles_removed, 1);
  EXPECT_EQ(safe.report.double_walls_removed, 0);
  EXPECT_EQ(safe.mesh.num_triangles(), 4);
  EXPECT_NEAR(safe.report.volume, 1.0 / 6.0, 1e-15);
}

class RealMeshes : public ::testing::TestWithParam<const char*> {};

TEST_P(RealMeshes, AreUsableClosedAndOutward) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const ValidatedMesh v = ValidateMesh(mesh);
  EXPECT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_TRUE(v.report.closed());
  EXPECT_EQ(v.report.flipped_triangles, 0);  // LoadTestMesh already oriented it
  EXPECT_GT(v.report.volume, 0.0);
  EXPECT_LT(v.report.volume, v.report.bbox.extent().prod());
}

INSTANTIATE_TEST_SUITE_P(Cgal, RealMeshes,
                         ::testing::Values("eight.off", "cow.off", "elephant.off", "knot1.off",
                                           "fandisk.off", "bunny00.off"));

TEST(ValidateMesh, CgalPigIsOpen) {
  // CGAL's pig.off has 891 triangles: an odd count cannot close up.
  INSCRIBE_REQUIRE_MESH("pig.off");
  absl::StatusOr<Mesh> pig = ReadMesh(testing::TestMeshPath("pig.off"));
  ASSERT_TRUE(pig.ok());
  const ValidatedMesh v = ValidateMesh(*pig);
  EXPECT_EQ(v.report.border_edges, 55);
  EXPECT_FALSE(v.report.usable());
}

}  // namespace
}  // namespace inscribe
