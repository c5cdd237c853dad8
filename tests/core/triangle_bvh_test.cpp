// TriangleBvh (core/src/solid/triangle_bvh.h, private) against the slow obvious answers: a scan of
// every triangle with the same double-precision routines. The BVH promises the scan's answer
// bit for bit (ties to the lowest triangle index), so every comparison here is exact.
#include "solid/triangle_bvh.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "support/brute_force_closest_point.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe::internal {
namespace {

using ::inscribe::testing::BruteForceClosest;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

Vector3 Corner(const Mesh& mesh, Eigen::Index t, int k) {
  return mesh.vertices.row(mesh.triangles(t, k)).transpose();
}

// The winding number around p by XRayCrossing over every triangle, and whether one holds p.
int ScanWinding(const Mesh& mesh, const Vector3& p, bool* on_surface) {
  int winding = 0;
  *on_surface = false;
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    const int crossing =
        XRayCrossing(p, Corner(mesh, t, 0), Corner(mesh, t, 1), Corner(mesh, t, 2));
    if (crossing == kOnTriangle) {
      *on_surface = true;
    } else {
      winding += crossing;
    }
  }
  return winding;
}

bool Identical(const BoundaryPoint& a, const BoundaryPoint& b) {
  return a.triangle == b.triangle && a.point == b.point && a.barycentric == b.barycentric &&
         a.distance == b.distance;
}

std::string Describe(const BoundaryPoint& b) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "triangle %d, point (%.17g, %.17g, %.17g), distance %.17g",
                b.triangle, b.point.x(), b.point.y(), b.point.z(), b.distance);
  return buffer;
}

// Query points of seven kinds, `per_kind` each: on the surface, near it (within 2% of the bbox
// diagonal), anywhere in the bbox, far away (a box ten times larger), exactly on vertices, on
// edge midpoints, and on the surface pushed a hair (1e-9 diagonal) along a random direction.
std::vector<Vector3> QueryPoints(const Mesh& mesh, int per_kind, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<Eigen::Index> pick_triangle(0, mesh.num_triangles() - 1);
  std::uniform_int_distribution<int> pick_corner(0, 2);
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const double diag = box.diagonal();
  const auto random_direction = [&] {
    const Vector3 v(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    return v.norm() > 0.0 ? Vector3(v.normalized()) : Vector3(Vector3::UnitX());
  };
  std::vector<Vector3> points;
  for (int i = 0; i < per_kind; ++i) {
    const Eigen::Index t = pick_triangle(rng);
    double a = unit(rng), b = unit(rng);
    if (a + b > 1) a = 1 - a, b = 1 - b;
    const Vector3 on =
        (1 - a - b) * Corner(mesh, t, 0) + a * Corner(mesh, t, 1) + b * Corner(mesh, t, 2);
    const int k = pick_corner(rng);
    points.push_back(on);
    points.push_back(on + 0.02 * diag * unit(rng) * random_direction());
    points.push_back(box.min + box.extent().cwiseProduct(Vector3(unit(rng), unit(rng), unit(rng))));
    points.push_back(box.min - 4.5 * box.extent() +
                     10 * box.extent().cwiseProduct(Vector3(unit(rng), unit(rng), unit(rng))));
    points.push_back(Corner(mesh, t, k));
    points.push_back(0.5 * (Corner(mesh, t, k) + Corner(mesh, t, (k + 1) % 3)));
    points.push_back(on + 1e-9 * diag * random_direction());
  }
  return points;
}

// Fails (at most five messages) wherever the BVH and the scan differ in any bit.
void ExpectClosestMatchesBruteForce(const Mesh& mesh, const TriangleBvh& bvh,
                                    const std::vector<Vector3>& points) {
  int failures = 0;
  for (std::size_t i = 0; i < points.size() && failures < 5; ++i) {
    const BoundaryPoint expected = BruteForceClosest(mesh, points[i]);
    const BoundaryPoint got = bvh.ClosestPoint(points[i]);
    if (!Identical(got, expected)) {
      ++failures;
      ADD_FAILURE() << "query " << i << " at " << points[i].transpose() << ": BVH " << Describe(got)
                    << "; scan " << Describe(expected);
    }
  }
}

// 500 random triangles in the unit box, with the cases a mesh that passed PrepareMesh would
// not have: zero-area triangles (collinear corners, repeated corners, a single point), slivers,
// exact duplicates (exact ties) and a triangle with its corners in the other order.
Mesh TriangleSoup(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto random_point = [&] { return Vector3(unit(rng), unit(rng), unit(rng)); };
  std::vector<Vector3> vertices;
  std::vector<std::array<std::int32_t, 3>> triangles;
  const auto add = [&](const Vector3& a, const Vector3& b, const Vector3& c) {
    const auto v = static_cast<std::int32_t>(vertices.size());
    vertices.insert(vertices.end(), {a, b, c});
    triangles.push_back({v, v + 1, v + 2});
  };
  for (int i = 0; i < 400; ++i) {
    const Vector3 a = random_point();
    add(a, a + 0.1 * (random_point() - Vector3::Constant(0.5)),
        a + 0.1 * (random_point() - Vector3::Constant(0.5)));
  }
  for (int i = 0; i < 20; ++i) {
    const Vector3 a = random_point(), d = random_point() - Vector3::Constant(0.5);
    add(a, a + 0.25 * d, a + 0.75 * d);            // collinear (up to rounding)
    add(a, a, a + d);                              // repeated corner
    add(a, a, a);                                  // a point
    add(a, a + d, a + d + 1e-9 * random_point());  // sliver
  }
  const std::size_t originals = triangles.size();
  for (std::size_t i = 0; i < 20; ++i) triangles.push_back(triangles[7 * i]);  // duplicates
  for (std::size_t i = 0; i < 10; ++i) {
    const auto& t = triangles[11 * i];
    triangles.push_back({t[2], t[1], t[0]});  // same triangle, other orientation
  }
  EXPECT_GT(triangles.size(), originals);
  Mesh mesh;
  mesh.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    mesh.vertices.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  }
  mesh.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      mesh.triangles(static_cast<Eigen::Index>(t), k) = triangles[t][static_cast<std::size_t>(k)];
    }
  }
  return mesh;
}

