#include "inscribe/mesh_validation.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
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
#include "inscribe/mesh_io.h"
#include "mesh_topology.h"       // private: core/src
#include "self_intersections.h"  // private: core/src
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
  fill.fill_holes = true;
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
    options.fill_holes = false;  // the brute force counts on the mesh as validated
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
  const ValidatedMesh v = ValidateMesh(tet);
  EXPECT_FALSE(v.report.usable());
  EXPECT_EQ(v.report.duplicate_triangles, 1);
  EXPECT_EQ(v.report.non_manifold_edges, 3);
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

// Meshes that intersect themselves in many places: `mesh` with a few percent of its vertices
// pushed a random distance along random directions, and beside it a copy moved by a tenth of
// its size (two shells crossing along a curve).
Mesh Crumpled(const Mesh& mesh, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  const double size = ComputeBoundingBox(mesh.vertices).extent().norm();
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit;
  Mesh crumpled = mesh;
  for (Eigen::Index v = 0; v < crumpled.vertices.rows(); ++v) {
    if (unit(random) > 0.03) continue;
    const Vector3 direction = Vector3(normal(random), normal(random), normal(random)).normalized();
    crumpled.vertices.row(v) += (0.05 * size * unit(random) * direction).transpose();
  }
  Mesh moved = mesh;
  moved.vertices.rowwise() += (0.1 * size * Vector3(0.6, 0.0, 0.8)).transpose();
  return Concatenate(crumpled, moved);
}

// The search split into slabs finds exactly the pairs of one whole search (CGAL's own, one
// slab), however many slabs: on real meshes made to cross themselves, and on boxes whose face
// bounds fall on the cuts.
TEST(SelfIntersectingPairs, SlabsFindExactlyWhatOneWholeSearchFinds) {
  std::vector<std::pair<std::string, Mesh>> cases;
  std::uint64_t seed = 1;
  for (const char* name : {"eight.off", "knot1.off", "fandisk.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    cases.emplace_back(name, Crumpled(testing::LoadTestMesh(name), seed++));
  }
  Mesh pierced = UnitCube();
  pierced.vertices.row(7) << 0.3, 0.3, -0.5;
  cases.emplace_back("pierced cube", pierced);
  cases.emplace_back("overlapping boxes",
                     Concatenate(UnitCube(), Box(Vector3::Constant(0.5), Vector3::Constant(1.5))));
  for (const auto& [name, mesh] : cases) {
    const auto whole = internal::SelfIntersectingPairs(mesh, 1);
    ASSERT_TRUE(whole) << name;
    EXPECT_GT(whole->size(), 0u) << name;
    for (const std::size_t slabs : {0, 2, 7, 64, 1000}) {
      EXPECT_EQ(internal::SelfIntersectingPairs(mesh, slabs), whole)
          << name << ", " << slabs << " slabs";
    }
  }
}

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;

Epick::Point_3 ToPoint(const Vector3& p) { return Epick::Point_3(p.x(), p.y(), p.z()); }

// Triangles and segments with corners on a 4 x 4 x 4 grid (many exactly coplanar, collinear
// and touching pairs), on the tilted plane z = x/2 + y/4 (exactly coplanar), nudged off it by
// one ulp, or scaled by 0.1 (coplanar before rounding): whenever their shadows are said to be
// apart, CGAL's exact test must say the shapes do not meet.
TEST(ShadowsApart, NeverSeparatesShapesThatMeet) {
  std::mt19937_64 random(11);
  std::uniform_int_distribution<int> grid(0, 3);
  std::uniform_int_distribution<int> coin(0, 1);
  auto point = [&](int kind) {
    const double x = grid(random), y = grid(random);
    double z = kind == 0 ? grid(random) : 0.5 * x + 0.25 * y;
    if (kind == 2 && coin(random) == 1) {
      z = std::nextafter(z, coin(random) == 1 ? 10.0 : -10.0);
    }
    const Vector3 p(x, y, z);
    return kind == 3 ? Vector3(0.1 * p) : p;
  };
  std::int64_t tried = 0, apart = 0, meet = 0;
  for (int round = 0; round < 200000; ++round) {
    const int kind = round % 4;
    const int count = 2 + round / 4 % 2;
    const Vector3 triangle[3] = {point(kind), point(kind), point(kind)};
    Vector3 other[3] = {point(kind), point(kind), point(kind)};
    const Epick::Triangle_3 t(ToPoint(triangle[0]), ToPoint(triangle[1]), ToPoint(triangle[2]));
    if (t.is_degenerate()) continue;
    bool meets;
    if (count == 2) {
      if (other[0] == other[1]) continue;
      meets = CGAL::do_intersect(t, Epick::Segment_3(ToPoint(other[0]), ToPoint(other[1])));
    } else {
      const Epick::Triangle_3 u(ToPoint(other[0]), ToPoint(other[1]), ToPoint(other[2]));
      if (u.is_degenerate()) continue;
      meets = CGAL::do_intersect(t, u);
    }
    ++tried;
    meet += meets ? 1 : 0;
    if (internal::ShadowsApart(triangle, other, count)) {
      ++apart;
      ASSERT_FALSE(meets) << "round " << round << ": shadows apart, shapes meet";
    }
  }
  EXPECT_GT(tried, 150000);
  EXPECT_GT(meet, tried / 10);  // touching and crossing cases are plentiful
  EXPECT_GT(apart, tried / 5);  // and the screen decides many of the others
}

// `mesh` with every triangle split in four through its edge midpoints: the same solid, its
// neighbouring triangles coplanar (up to the rounding of the midpoints).
Mesh Subdivided(const Mesh& mesh) {
  Mesh out;
  out.vertices = mesh.vertices;
  // Room for every midpoint; cut to those made at the end.
  out.vertices.conservativeResize(mesh.vertices.rows() + 3 * mesh.triangles.rows(), 3);
  Eigen::Index made = mesh.vertices.rows();
  std::map<std::pair<int, int>, int> midpoint;
  auto middle = [&](int a, int b) {
    const auto [it, added] = midpoint.emplace(std::minmax(a, b), static_cast<int>(made));
    if (added) out.vertices.row(made++) = 0.5 * (out.vertices.row(a) + out.vertices.row(b));
    return it->second;
  };
  out.triangles.resize(4 * mesh.triangles.rows(), 3);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const int a = mesh.triangles(t, 0), b = mesh.triangles(t, 1), c = mesh.triangles(t, 2);
    const int ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
    out.triangles.row(4 * t) << a, ab, ca;
    out.triangles.row(4 * t + 1) << ab, b, bc;
    out.triangles.row(4 * t + 2) << ca, bc, c;
    out.triangles.row(4 * t + 3) << ab, bc, ca;
  }
  out.vertices.conservativeResize(made, 3);
  return out;
}

