// Welding coincident vertices in ValidateMesh: files that repeat each vertex per face (MeshLab's
// OBJ), near-coincident copies, what welding collapses, shells that touch, and the kd-tree
// search against a brute-force one.
#include "mesh/vertex_welding.h"  // private: core/src

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "support/cgal_mesh_writer.h"
#include "support/mesh_issues.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::HasIssue;
using ::testing::HasSubstr;
using testing::PerFaceVertices;
using testing::UnitCube;

// The mesh with its vertices renumbered in order of first use by the triangles (unused ones
// dropped): what welding a per-face copy of it gives back.
Mesh InFirstUseOrder(const Mesh& mesh) {
  std::vector<std::int32_t> renumber(static_cast<std::size_t>(mesh.num_vertices()), -1);
  std::vector<Eigen::Index> order;
  Mesh out;
  out.triangles = mesh.triangles;
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      std::int32_t& n = renumber[static_cast<std::size_t>(mesh.triangles(t, k))];
      if (n < 0) {
        n = static_cast<std::int32_t>(order.size());
        order.push_back(mesh.triangles(t, k));
      }
      out.triangles(t, k) = n;
    }
  }
  out.vertices.resize(static_cast<Eigen::Index>(order.size()), 3);
  for (std::size_t i = 0; i < order.size(); ++i) {
    out.vertices.row(static_cast<Eigen::Index>(i)) = mesh.vertices.row(order[i]);
  }
  return out;
}

TEST(WeldVertices, PerFaceObjOfADemoMeshIsTheMeshAgain) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh original = InFirstUseOrder(testing::LoadTestMesh("eight.off"));
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("inscribe_weld_" + std::to_string(::getpid()) + ".obj"))
                               .string();
  ASSERT_TRUE(testing::WriteMeshWithCgal(path, PerFaceVertices(original), false));
  absl::StatusOr<Mesh> read = ReadMesh(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->num_vertices(), 3 * original.num_triangles());

  const ValidatedMesh welded = ValidateMesh(*read);
  ASSERT_TRUE(welded.report.usable()) << welded.report.first_error();
  EXPECT_TRUE(welded.report.closed());
  EXPECT_EQ(welded.report.vertices, 3 * original.num_triangles());
  EXPECT_EQ(welded.report.welded_vertices, 3 * original.num_triangles() - original.num_vertices());
  EXPECT_EQ(welded.report.weld_collapsed_triangles, 0);
  EXPECT_TRUE(HasIssue(welded.report, "welded_vertices", Severity::kFixed));
  const ValidatedMesh reference = ValidateMesh(original);
  EXPECT_EQ(MeshSha256(welded.mesh), MeshSha256(reference.mesh));
  EXPECT_EQ(welded.report.volume, reference.report.volume);
  for (const MeshIssue& issue : welded.report.issues) {
    if (issue.code != "welded_vertices") continue;
    EXPECT_EQ(issue.count, welded.report.welded_vertices);
    EXPECT_THAT(issue.message, HasSubstr(std::to_string(welded.report.welded_vertices)));
  }

  ValidateOptions no_weld;
  no_weld.weld_vertices = false;
  no_weld.repair.level = MeshRepair::kNone;
  const ValidatedMesh open = ValidateMesh(*read, no_weld);
  EXPECT_FALSE(open.report.usable());
  EXPECT_TRUE(HasIssue(open.report, "not_closed", Severity::kError));
  EXPECT_EQ(open.report.welded_vertices, 0);
}