Mesh Translated(Mesh mesh, const Vector3& offset) {
  mesh.vertices.rowwise() += offset.transpose();
  return mesh;
}

Mesh Scaled(Mesh mesh, double factor) {
  mesh.vertices *= factor;
  return mesh;
}

TEST(TriangleBvh, ClosestPointEqualsScanOnSyntheticMeshes) {
  const std::vector<std::pair<std::string, Mesh>> meshes = {
      {"unit cube", testing::UnitCube()},
      {"icosphere", testing::Icosphere(4, Vector3(0.3, -0.2, 5), 0.7)},
      {"hollow box", testing::Concatenate(
                         testing::Box(Vector3(-2, -2, -2), Vector3(2, 2, 2)),
                         testing::Inverted(testing::Box(Vector3(-1, -1, -1), Vector3(1, 1, 1))))},
      {"triangle soup", TriangleSoup(7)},
      {"far from the origin", Translated(testing::Icosphere(3), Vector3(1e4, -3e4, 2e4))},
      {"tiny", Scaled(testing::Icosphere(3, Vector3(1, 2, 3)), 1e-7)},
      {"one triangle", [] {
         Mesh m = testing::UnitCube();
         m.triangles.conservativeResize(1, 3);
         return m;
       }()},
  };
  for (const auto& [name, mesh] : meshes) {
    SCOPED_TRACE(name);
    const TriangleBvh bvh = TriangleBvh::Build(mesh);
    ExpectClosestMatchesBruteForce(mesh, bvh, QueryPoints(mesh, 150, 21));
  }
}