// CGAL's own search with its own traits over the whole mesh: the slow obvious reference.
std::vector<std::pair<std::int32_t, std::int32_t>> CgalSelfIntersectingPairs(const Mesh& mesh) {
  using SurfaceMesh = CGAL::Surface_mesh<Epick::Point_3>;
  std::vector<Epick::Point_3> points;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    points.push_back(ToPoint(mesh.vertices.row(v).transpose()));
  }
  std::vector<std::array<std::size_t, 3>> polygons;
  std::vector<std::int32_t> original;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    polygons.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                        static_cast<std::size_t>(mesh.triangles(t, 1)),
                        static_cast<std::size_t>(mesh.triangles(t, 2))});
    original.push_back(static_cast<std::int32_t>(t));
  }
  SurfaceMesh surface;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, polygons, surface);
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> found;
  CGAL::Polygon_mesh_processing::self_intersections<CGAL::Sequential_tag>(
      surface, std::back_inserter(found));
  std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
  for (const auto& [f, g] : found) {
    const std::int32_t a = original[f.idx()], b = original[g.idx()];
    pairs.emplace_back(std::min(a, b), std::max(a, b));
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

// `mesh` without its triangle `t`: a hole, bordered by three edges.
Mesh WithoutTriangle(const Mesh& mesh, Eigen::Index t) {
  Mesh out = mesh;
  out.triangles.row(t) = out.triangles.row(out.triangles.rows() - 1);
  out.triangles.conservativeResize(out.triangles.rows() - 1, 3);
  return out;
}

// The screened search (shadows first, CGAL's test for the rest, on a surface linked from the
// edge groups) reports exactly CGAL's pairs on CGAL's own conversion of the soup: on nearly flat
// surfaces (subdivided CAD and box meshes, where the screen decides most neighbours), crossing
// themselves or not, on crumpled real meshes, and on open ones (linked by CGAL's conversion).
TEST(SelfIntersectingPairs, ScreenedSearchFindsExactlyCgalsPairs) {
  INSCRIBE_REQUIRE_MESH("fandisk.off");
  INSCRIBE_REQUIRE_MESH("eight.off");
  INSCRIBE_REQUIRE_MESH("knot1.off");
  const Mesh fandisk = Subdivided(testing::LoadTestMesh("fandisk.off"));
  Mesh pierced = Subdivided(Subdivided(UnitCube()));
  pierced.vertices.row(7) << 0.3, 0.3, -0.5;
  const Mesh knot = Crumpled(testing::LoadTestMesh("knot1.off"), 7);
  const std::vector<std::pair<std::string, Mesh>> cases = {
      {"knot1, crumpled", knot},
      {"knot1, crumpled, open", WithoutTriangle(WithoutTriangle(knot, 5), 4000)},
      {"fandisk subdivided, crumpled, open", WithoutTriangle(Crumpled(fandisk, 5), 100)},
      {"fandisk subdivided", fandisk},
      {"fandisk subdivided, crumpled", Crumpled(fandisk, 5)},
      {"eight subdivided twice, crumpled",
       Crumpled(Subdivided(Subdivided(testing::LoadTestMesh("eight.off"))), 6)},
      {"cube subdivided twice, pierced", pierced},
      {"boxes subdivided, overlapping",
       Concatenate(Subdivided(UnitCube()),
                   Subdivided(Box(Vector3::Constant(0.5), Vector3::Constant(1.5))))},
  };
  for (const auto& [name, mesh] : cases) {
    const auto screened = internal::SelfIntersectingPairs(mesh);
    ASSERT_TRUE(screened) << name;
    EXPECT_EQ(*screened, CgalSelfIntersectingPairs(mesh)) << name;
    if (name != "fandisk subdivided") {
      EXPECT_GT(screened->size(), 0u) << name;
    }
  }
}

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

namespace inscribe {
namespace {

// CGAL's own verdict on the same soup: the slow obvious reference of IsOrientedManifold.
bool CgalSaysPolygonMesh(const Mesh& mesh) {
  std::vector<std::array<std::size_t, 3>> polygons;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    polygons.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                        static_cast<std::size_t>(mesh.triangles(t, 1)),
                        static_cast<std::size_t>(mesh.triangles(t, 2))});
  }
  return CGAL::Polygon_mesh_processing::is_polygon_soup_a_polygon_mesh(polygons);
}