TEST(WeldVertices, NearCoincidentCopiesNeedTheTolerance) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh original = InFirstUseOrder(testing::LoadTestMesh("eight.off"));
  Mesh soup = PerFaceVertices(original);
  const double diagonal = ComputeBoundingBox(original.vertices).diagonal();
  std::mt19937 random(23);
  std::uniform_real_distribution<double> offset(-1.0, 1.0);
  // Every copy after a vertex's first moves by up to 1e-9 of the diagonal on each axis.
  std::vector<char> seen(static_cast<std::size_t>(original.num_vertices()), 0);
  for (Eigen::Index t = 0; t < original.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (seen[static_cast<std::size_t>(original.triangles(t, k))]++ == 0) continue;
      for (int axis = 0; axis < 3; ++axis)
        soup.vertices(3 * t + k, axis) += 1e-9 * diagonal * offset(random);
    }
  }
  ValidateOptions none;
  none.repair.level = MeshRepair::kNone;
  const ValidatedMesh exact = ValidateMesh(soup, none);
  EXPECT_FALSE(exact.report.usable());
  EXPECT_TRUE(HasIssue(exact.report, "not_closed", Severity::kError));
  EXPECT_THAT(exact.report.first_error(), HasSubstr("--weld-tolerance"));
  // The default safe repair welds them as cracks: the same mesh again.
  const ValidatedMesh cracks = ValidateMesh(soup);
  ASSERT_TRUE(cracks.report.usable()) << cracks.report.first_error();
  EXPECT_EQ(MeshSha256(cracks.mesh), MeshSha256(ValidateMesh(original).mesh));

  ValidateOptions near;
  near.repair.weld_tolerance = 1e-7 * diagonal;
  const ValidatedMesh welded = ValidateMesh(soup, near);
  ASSERT_TRUE(welded.report.usable()) << welded.report.first_error();
  EXPECT_EQ(welded.report.welded_vertices, 3 * original.num_triangles() - original.num_vertices());
  // The first copy of each vertex is kept: the welded mesh is the original exactly.
  EXPECT_EQ(MeshSha256(welded.mesh), MeshSha256(ValidateMesh(original).mesh));
}

TEST(WeldVertices, TrianglesThatCollapseAreRemovedAndReported) {
  // A closed cube and a sliver whose corners all lie within 1e-9 of the cube's vertex 0.
  Mesh mesh = UnitCube();
  const Eigen::Index n = mesh.num_vertices();
  mesh.vertices.conservativeResize(n + 3, 3);
  mesh.vertices.row(n) = mesh.vertices.row(0);
  mesh.vertices.row(n + 1) = mesh.vertices.row(0) + Eigen::RowVector3d(1e-9, 0, 0);
  mesh.vertices.row(n + 2) = mesh.vertices.row(0) + Eigen::RowVector3d(0, 1e-9, 0);
  mesh.triangles.conservativeResize(mesh.num_triangles() + 1, 3);
  mesh.triangles.bottomRows(1) << n, n + 1, n + 2;

  ValidateOptions near;
  near.repair.weld_tolerance = 1e-6;
  const ValidatedMesh v = ValidateMesh(mesh, near);
  ASSERT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_EQ(v.report.welded_vertices, 3);
  EXPECT_EQ(v.report.weld_collapsed_triangles, 1);
  EXPECT_EQ(v.mesh.num_triangles(), 12);
  EXPECT_EQ(v.mesh.num_vertices(), 8);
  EXPECT_EQ(v.report.degenerate_triangles, 0);
  EXPECT_NEAR(v.report.volume, 1.0, 1e-15);
  ASSERT_TRUE(HasIssue(v.report, "welded_vertices", Severity::kFixed));
  for (const MeshIssue& issue : v.report.issues) {
    if (issue.code == "welded_vertices") {
      EXPECT_THAT(issue.message, HasSubstr("removed 1 triangle that welding left with a repeated"));
    }
  }
  // Exactly: only the copy of vertex 0 coincides, and the sliver, a sheet of its own, would
  // only touch the cube there: nothing is welded, and the sliver's edges are borders.
  ValidateOptions none;
  none.repair.level = MeshRepair::kNone;
  const ValidatedMesh exact = ValidateMesh(mesh, none);
  EXPECT_EQ(exact.report.welded_vertices, 0);
  EXPECT_EQ(exact.report.weld_collapsed_triangles, 0);
  EXPECT_FALSE(exact.report.usable());
  // The crack weld never merges the sliver's own corners (an edge joins each pair): still open.
  EXPECT_FALSE(ValidateMesh(mesh).report.usable());

  // A triangle that repeated a corner as given is not the weld's: it stays, a degenerate one.
  Mesh given = UnitCube();
  given.triangles.conservativeResize(13, 3);
  given.triangles.row(12) << 0, 0, 1;
  const ValidatedMesh kept = ValidateMesh(given);
  EXPECT_EQ(kept.report.weld_collapsed_triangles, 0);
  EXPECT_EQ(kept.report.degenerate_triangles, 1);
}