// Found by fuzz_requests under UBSan: centroids a subnormal distance apart made the binning
// scale overflow and cast NaN to int. The scan and the BVH must still agree bit for bit.
TEST(TriangleBvh, SubnormalCentroidExtent) {
  const int n = 64;  // well over a leaf, so the builder bins
  Mesh mesh;
  mesh.vertices.resize(3 * n, 3);
  mesh.triangles.resize(n, 3);
  for (int k = 0; k < n; ++k) {
    const double x = std::numeric_limits<double>::denorm_min() * (k + 1);
    mesh.vertices.row(3 * k) = Vector3(x, 0, 0);
    mesh.vertices.row(3 * k + 1) = Vector3(x, 1, 0);
    mesh.vertices.row(3 * k + 2) = Vector3(x, 0, 1);
    mesh.triangles.row(k) << 3 * k, 3 * k + 1, 3 * k + 2;
  }
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  ExpectClosestMatchesBruteForce(mesh, bvh, QueryPoints(mesh, 20, 5));
}

TEST(TriangleBvh, ExactTiesGoToTheLowestTriangle) {
  // The cube's centre is equally far (0.5) from all 12 triangles; a point above a face's
  // diagonal is equally far from that face's two triangles.
  const Mesh cube = testing::UnitCube();
  const TriangleBvh bvh = TriangleBvh::Build(cube);
  const BoundaryPoint centre = bvh.ClosestPoint(Vector3(0.5, 0.5, 0.5));
  EXPECT_EQ(centre.triangle, 0);
  EXPECT_EQ(centre.distance, 0.5);
  for (const Vector3& p : {Vector3(0.5, 0.5, 1.5), Vector3(0.25, 0.25, -3), Vector3(2, 0.3, 0.7)}) {
    EXPECT_TRUE(Identical(bvh.ClosestPoint(p), BruteForceClosest(cube, p))) << p.transpose();
  }
  // Duplicated triangles everywhere: every answer is an exact tie.
  const Mesh doubled = testing::Concatenate(testing::Icosphere(2), testing::Icosphere(2));
  const TriangleBvh doubled_bvh = TriangleBvh::Build(doubled);
  for (const Vector3& p : QueryPoints(doubled, 50, 22)) {
    const BoundaryPoint got = doubled_bvh.ClosestPoint(p);
    EXPECT_LT(got.triangle, doubled.num_triangles() / 2) << p.transpose();
    EXPECT_TRUE(Identical(got, BruteForceClosest(doubled, p))) << p.transpose();
  }
}

// A flat 40 x 40 grid of unit squares in the plane x = 0, integer coordinates (0, i, j): every
// box bound is a float exactly, so box boundaries carry no slack from rounding outward, and the
// rays along +x pass exactly through its vertices and edges.
Mesh Grid() {
  constexpr int kN = 40;
  Mesh mesh;
  mesh.vertices.resize((kN + 1) * (kN + 1), 3);
  for (int i = 0; i <= kN; ++i) {
    for (int j = 0; j <= kN; ++j) mesh.vertices.row(i * (kN + 1) + j) << 0, i, j;
  }
  mesh.triangles.resize(2 * kN * kN, 3);
  for (int i = 0; i < kN; ++i) {
    for (int j = 0; j < kN; ++j) {
      const int v = i * (kN + 1) + j;
      mesh.triangles.row(2 * (i * kN + j)) << v, v + kN + 1, v + 1;
      mesh.triangles.row(2 * (i * kN + j) + 1) << v + 1, v + kN + 1, v + kN + 2;
    }
  }
  return mesh;
}

