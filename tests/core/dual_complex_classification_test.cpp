// ComputeDualComplex classifies the regular triangulation at alpha = 0 itself; these tests
// compare it, simplex for simplex, with CGAL's Fixed_alpha_shape_3 on the same input
// (testing::FixedAlphaShapeDualComplex), on random and on degenerate sets.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "inscribe/balls/union_of_balls.h"
#include "support/fixed_alpha_shape_dual_complex.h"
#include "support/sphere_sets.h"

namespace inscribe {
namespace {

using testing::FixedAlphaShapeDualComplex;
using testing::RandomBalls;

Sphere Ball(double x, double y, double z, double r) { return Sphere{Vector3(x, y, z), r}; }

// The direct complex of `balls`, after checking it equals the reference.
DualComplex ExpectSameComplex(const std::vector<Sphere>& balls, const std::string& what) {
  const absl::StatusOr<DualComplex> direct = ComputeDualComplex(balls);
  const DualComplex reference = FixedAlphaShapeDualComplex(balls);
  EXPECT_TRUE(direct.ok()) << what << ": " << direct.status();
  if (!direct.ok()) return {};
  EXPECT_EQ(direct->vertices, reference.vertices) << what;
  EXPECT_EQ(direct->edges, reference.edges) << what;
  EXPECT_EQ(direct->triangles, reference.triangles) << what;
  EXPECT_EQ(direct->tetrahedra, reference.tetrahedra) << what;
  EXPECT_EQ(direct->redundant, reference.redundant) << what;
  return *direct;
}

// Edges in no triangle and triangles in no tetrahedron: the simplices that only the Gabriel
// rules admit.
std::size_t SingularSimplices(const DualComplex& c) {
  std::set<std::array<std::int32_t, 2>> covered_edges;
  for (const auto& t : c.triangles) {
    covered_edges.insert({{t[0], t[1]}});
    covered_edges.insert({{t[0], t[2]}});
    covered_edges.insert({{t[1], t[2]}});
  }
  std::set<std::array<std::int32_t, 3>> covered_triangles;
  for (const auto& t : c.tetrahedra) {
    for (int skip = 0; skip < 4; ++skip) {
      std::array<std::int32_t, 3> face;
      for (int k = 0, j = 0; k < 4; ++k) {
        if (k != skip) face[static_cast<std::size_t>(j++)] = t[static_cast<std::size_t>(k)];
      }
      covered_triangles.insert(face);
    }
  }
  std::size_t n = 0;
  for (const auto& e : c.edges) n += covered_edges.count(e) == 0;
  for (const auto& t : c.triangles) n += covered_triangles.count(t) == 0;
  return n;
}

TEST(DualComplexClassification, MatchesFixedAlphaShapeOnRandomSets) {
  std::size_t singular = 0;
  std::size_t redundant = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    for (int n : {5, 60, 700}) {
      const double side = std::cbrt(static_cast<double>(n));
      const std::string size = " n=" + std::to_string(n) + " seed=" + std::to_string(seed);
      ExpectSameComplex(RandomBalls(n, side, 0.6, 1.2, seed), "dense" + size);
      // Sparse (isolated balls, singular edges and triangles) and mixed (many hidden).
      singular += SingularSimplices(
          ExpectSameComplex(RandomBalls(n, 3 * side, 0.2, 1.0, seed), "sparse" + size));
      redundant +=
          ExpectSameComplex(RandomBalls(n, side, 0.05, 1.5, seed), "mixed" + size).redundant.size();
    }
  }
  // The sets reach the rules' less common branches.
  EXPECT_GT(singular, 100u);
  EXPECT_GT(redundant, 100u);
}

TEST(DualComplexClassification, MatchesFixedAlphaShapeOnCoSphericalCubeCorners) {
  // Every 4 corners of a face co-circular, all 8 co-spherical; radii on both sides of and at
  // the power vertex's distance sqrt(0.75), and at the face centres' sqrt(0.5).
  for (double r : {0.5, 0.55, std::sqrt(0.5), 0.8, std::sqrt(0.75), 0.9, 1.3}) {
    std::vector<Sphere> balls;
    for (int k = 0; k < 8; ++k) balls.push_back(Ball(k & 1, (k >> 1) & 1, (k >> 2) & 1, r));
    ExpectSameComplex(balls, "cube r=" + std::to_string(r));
  }
}

TEST(DualComplexClassification, MatchesFixedAlphaShapeOnAGridOfEqualBalls) {
  // A 4 x 4 x 4 grid: co-spherical everywhere; tangent (r = 0.5) and overlapping radii.
  for (double r : {0.3, 0.5, std::sqrt(0.5), 0.75, std::sqrt(0.75)}) {
    std::vector<Sphere> balls;
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        for (int k = 0; k < 4; ++k) balls.push_back(Ball(i, j, k, r));
      }
    }
    ExpectSameComplex(balls, "grid r=" + std::to_string(r));
  }
}

