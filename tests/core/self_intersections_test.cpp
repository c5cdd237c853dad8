// The self-intersection search (self_intersections.h) against CGAL's own: slabs, the shadow
// screen and the surface linked from edge groups find exactly CGAL's pairs.
#include "solid/self_intersections.h"  // private: core/src

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "mesh/mesh_topology.h"  // private: core/src
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::Box;
using testing::Concatenate;
using testing::UnitCube;

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