// Rays through grid vertices and edges: the perturbed ray must cross the sheet exactly once
// (every triangle faces +x: a crossing of +1) wherever its origin's (y, z) lies in
// [0, 40) x [0, 40), never outside it, the BVH must find what the scan finds, and an origin on
// the sheet is on it.
TEST(TriangleBvh, RaysThroughVerticesAndEdgesCrossTheSheetOnce) {
  const Mesh grid = Grid();
  const TriangleBvh bvh = TriangleBvh::Build(grid);
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> coordinate(-1, 41);
  int failures = 0;
  for (int i = 0; i < 4000; ++i) {
    Vector3 origin(-1 - 10 * unit(rng), coordinate(rng), coordinate(rng));
    if (i % 3 == 1) origin.y() += unit(rng);  // a point on an edge
    if (i % 5 == 0) origin.x() = 0.0;         // on the sheet (or its plane)
    const bool in_range = origin.y() >= 0 && origin.y() < 40 && origin.z() >= 0 && origin.z() < 40;
    bool scan_on = false, bvh_on = false;
    const int scan = ScanWinding(grid, origin, &scan_on);
    const int got = bvh.XRayWinding(origin, &bvh_on);
    const bool on_plane = origin.x() == 0.0;
    const bool holds = origin.y() >= 0 && origin.y() <= 40 && origin.z() >= 0 && origin.z() <= 40;
    const int expected = on_plane ? 0 : (in_range ? 1 : 0);
    if ((got != scan || bvh_on != scan_on || (!on_plane && got != expected) ||
         (on_plane && in_range && !bvh_on) || (bvh_on && !(on_plane && holds))) &&
        failures++ < 5) {
      ADD_FAILURE() << "ray from " << origin.transpose() << ": BVH winding " << got << " (on "
                    << bvh_on << "), scan " << scan << " (on " << scan_on << "), expected "
                    << expected;
    }
  }
  EXPECT_EQ(failures, 0);
}

// Float boxes must contain the double points they bound: RoundDown / RoundUp give the nearest
// float on the requested side, and the bit arithmetic behind them matches std::nextafter.
TEST(TriangleBvh, RoundingToFloatIsDirected) {
  std::mt19937_64 rng(30);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-140, 120);
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::vector<double> values = {0.0, -0.0, 1.0, -1.0, 1e-45, -1e-45, 3.4e38, -3.4e38};
  for (int i = 0; i < 100000; ++i) values.push_back(std::ldexp(mantissa(rng), exponent(rng)));
  for (const double x : values) {
    const float down = RoundDown(x), up = RoundUp(x);
    ASSERT_LE(static_cast<double>(down), x) << x;
    ASSERT_GT(static_cast<double>(std::nextafter(down, kInf)), x) << x;
    ASSERT_GE(static_cast<double>(up), x) << x;
    ASSERT_LT(static_cast<double>(std::nextafter(up, -kInf)), x) << x;
    const auto f = static_cast<float>(x);
    ASSERT_EQ(NextFloatDown(f), std::nextafter(f, -kInf)) << f;
    ASSERT_EQ(NextFloatUp(f), std::nextafter(f, kInf)) << f;
  }
  EXPECT_EQ(NextFloatDown(std::numeric_limits<float>::max()),
            std::nextafter(std::numeric_limits<float>::max(), 0.0f));
}

class TriangleBvhOnMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(TriangleBvhOnMesh, ClosestPointEqualsScan) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  // About 10^7 triangle tests per mesh for the scan.
  const int per_kind =
      static_cast<int>(std::clamp<std::int64_t>(1'500'000 / mesh.num_triangles(), 4, 200));
  ExpectClosestMatchesBruteForce(mesh, bvh, QueryPoints(mesh, per_kind, 23));
}