TEST(IsOrientedManifold, AgreesWithCgalOnRealAndBrokenMeshes) {
  std::vector<std::pair<std::string, Mesh>> cases;
  for (const char* name : {"eight.off", "knot1.off", "fandisk.off"}) {
    cases.emplace_back(name, testing::LoadTestMesh(name));
  }
  const Mesh cube = testing::Box(Vector3::Zero(), Vector3::Ones());
  cases.emplace_back("cube", cube);
  Mesh flipped = cube;
  std::swap(flipped.triangles(3, 1), flipped.triangles(3, 2));
  cases.emplace_back("one triangle flipped", flipped);
  Mesh open = cube;
  open.triangles.conservativeResize(open.triangles.rows() - 1, 3);
  cases.emplace_back("open (a border)", open);
  Mesh three = cube;  // an edge in three triangles
  three.triangles.conservativeResize(three.triangles.rows() + 1, 3);
  three.triangles.row(three.triangles.rows() - 1) = cube.triangles.row(0);
  std::swap(three.triangles(three.triangles.rows() - 1, 1),
            three.triangles(three.triangles.rows() - 1, 2));
  cases.emplace_back("edge in three triangles", three);
  // Two cubes sharing one corner vertex: two fans at that vertex.
  Mesh bowtie;
  bowtie.vertices.resize(2 * cube.vertices.rows() - 1, 3);
  bowtie.vertices.topRows(cube.vertices.rows()) = cube.vertices;
  Eigen::Index shared = 0;
  for (Eigen::Index v = 0; v < cube.vertices.rows(); ++v) {
    if (cube.vertices.row(v).isZero()) shared = v;
  }
  std::vector<Eigen::Index> second(static_cast<std::size_t>(cube.vertices.rows()));
  Eigen::Index next = cube.vertices.rows();
  for (Eigen::Index v = 0; v < cube.vertices.rows(); ++v) {
    if (v == shared) {
      second[static_cast<std::size_t>(v)] = shared;
      continue;
    }
    second[static_cast<std::size_t>(v)] = next;
    bowtie.vertices.row(next++) = -cube.vertices.row(v);  // the mirror cube
  }
  bowtie.triangles.resize(2 * cube.triangles.rows(), 3);
  for (Eigen::Index t = 0; t < cube.triangles.rows(); ++t) {
    bowtie.triangles.row(t) = cube.triangles.row(t);
    for (int k = 0; k < 3; ++k) {
      // Mirroring flips orientation: walk the corners backwards.
      bowtie.triangles(cube.triangles.rows() + t, k) =
          static_cast<std::int32_t>(second[static_cast<std::size_t>(cube.triangles(t, 2 - k))]);
    }
  }
  cases.emplace_back("two cubes at one vertex", bowtie);
  int manifold = 0;
  for (const auto& [name, mesh] : cases) {
    SCOPED_TRACE(name);
    const bool ours = internal::IsOrientedManifold(mesh);
    EXPECT_EQ(ours, CgalSaysPolygonMesh(mesh));
    manifold += ours;
  }
  EXPECT_EQ(manifold, 5);  // the three meshes, the cube and the open cube
}

}  // namespace
}  // namespace inscribe