TEST(DualComplexClassification, MatchesFixedAlphaShapeOnCoplanarAndCollinearCentres) {
  for (double r : {0.45, 0.5, 0.7071067811865476, 1.5}) {
    std::vector<Sphere> plane;
    std::vector<Sphere> line;
    for (int i = 0; i < 4; ++i) {
      line.push_back(Ball(i, 0.5, -2, r + 0.05 * i));
      for (int j = 0; j < 4; ++j) plane.push_back(Ball(i, j, 0.25, r));
    }
    ExpectSameComplex(plane, "plane r=" + std::to_string(r));
    ExpectSameComplex(line, "line r=" + std::to_string(r));
  }
  ExpectSameComplex({Ball(0, 0, 0, 1)}, "one ball");
  ExpectSameComplex({Ball(0, 0, 0, 1), Ball(1.5, 0, 0, 1)}, "two balls");
}

TEST(DualComplexClassification, MatchesFixedAlphaShapeWithDuplicateAndNestedBalls) {
  std::vector<Sphere> balls = RandomBalls(40, 3.0, 0.6, 1.2, 7);
  const std::vector<Sphere> base = balls;
  balls.insert(balls.end(), base.begin(), base.begin() + 10);  // exact duplicates
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> unit(-0.3, 0.3);
  for (std::size_t k = 0; k < 20; ++k) {
    const Sphere& host = base[k];
    // Nested: strictly inside, internally tangent, and concentric with a smaller radius.
    balls.push_back(
        {host.center + Vector3(unit(rng), unit(rng), unit(rng)) * host.radius, 0.2 * host.radius});
    balls.push_back({host.center + Vector3(0.5 * host.radius, 0, 0), 0.5 * host.radius});
    balls.push_back({host.center, 0.9 * host.radius});
  }
  ExpectSameComplex(balls, "duplicates and nested");
}

// From 2,048 distinct balls the regular triangulation is built by CGAL's parallel insertion
// (with locks); the complex must be the one the reference builds one ball at a time, on random
// sets with hidden balls, on co-spherical grids (symbolic perturbation decides), with
// duplicates and nested balls, and on coplanar centres (the flat triangulation is rebuilt one
// ball at a time and padded).
TEST(DualComplexClassification, MatchesFixedAlphaShapeWhenInsertedInParallel) {
  if (tbb::this_task_arena::max_concurrency() < 2) {
    GTEST_SKIP() << "one thread: nothing is inserted in parallel";
  }
  const int n = 4000;
  const double side = std::cbrt(static_cast<double>(n));
  ExpectSameComplex(RandomBalls(n, side, 0.6, 1.2, 21), "dense");
  const DualComplex mixed = ExpectSameComplex(RandomBalls(n, side, 0.05, 1.5, 22), "mixed");
  EXPECT_GT(mixed.redundant.size(), 100u) << "the mixed set should hide balls";
  for (double r : {0.5, std::sqrt(0.75)}) {
    std::vector<Sphere> grid;
    for (int i = 0; i < 14; ++i) {
      for (int j = 0; j < 14; ++j) {
        for (int k = 0; k < 14; ++k) grid.push_back(Ball(i, j, k, r));
      }
    }
    ExpectSameComplex(grid, "14^3 grid r=" + std::to_string(r));
  }
  std::vector<Sphere> nested = RandomBalls(2500, std::cbrt(2500.0), 0.6, 1.2, 23);
  const std::vector<Sphere> base = nested;
  nested.insert(nested.end(), base.begin(), base.begin() + 300);
  for (std::size_t k = 0; k < 300; ++k) nested.push_back({base[k].center, 0.5 * base[k].radius});
  ExpectSameComplex(nested, "duplicates and nested");
  std::vector<Sphere> plane;
  for (int i = 0; i < 50; ++i) {
    for (int j = 0; j < 50; ++j)
      plane.push_back(Ball(i, j, 0.25, 0.6 + 0.002 * ((i * 7 + j) % 50)));
  }
  ExpectSameComplex(plane, "50 x 50 plane");
}

TEST(DualComplexClassification, SameComplexAndVolumeBitsOnOneThreadAndOnAll) {
  const std::vector<Sphere> balls = RandomBalls(3000, std::cbrt(3000.0), 0.6, 1.2, 9);
  absl::StatusOr<DualComplex> serial_complex;
  absl::StatusOr<double> serial_volume;
  tbb::task_arena one_thread(1);
  one_thread.execute([&] {
    serial_complex = ComputeDualComplex(balls);
    serial_volume = UnionVolume(balls);
  });
  const absl::StatusOr<DualComplex> complex = ComputeDualComplex(balls);
  const absl::StatusOr<double> volume = UnionVolume(balls);
  ASSERT_TRUE(serial_complex.ok() && complex.ok() && serial_volume.ok() && volume.ok());
  EXPECT_EQ(serial_complex->vertices, complex->vertices);
  EXPECT_EQ(serial_complex->redundant, complex->redundant);
  EXPECT_EQ(serial_complex->edges, complex->edges);
  EXPECT_EQ(serial_complex->triangles, complex->triangles);
  EXPECT_EQ(serial_complex->tetrahedra, complex->tetrahedra);
  EXPECT_EQ(std::memcmp(&*serial_volume, &*volume, sizeof(double)), 0)
      << *serial_volume << " vs " << *volume;
}

}  // namespace
}  // namespace inscribe