TEST_P(TriangleBvhOnMesh, BoundedQueryEqualsUnbounded) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  std::mt19937_64 rng(24);
  std::uniform_int_distribution<Eigen::Index> pick(0, mesh.num_vertices() - 1);
  int failures = 0;
  TriangleBvhStats unbounded_work, bounded_work;
  for (const Vector3& p : QueryPoints(mesh, 60, 25)) {
    const BoundaryPoint expected = bvh.ClosestPoint(p, kInfinity, &unbounded_work);
    const Vector3 known = mesh.vertices.row(pick(rng)).transpose();
    // Bounds a caller may know: the answer itself, a little more, the distance to any boundary
    // point (a vertex).
    for (const double bound :
         {expected.distance, std::nextafter(expected.distance, 0.0),
          expected.distance * (1 + 1e-15), 1.5 * expected.distance + 1e-3, (p - known).norm()}) {
      if (!(bound >= expected.distance * (1 - 1e-15))) continue;
      const BoundaryPoint got = bvh.ClosestPoint(p, bound, &bounded_work);
      if (!Identical(got, expected) && failures++ < 5) {
        ADD_FAILURE() << "query at " << p.transpose() << " bound " << bound << ": " << Describe(got)
                      << "; unbounded " << Describe(expected);
      }
    }
    // A bound below the true distance breaks the caller's promise: no answer. NaN: no bound.
    if (expected.distance > 1e-6) {
      for (const double broken : {0.5 * expected.distance, 0.0, -1.0}) {
        EXPECT_EQ(bvh.ClosestPoint(p, broken).triangle, -1) << p.transpose() << " " << broken;
      }
    }
    EXPECT_TRUE(Identical(bvh.ClosestPoint(p, std::numeric_limits<double>::quiet_NaN()), expected));
  }
  EXPECT_EQ(failures, 0);
  // The tight bound must let the search skip work (per query: compare with 5 bounded ones).
  EXPECT_LT(bounded_work.triangles, 5 * unbounded_work.triangles);
}