namespace inscribe {
namespace {

// The slow obvious order: every use of every triangle with distinct corners, compared whole.
std::vector<internal::EdgeUse> ComparisonSortedEdgeUses(const Mesh& mesh) {
  std::vector<internal::EdgeUse> uses;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = mesh.triangles(t, k);
      const std::int32_t b = mesh.triangles(t, (k + 1) % 3);
      uses.push_back({std::min(a, b), std::max(a, b), static_cast<std::int32_t>(t),
                      static_cast<std::int8_t>(k), a < b});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const internal::EdgeUse& x, const internal::EdgeUse& y) {
    return std::tie(x.lo, x.hi, x.triangle, x.side) < std::tie(y.lo, y.hi, y.triangle, y.side);
  });
  return uses;
}

void ExpectSameUses(const Mesh& mesh) {
  const std::vector<internal::EdgeUse> fast = internal::SortedEdgeUses(mesh);
  const std::vector<internal::EdgeUse> slow = ComparisonSortedEdgeUses(mesh);
  ASSERT_EQ(fast.size(), slow.size());
  for (std::size_t i = 0; i < fast.size(); ++i) {
    ASSERT_EQ(std::tie(fast[i].lo, fast[i].hi, fast[i].triangle, fast[i].side, fast[i].forward),
              std::tie(slow[i].lo, slow[i].hi, slow[i].triangle, slow[i].side, slow[i].forward))
        << "use " << i;
  }
}

TEST(SortedEdgeUses, SameOrderAsTheComparisonSort) {
  for (const char* name : {"eight.off", "fandisk.off", "bunny00.off"}) {
    SCOPED_TRACE(name);
    ExpectSameUses(testing::LoadTestMesh(name));
  }
  // Random soups: repeated and degenerate triangles, a vertex shared by hundreds (its uses
  // sorted by comparison), indices out of range and negative (the comparison fallback).
  std::mt19937_64 rng(3);
  for (int round = 0; round < 6; ++round) {
    SCOPED_TRACE(round);
    Mesh soup;
    soup.vertices.resize(50, 3);
    soup.vertices.setZero();
    std::uniform_int_distribution<std::int32_t> vertex(0, round < 4 ? 49 : 60);
    soup.triangles.resize(900, 3);
    for (Eigen::Index t = 0; t < soup.triangles.rows(); ++t) {
      for (int k = 0; k < 3; ++k)
        soup.triangles(t, k) = t % 3 == 0 ? (k == 0 ? 7 : vertex(rng)) : vertex(rng);
    }
    if (round == 5) soup.triangles(4, 1) = -3;
    ExpectSameUses(soup);
  }
}

}  // namespace
}  // namespace inscribe