// Coincident vertices of separate shells are not welded: the shells would be pinched together
// (a non-manifold vertex or edge), and the mesh was usable as it was.
TEST(WeldVertices, SeparateShellsThatTouchStayApart) {
  // Two cubes sharing an edge, each with its own vertices; and the same cube twice.
  for (const Mesh& mesh :
       {testing::Concatenate(UnitCube(), testing::Box(Vector3(1, 1, 0), Vector3(2, 2, 1))),
        testing::Concatenate(UnitCube(), UnitCube())}) {
    ValidateOptions no_weld;
    no_weld.weld_vertices = false;
    const ValidatedMesh v = ValidateMesh(mesh);
    EXPECT_EQ(v.report.welded_vertices, 0);
    EXPECT_EQ(v.mesh.vertices, mesh.vertices);
    EXPECT_EQ(v.report.usable(), ValidateMesh(mesh, no_weld).report.usable());
    EXPECT_EQ(v.report.non_manifold_edges, 0);
  }
  // Written per face, two cubes touching at a corner weld into two closed cubes that do not
  // share the corner (one vertex each), not one bow tie.
  const Mesh touching = PerFaceVertices(
      testing::Concatenate(UnitCube(), testing::Box(Vector3(1, 1, 1), Vector3(2, 2, 2))));
  const ValidatedMesh v = ValidateMesh(touching);
  ASSERT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_EQ(v.mesh.num_vertices(), 16);
  EXPECT_EQ(v.report.welded_vertices, 72 - 16);
  EXPECT_EQ(v.report.non_manifold_vertices, 0);
  EXPECT_EQ(v.report.components, 2);
  EXPECT_NEAR(v.report.volume, 2.0, 1e-12);
}

TEST(WeldVertices, ToleranceMustBeAFiniteDistance) {
  for (const double tolerance : {-1e-3, std::nan(""), HUGE_VAL}) {
    ValidateOptions options;
    options.repair.weld_tolerance = tolerance;
    const ValidatedMesh v = ValidateMesh(UnitCube(), options);
    EXPECT_FALSE(v.report.usable()) << tolerance;
    EXPECT_TRUE(HasIssue(v.report, "invalid_weld_tolerance", Severity::kError)) << tolerance;
  }
}

TEST(WeldVertices, ClustersFollowIndexOrder) {
  // Points 0.6 apart on a line, tolerance 1: 1 joins 0; 2 is 1.2 from 0 and stays (1 is no
  // longer a vertex to join); 3 joins 2.
  Mesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 0.6, 0, 0, 1.2, 0, 0, 1.8, 0, 0;
  mesh.triangles.resize(0, 3);
  const internal::Weld weld = internal::WeldVertices(mesh, 1.0);
  EXPECT_EQ(weld.merged_vertices, 2);
  ASSERT_EQ(mesh.num_vertices(), 2);
  EXPECT_EQ(mesh.vertices(0, 0), 0.0);
  EXPECT_EQ(mesh.vertices(1, 0), 1.2);
}

// The kd-tree search against the definition, on random points with many near pairs.
TEST(WeldVertices, MatchesBruteForceOnRandomPoints) {
  std::mt19937 random(7);
  std::uniform_int_distribution<int> lattice(0, 6);
  std::uniform_real_distribution<double> jitter(-0.04, 0.04);
  for (int round = 0; round < 20; ++round) {
    const double tolerance = 0.02 + 0.01 * round;
    Mesh mesh;
    const int n = 400;
    mesh.vertices.resize(n, 3);
    for (int v = 0; v < n; ++v) {
      for (int axis = 0; axis < 3; ++axis) {
        mesh.vertices(v, axis) = 0.1 * lattice(random) + jitter(random);
      }
    }
    mesh.triangles.resize(0, 3);  // no triangles: every group is one kept vertex

    std::vector<int> representative(n, -1);
    for (int v = 0; v < n; ++v) {
      if (representative[v] >= 0) continue;
      representative[v] = v;
      for (int w = v + 1; w < n; ++w) {
        if (representative[w] < 0 &&
            (mesh.vertices.row(v) - mesh.vertices.row(w)).squaredNorm() <= tolerance * tolerance) {
          representative[w] = v;
        }
      }
    }
    std::vector<Eigen::Index> kept;
    for (int v = 0; v < n; ++v) {
      if (representative[v] == v) kept.push_back(v);
    }
    Mesh welded = mesh;
    const internal::Weld weld = internal::WeldVertices(welded, tolerance);
    EXPECT_EQ(weld.merged_vertices, n - static_cast<int>(kept.size())) << round;
    ASSERT_EQ(welded.num_vertices(), static_cast<Eigen::Index>(kept.size())) << round;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      EXPECT_EQ(welded.vertices.row(static_cast<Eigen::Index>(i)), mesh.vertices.row(kept[i]))
          << round;
    }
  }
}

}  // namespace
}  // namespace inscribe