TEST_P(TriangleBvhOnMesh, XRayWindingEqualsScan) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  std::mt19937_64 rng(26);
  // About 10^7 triangle tests for the scan.
  std::vector<Vector3> origins = QueryPoints(
      mesh, static_cast<int>(std::clamp<std::int64_t>(800'000 / mesh.num_triangles(), 6, 60)), 27);
  // Origins whose ray runs exactly through a vertex or along an edge's (y, z) line, and
  // origins on a vertex: where the perturbation decides.
  std::uniform_int_distribution<Eigen::Index> pick(0, mesh.num_triangles() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::size_t given = origins.size();
  for (std::size_t i = 0; i < given; ++i) {
    const Eigen::Index t = pick(rng);
    const Vector3 a = Corner(mesh, t, 0), b = Corner(mesh, t, 1);
    origins.emplace_back(origins[i].x(), a.y(), a.z());
    origins.emplace_back(origins[i].x(), a.y(), 0.5 * (a.z() + b.z()));
    if (i % 8 == 0) origins.push_back(a);
  }
  int failures = 0;
  for (const Vector3& o : origins) {
    bool scan_on = false, bvh_on = false;
    const int expected = ScanWinding(mesh, o, &scan_on);
    const int got = bvh.XRayWinding(o, &bvh_on);
    if ((got != expected || bvh_on != scan_on) && failures++ < 5) {
      ADD_FAILURE() << "ray from " << o.transpose() << ": BVH " << got << " (on " << bvh_on
                    << "), scan " << expected << " (on " << scan_on << ")";
    }
    // A closed surface (as the file orients it): winding +-1 inside, 0 outside, except where
    // cow's self-intersecting sheets overlap.
    if (!scan_on && std::abs(expected) > (GetParam() == std::string("cow.off") ? 2 : 1) &&
        failures++ < 5) {
      ADD_FAILURE() << "winding " << expected << " at " << o.transpose();
    }
  }
  EXPECT_EQ(failures, 0);
}

// Every stored bit of two trees: topology, boxes, leaf frames, copied corners.
void ExpectSameTree(const TriangleBvh& a, const TriangleBvh& b) {
  ASSERT_EQ(a.nodes().size(), b.nodes().size());
  ASSERT_EQ(a.leaves().size(), b.leaves().size());
  ASSERT_EQ(a.slot_boxes().size(), b.slot_boxes().size());
  EXPECT_EQ(a.root().index, b.root().index);
  EXPECT_EQ(a.root().count, b.root().count);
  EXPECT_EQ(
      std::memcmp(a.nodes().data(), b.nodes().data(), b.nodes().size() * sizeof(TriangleBvhNode)),
      0);
  EXPECT_EQ(std::memcmp(a.leaves().data(), b.leaves().data(),
                        b.leaves().size() * sizeof(TriangleBvhLeaf)),
            0);
  EXPECT_EQ(std::memcmp(a.slot_boxes().data(), b.slot_boxes().data(),
                        b.slot_boxes().size() * sizeof(TriangleBvhSlotBox)),
            0);
  EXPECT_EQ(a.corners(), b.corners());
  EXPECT_EQ(a.slot_triangles(), b.slot_triangles());
  EXPECT_EQ(a.magnitude(), b.magnitude());
}

TEST_P(TriangleBvhOnMesh, RefitEqualsFreshBuild) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  // A smooth bend, stretch and shear: same triangles, new positions.
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  Mesh deformed = mesh;
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    const Vector3 p = (mesh.vertices.row(v).transpose() - box.min).cwiseQuotient(box.extent());
    deformed.vertices.row(v) +=
        box.extent()
            .cwiseProduct(Vector3(0.1 * std::sin(3 * p.y()), 0.3 * p.y(), 0.05 * p.x() * p.x()))
            .transpose();
  }
  const TriangleBvh fresh = TriangleBvh::Build(mesh);
  TriangleBvh refit = TriangleBvh::Build(mesh);
  refit.Refit(deformed);
  // Queries on the refit tree: exactly the fresh tree's (and the scan's) answers.
  const TriangleBvh fresh_deformed = TriangleBvh::Build(deformed);
  const std::vector<Vector3> points = QueryPoints(
      deformed, static_cast<int>(std::clamp<std::int64_t>(1'000'000 / mesh.num_triangles(), 2, 30)),
      28);
  for (const Vector3& p : points) {
    const BoundaryPoint got = refit.ClosestPoint(p);
    ASSERT_TRUE(Identical(got, fresh_deformed.ClosestPoint(p))) << p.transpose();
  }
  ExpectClosestMatchesBruteForce(deformed, refit, points);
  // Refit back to the original positions: every stored bit as Build left it.
  refit.Refit(mesh);
  ExpectSameTree(refit, fresh);
}

// The build splits large ranges in parallel: on one thread and on all, the same tree, bit for bit.
TEST_P(TriangleBvhOnMesh, BuildDoesNotDependOnTheThreads) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const TriangleBvh parallel = TriangleBvh::Build(mesh);
  tbb::task_arena one_thread(1);
  const TriangleBvh serial = one_thread.execute([&] { return TriangleBvh::Build(mesh); });
  ExpectSameTree(serial, parallel);
}

// Every bound the queries rely on: each triangle in exactly one leaf, boxes containing what
// they bound, leaf axes orthonormal, the tree shallow enough for the fixed traversal stack.
TEST_P(TriangleBvhOnMesh, StructureInvariants) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  std::vector<int> seen(static_cast<std::size_t>(mesh.num_triangles()), 0);
  for (const std::int32_t t : bvh.slot_triangles()) ++seen[static_cast<std::size_t>(t)];
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), mesh.num_triangles());
  ASSERT_EQ(bvh.corners().size(), 3 * bvh.slot_triangles().size());
  std::vector<int> slot_in_leaves(bvh.slot_triangles().size(), 0);
  for (const TriangleBvhLeaf& leaf : bvh.leaves()) {
    ASSERT_GE(leaf.count, 1);
    ASSERT_LE(leaf.count, TriangleBvh::kMaxLeafSize);
    const Eigen::Matrix3d axes =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(&leaf.axes[0][0]);
    EXPECT_LT((axes * axes.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    for (std::int32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
      ++slot_in_leaves[static_cast<std::size_t>(s)];
      const TriangleBvhSlotBox& box = bvh.slot_boxes()[static_cast<std::size_t>(s)];
      // Projections computed here round differently from the BVH's (by ulps); the query's
      // culling margin (1e-12 * magnitude) absorbs ten times the tolerance allowed here.
      const double tolerance = 1e-13 * bvh.magnitude();
      for (int k = 0; k < 3; ++k) {
        const Vector3 x = axes * bvh.corners()[3 * static_cast<std::size_t>(s) + k];
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(box.lo[a], x[a] + tolerance);
          EXPECT_GE(box.hi[a], x[a] - tolerance);
          EXPECT_LE(leaf.lo[a], x[a] + tolerance);
          EXPECT_GE(leaf.hi[a], x[a] - tolerance);
        }
      }
    }
  }
  EXPECT_EQ(std::count(slot_in_leaves.begin(), slot_in_leaves.end(), 1),
            static_cast<std::ptrdiff_t>(slot_in_leaves.size()));
  // Walk from the root: every child's box inside its parent's, every corner inside its leaf's
  // axis-aligned box, inner nodes after their parents, depth within the traversal stack.
  struct Item {
    TriangleBvhRef ref;
    int depth;
  };
  std::vector<Item> stack = {{bvh.root(), 0}};
  int max_depth = 0;
  std::vector<int> node_seen(bvh.nodes().size(), 0);
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    max_depth = std::max(max_depth, item.depth);
    if (item.ref.is_leaf()) continue;
    ++node_seen[static_cast<std::size_t>(item.ref.index)];
    const TriangleBvhNode& n = bvh.nodes()[static_cast<std::size_t>(item.ref.index)];
    for (int c = 0; c < 2; ++c) {
      const TriangleBvhRef child = n.child[c];
      if (child.is_leaf()) {
        const TriangleBvhLeaf& leaf = bvh.leaves()[static_cast<std::size_t>(child.index)];
        EXPECT_EQ(leaf.count, child.count);
        for (int j = 3 * leaf.first; j < 3 * (leaf.first + leaf.count); ++j) {
          for (int a = 0; a < 3; ++a) {
            EXPECT_LE(n.lo[a][c], bvh.corners()[static_cast<std::size_t>(j)][a]);
            EXPECT_GE(n.hi[a][c], bvh.corners()[static_cast<std::size_t>(j)][a]);
          }
        }
      } else {
        EXPECT_GT(child.index, item.ref.index);
        const TriangleBvhNode& m = bvh.nodes()[static_cast<std::size_t>(child.index)];
        for (int a = 0; a < 3; ++a) {
          for (int cc = 0; cc < 2; ++cc) {
            EXPECT_LE(n.lo[a][c], m.lo[a][cc]);
            EXPECT_GE(n.hi[a][c], m.hi[a][cc]);
          }
        }
      }
      stack.push_back({child, item.depth + 1});
    }
  }
  EXPECT_EQ(std::count(node_seen.begin(), node_seen.end(), 1),
            static_cast<std::ptrdiff_t>(node_seen.size()));
  EXPECT_LE(max_depth, 80);
}

// Culling must actually cull: a query far outside tests a small fraction of the triangles.
TEST_P(TriangleBvhOnMesh, QueriesTestFewTriangles) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Mesh mesh = testing::LoadTestMesh(GetParam());
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  const std::vector<Vector3> points = QueryPoints(mesh, 50, 29);
  TriangleBvhStats stats;
  for (const Vector3& p : points) bvh.ClosestPoint(p, kInfinity, &stats);
  const double per_query =
      static_cast<double>(stats.triangles) / static_cast<double>(points.size());
  EXPECT_LT(per_query, 0.05 * static_cast<double>(mesh.num_triangles()) + 40) << per_query;
}

INSTANTIATE_TEST_SUITE_P(Meshes, TriangleBvhOnMesh,
                         ::testing::Values("eight.off", "cow.off", "elephant.off", "fandisk.off",
                                           "knot1.off", "bunny00.off"),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           return name.substr(0, name.find('.'));
                         });

}  // namespace
}  // namespace inscribe::internal
