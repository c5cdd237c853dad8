#include "inscribe/medial/sphere_dilation.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "inscribe/balls/sphere_quality.h"
#include "inscribe/balls/union_of_balls.h"
#include "inscribe/medial/medial_spheres.h"
#include "support/brute_force_closest_point.h"
#include "support/sphere_sets.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::RandomBalls;

using testing::BruteForceClosest;
using testing::BruteForceDistance;
using testing::Icosphere;
using testing::LoadTestMesh;
using Triple = std::array<std::int32_t, 3>;
using Pair = std::array<std::int32_t, 2>;

// The references decide "inside another sphere" with this band around the sphere (relative to
// its radius); points inside the band are not checked either way.
constexpr double kBand = 1e-9;

BoundaryOracle BuildOracle(const Mesh& mesh) {
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  EXPECT_TRUE(oracle.ok()) << oracle.status();
  return *std::move(oracle);
}

EnvelopePoints Envelope(const std::vector<Sphere>& spheres, const DilationOptions& options = {}) {
  absl::StatusOr<EnvelopePoints> points = ComputeEnvelopePoints(spheres, options);
  EXPECT_TRUE(points.ok()) << points.status();
  return points.ok() ? *std::move(points) : EnvelopePoints{};
}

// Smallest (|x - c| - r) / r over the spheres not in `own`: > 0 outside them all.
double Clearance(const std::vector<Sphere>& spheres, const Vector3& x, const Triple& own) {
  double clearance = std::numeric_limits<double>::infinity();
  for (std::size_t l = 0; l < spheres.size(); ++l) {
    const auto li = static_cast<std::int32_t>(l);
    if (li == own[0] || li == own[1] || li == own[2]) continue;
    clearance = std::min(clearance,
                         ((x - spheres[l].center).norm() - spheres[l].radius) / spheres[l].radius);
  }
  return clearance;
}

// Triple points by trilateration in a frame built on the centres (a different formula from
// the library's radical line): c1 + x ex + y ey +- z ez. Returns the points with z^2 clearly
// positive; `ambiguous` is set when z^2 is within rounding of 0.
std::vector<Vector3> Trilaterate(const Sphere& s1, const Sphere& s2, const Sphere& s3,
                                 bool* ambiguous) {
  using V = Eigen::Matrix<long double, 3, 1>;
  const V c1 = s1.center.cast<long double>();
  const V c2 = s2.center.cast<long double>();
  const V c3 = s3.center.cast<long double>();
  const long double r1 = s1.radius, r2 = s2.radius, r3 = s3.radius;
  const long double d = (c2 - c1).norm();
  const V ex = (c2 - c1) / d;
  const long double i = ex.dot(c3 - c1);
  V ey = c3 - c1 - i * ex;
  const long double j = ey.norm();
  *ambiguous = false;
  if (!(j > 1e-9L * d)) {
    *ambiguous = true;
    return {};
  }
  ey /= j;
  const V ez = ex.cross(ey);
  const long double x = (r1 * r1 - r2 * r2 + d * d) / (2 * d);
  const long double y = (r1 * r1 - r3 * r3 + i * i + j * j) / (2 * j) - i / j * x;
  const long double z2 = r1 * r1 - x * x - y * y;
  if (std::abs(z2) <= 1e-9L * r1 * r1) *ambiguous = true;
  if (!(z2 > 0)) return {};
  const long double z = std::sqrt(z2);
  const V base = c1 + x * ex + y * ey;
  return {(base + z * ez).cast<double>(), (base - z * ez).cast<double>()};
}

bool Sorted(const std::vector<Triple>& list, const Triple& t) {
  return std::binary_search(list.begin(), list.end(), t);
}

// Every envelope point lies on its spheres and is outside every other sphere (brute force over
// all of them); v-points come from triangles of the complex, circle points from its edges in
// no triangle.
void ExpectPointsOnTheEnvelope(const std::vector<Sphere>& spheres, const EnvelopePoints& points,
                               const DualComplex& complex) {
  std::set<Pair> edges_in_triangles;
  for (const Triple& t : complex.triangles) {
    edges_in_triangles.insert({t[0], t[1]});
    edges_in_triangles.insert({t[0], t[2]});
    edges_in_triangles.insert({t[1], t[2]});
  }
  const auto check = [&](const EnvelopePoint& p, bool circle) {
    const int count = circle ? 2 : 3;
    for (int k = 0; k < count; ++k) {
      const Sphere& s = spheres[static_cast<std::size_t>(p.spheres[k])];
      EXPECT_NEAR((p.point - s.center).norm(), s.radius, 1e-9 * s.radius)
          << "sphere " << p.spheres[k];
      if (k > 0) {
        EXPECT_LT(p.spheres[k - 1], p.spheres[k]);
      }
    }
    EXPECT_GT(Clearance(spheres, p.point, p.spheres), -kBand);
    if (circle) {
      EXPECT_EQ(p.spheres[2], -1);
      const Pair e = {p.spheres[0], p.spheres[1]};
      EXPECT_TRUE(std::binary_search(complex.edges.begin(), complex.edges.end(), e));
      EXPECT_EQ(edges_in_triangles.count(e), 0u);
    } else {
      EXPECT_TRUE(Sorted(complex.triangles, p.spheres));
    }
  };
  for (const EnvelopePoint& p : points.v_points) check(p, false);
  for (const EnvelopePoint& p : points.circle_points) check(p, true);
}

// Every triple point of the listed triples that lies clearly outside all other spheres is a
// v-point of that triple. Returns how many such points there were.
std::int64_t ExpectUncoveredTriplePointsKept(const std::vector<Sphere>& spheres,
                                             const std::vector<Triple>& triples,
                                             const EnvelopePoints& points) {
  std::map<Triple, std::vector<Vector3>> kept;
  for (const EnvelopePoint& p : points.v_points) kept[p.spheres].push_back(p.point);
  std::int64_t uncovered = 0;
  for (const Triple& t : triples) {
    bool ambiguous = false;
    const std::vector<Vector3> reference = Trilaterate(
        spheres[static_cast<std::size_t>(t[0])], spheres[static_cast<std::size_t>(t[1])],
        spheres[static_cast<std::size_t>(t[2])], &ambiguous);
    if (ambiguous) continue;
    const double scale = std::max({spheres[static_cast<std::size_t>(t[0])].radius,
                                   spheres[static_cast<std::size_t>(t[1])].radius,
                                   spheres[static_cast<std::size_t>(t[2])].radius});
    for (const Vector3& x : reference) {
      if (!(Clearance(spheres, x, t) > kBand)) continue;
      ++uncovered;
      const auto it = kept.find(t);
      bool found = false;
      if (it != kept.end()) {
        for (const Vector3& v : it->second) found = found || (v - x).norm() <= 1e-7 * scale;
      }
      EXPECT_TRUE(found) << "triple point of (" << t[0] << ", " << t[1] << ", " << t[2] << ") at "
                         << x.transpose() << " is on the envelope but was not kept";
    }
  }
  return uncovered;
}

// Pairs whose circle of intersection no other ball reaches: the minimum distance from another
// centre to the circle exceeds that ball's radius (exact point-to-circle distance). Pairs
// within the band of touching anything are left out of both lists.
void BruteForceFreeCircles(const std::vector<Sphere>& spheres, std::set<Pair>* free,
                           std::set<Pair>* touched) {
  const auto n = static_cast<std::int32_t>(spheres.size());
  for (std::int32_t i = 0; i < n; ++i) {
    for (std::int32_t j = i + 1; j < n; ++j) {
      const Sphere& a = spheres[static_cast<std::size_t>(i)];
      const Sphere& b = spheres[static_cast<std::size_t>(j)];
      const double d = (b.center - a.center).norm();
      if (!(d < (a.radius + b.radius) * (1 - kBand) &&
            d > std::abs(a.radius - b.radius) * (1 + kBand))) {
        continue;
      }
      const Vector3 e = (b.center - a.center) / d;
      const double x = (d * d + a.radius * a.radius - b.radius * b.radius) / (2 * d);
      const double rho = std::sqrt(a.radius * a.radius - x * x);
      const Vector3 m = a.center + x * e;
      bool is_free = true, ambiguous = false;
      for (std::int32_t l = 0; l < n; ++l) {
        if (l == i || l == j) continue;
        const Sphere& s = spheres[static_cast<std::size_t>(l)];
        const Vector3 q = s.center - m;
        const double along = q.dot(e);
        const double across = (q - along * e).norm();
        const double nearest = std::hypot(along, across - rho);
        if (nearest < s.radius * (1 - kBand)) is_free = false;
        if (std::abs(nearest - s.radius) <= kBand * s.radius) ambiguous = true;
      }
      if (ambiguous) continue;
      (is_free ? free : touched)->insert({i, j});
    }
  }
}

// Circle points exist exactly for the pairs whose circle no other ball reaches (brute force),
// two per pair. Returns the numbers of free and touched circles checked.
std::pair<std::int64_t, std::int64_t> ExpectCirclePointsOnFreeCirclesOnly(
    const std::vector<Sphere>& spheres, const EnvelopePoints& points) {
  std::set<Pair> free, touched;
  BruteForceFreeCircles(spheres, &free, &touched);
  std::map<Pair, int> with_points;
  for (const EnvelopePoint& p : points.circle_points) ++with_points[{p.spheres[0], p.spheres[1]}];
  for (const Pair& e : free) {
    EXPECT_EQ(with_points[e], 2) << "free circle " << e[0] << "-" << e[1];
  }
  for (const Pair& e : touched) {
    EXPECT_EQ(with_points.count(e), 0u) << "touched circle " << e[0] << "-" << e[1];
  }
  EXPECT_EQ(points.circle_points.size(), 2 * free.size());
  return {static_cast<std::int64_t>(free.size()), static_cast<std::int64_t>(touched.size())};
}

// Triples of balls that pairwise overlap: every triple whose spheres share a point is one, so
// this is "all triples" for sets too large to enumerate them all.
std::vector<Triple> OverlappingTriples(const std::vector<Sphere>& spheres) {
  const auto n = static_cast<std::int32_t>(spheres.size());
  const auto overlap = [&](std::int32_t a, std::int32_t b) {
    const Sphere& x = spheres[static_cast<std::size_t>(a)];
    const Sphere& y = spheres[static_cast<std::size_t>(b)];
    return (x.center - y.center).norm() <= (x.radius + y.radius) * (1 + kBand);
  };
  std::vector<std::vector<std::int32_t>> neighbours(spheres.size());
  for (std::int32_t i = 0; i < n; ++i) {
    for (std::int32_t j = i + 1; j < n; ++j) {
      if (overlap(i, j)) neighbours[static_cast<std::size_t>(i)].push_back(j);
    }
  }
  std::vector<Triple> triples;
  for (std::int32_t i = 0; i < n; ++i) {
    const auto& ni = neighbours[static_cast<std::size_t>(i)];
    for (std::size_t a = 0; a < ni.size(); ++a) {
      for (std::size_t b = a + 1; b < ni.size(); ++b) {
        if (overlap(ni[a], ni[b])) triples.push_back({i, ni[a], ni[b]});
      }
    }
  }
  return triples;
}

TEST(EnvelopePoints, ThreeUnitSpheresMeetWhereExpected) {
  const std::vector<Sphere> spheres = {
      {Vector3(0, 0, 0), 1.0}, {Vector3(1, 0, 0), 1.0}, {Vector3(0, 1, 0), 1.0}};
  const EnvelopePoints points = Envelope(spheres);
  ASSERT_EQ(points.v_points.size(), 2u);
  EXPECT_EQ(points.singleton_edges, 0);
  EXPECT_TRUE(points.circle_points.empty());
  const double z = std::sqrt(0.5);
  // (c1 - c0) x (c2 - c0) = +z: the upper point first.
  EXPECT_LT((points.v_points[0].point - Vector3(0.5, 0.5, z)).norm(), 1e-15);
  EXPECT_LT((points.v_points[1].point - Vector3(0.5, 0.5, -z)).norm(), 1e-15);
  EXPECT_EQ(points.v_points[0].spheres, (Triple{0, 1, 2}));
}

TEST(EnvelopePoints, TwoSpheresGiveTwoOppositeCirclePoints) {
  const std::vector<Sphere> spheres = {{Vector3(0, 0, 0), 1.0}, {Vector3(1.2, 0, 0), 0.8}};
  const EnvelopePoints points = Envelope(spheres);
  EXPECT_TRUE(points.v_points.empty());
  EXPECT_EQ(points.singleton_edges, 1);
  ASSERT_EQ(points.circle_points.size(), 2u);
  // x = (1.44 + 1 - 0.64) / 2.4 = 0.75, rho = sqrt(1 - 0.5625).
  const Vector3 centre(0.75, 0, 0);
  const Vector3 a = points.circle_points[0].point - centre;
  const Vector3 b = points.circle_points[1].point - centre;
  EXPECT_NEAR(a.norm(), std::sqrt(1 - 0.5625), 1e-15);
  EXPECT_NEAR(a.x(), 0.0, 1e-15);
  EXPECT_LT((a + b).norm(), 1e-15);
  // Another seed turns the pair about the axis; no singleton edges, no circle points.
  DilationOptions other;
  other.seed = 2;
  EXPECT_GT(
      (Envelope(spheres, other).circle_points[0].point - points.circle_points[0].point).norm(),
      1e-6);
  other.singleton_edges = false;
  EXPECT_TRUE(Envelope(spheres, other).circle_points.empty());
}

// All triples and all pairs, brute force, on random sets from crowded to sparse.
TEST(EnvelopePoints, MatchBruteForceOverAllTriplesAndPairsOnRandomSets) {
  std::int64_t uncovered_total = 0, free_total = 0, touched_total = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const double side = seed <= 6 ? 0.8 + 0.1 * static_cast<double>(seed - 1) : 2.5;
    const std::vector<Sphere> spheres = RandomBalls(60, side, 0.1, 0.3, seed);
    const absl::StatusOr<DualComplex> complex = ComputeDualComplex(spheres);
    ASSERT_TRUE(complex.ok()) << complex.status();
    const EnvelopePoints points = Envelope(spheres);
    EXPECT_EQ(points.degenerate, 0);
    EXPECT_EQ(points.complex_triangles, static_cast<std::int64_t>(complex->triangles.size()));
    ExpectPointsOnTheEnvelope(spheres, points, *complex);

    std::vector<Triple> all;
    const auto n = static_cast<std::int32_t>(spheres.size());
    for (std::int32_t i = 0; i < n; ++i) {
      for (std::int32_t j = i + 1; j < n; ++j) {
        for (std::int32_t k = j + 1; k < n; ++k) all.push_back({i, j, k});
      }
    }
    const std::int64_t uncovered = ExpectUncoveredTriplePointsKept(spheres, all, points);
    EXPECT_EQ(uncovered, static_cast<std::int64_t>(points.v_points.size())) << "seed " << seed;
    uncovered_total += uncovered;
    const auto [free, touched] = ExpectCirclePointsOnFreeCirclesOnly(spheres, points);
    free_total += free;
    touched_total += touched;
  }
  // The sets exercise both kinds of points (totals seen: 682 v-points, 76 free circles, 1711
  // touched circles).
  EXPECT_GT(uncovered_total, 500);
  EXPECT_GT(free_total, 40);
  EXPECT_GT(touched_total, 1200);
}

// Symmetric input: on a grid of equal balls many triple points lie exactly on a fourth sphere
// and CGAL's perturbation picks among co-spherical simplices; collinear centres give a
// triangulation of dimension 1; touching spheres meet in one point.
TEST(EnvelopePoints, DegenerateInputStaysConsistent) {
  std::vector<Sphere> grid;
  for (int x = 0; x < 3; ++x) {
    for (int y = 0; y < 3; ++y) {
      for (int z = 0; z < 3; ++z) grid.push_back({Vector3(x, y, z), 0.75});
    }
  }
  const absl::StatusOr<DualComplex> complex = ComputeDualComplex(grid);
  ASSERT_TRUE(complex.ok()) << complex.status();
  const EnvelopePoints points = Envelope(grid);
  EXPECT_EQ(points.degenerate, 0);
  EXPECT_GT(points.v_points.size(), 50u);
  ExpectPointsOnTheEnvelope(grid, points, *complex);
  std::vector<Triple> all;
  for (std::int32_t i = 0; i < 27; ++i) {
    for (std::int32_t j = i + 1; j < 27; ++j) {
      for (std::int32_t k = j + 1; k < 27; ++k) all.push_back({i, j, k});
    }
  }
  ExpectUncoveredTriplePointsKept(grid, all, points);

  // Collinear: the circles of 0-1 and 1-2 are free, 0 and 2 do not meet.
  const std::vector<Sphere> line = {
      {Vector3(0, 0, 0), 0.8}, {Vector3(0.5, 0, 0), 0.8}, {Vector3(1, 0, 0), 0.8}};
  const EnvelopePoints on_line = Envelope(line);
  EXPECT_TRUE(on_line.v_points.empty());
  EXPECT_EQ(on_line.degenerate, 0);
  ASSERT_EQ(on_line.circle_points.size(), 4u);
  EXPECT_EQ(on_line.circle_points[0].spheres, (Triple{0, 1, -1}));
  EXPECT_EQ(on_line.circle_points[2].spheres, (Triple{1, 2, -1}));
  EXPECT_NEAR(on_line.circle_points[0].point.x(), 0.25, 1e-15);

  // Touching: at most the single point of contact, never two copies or NaN.
  const std::vector<Sphere> touching = {{Vector3(0, 0, 0), 1.0}, {Vector3(2, 0, 0), 1.0}};
  const EnvelopePoints touch = Envelope(touching);
  ASSERT_LE(touch.circle_points.size(), 1u);
  for (const EnvelopePoint& p : touch.circle_points) {
    EXPECT_LT((p.point - Vector3(1, 0, 0)).norm(), 1e-15);
  }
}

// The points do not depend on the number of threads.
TEST(EnvelopePoints, SameOnOneThread) {
  const std::vector<Sphere> spheres = RandomBalls(3000, 14.0, 0.5, 1.2, 7);
  const EnvelopePoints parallel = Envelope(spheres);
  EnvelopePoints serial;
  tbb::task_arena(1).execute([&] { serial = Envelope(spheres); });
  EXPECT_GT(parallel.v_points.size(), 3000u);
  ASSERT_EQ(serial.v_points.size(), parallel.v_points.size());
  ASSERT_EQ(serial.circle_points.size(), parallel.circle_points.size());
  for (std::size_t q = 0; q < serial.v_points.size(); ++q) {
    EXPECT_EQ(serial.v_points[q].point, parallel.v_points[q].point);
    EXPECT_EQ(serial.v_points[q].spheres, parallel.v_points[q].spheres);
  }
  for (std::size_t q = 0; q < serial.circle_points.size(); ++q) {
    EXPECT_EQ(serial.circle_points[q].point, parallel.circle_points[q].point);
  }
}

// Medial spheres of the real meshes, generated as the paper does for dilation (boundary voxels
// subdivided), at voxel sizes giving 300-400 spheres. Made once per mesh for the binary.
struct MedialSet {
  Mesh mesh;
  std::vector<Sphere> spheres;
  SphereSet set;
};

const MedialSet& Medial(const std::string& name) {
  static std::map<std::string, MedialSet> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  const std::map<std::string, double> voxel_size = {{"eight.off", 0.0695},
                                                    {"knot1.off", 0.0184},
                                                    {"fandisk.off", 0.122},
                                                    {"elephant.off", 0.0763}};
  MedialSet made;
  made.mesh = LoadTestMesh(name);
  const BoundaryOracle oracle = BuildOracle(made.mesh);
  MedialSphereOptions options;
  options.voxel_size = voxel_size.at(name);
  options.subdivide_boundary = true;
  absl::StatusOr<MedialSphereResult> generated = GenerateMedialSpheres(oracle, options);
  EXPECT_TRUE(generated.ok()) << generated.status();
  if (generated.ok()) made.set = std::move(generated->set);
  made.spheres = made.set.spheres;
  return cache.emplace(name, std::move(made)).first->second;
}

TEST(EnvelopePoints, MatchBruteForceOnMedialSpheresOfRealMeshes) {
  for (const std::string name : {"eight.off", "knot1.off", "fandisk.off", "elephant.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const std::vector<Sphere>& spheres = Medial(name).spheres;
    ASSERT_GT(spheres.size(), 200u) << name;
    const absl::StatusOr<DualComplex> complex = ComputeDualComplex(spheres);
    ASSERT_TRUE(complex.ok()) << complex.status();
    const EnvelopePoints points = Envelope(spheres);
    EXPECT_EQ(points.degenerate, 0) << name;
    ExpectPointsOnTheEnvelope(spheres, points, *complex);
    // Over the complex's triangles, then over every triple of pairwise overlapping balls (so
    // the complex misses no corner of the envelope).
    const std::int64_t uncovered =
        ExpectUncoveredTriplePointsKept(spheres, complex->triangles, points);
    EXPECT_GT(uncovered, static_cast<std::int64_t>(spheres.size() / 2)) << name;
    EXPECT_EQ(uncovered, static_cast<std::int64_t>(points.v_points.size())) << name;
    const std::vector<Triple> triples = OverlappingTriples(spheres);
    EXPECT_GT(triples.size(), 4 * complex->triangles.size()) << name;
    EXPECT_EQ(ExpectUncoveredTriplePointsKept(spheres, triples, points), uncovered) << name;
    const auto [free, touched] = ExpectCirclePointsOnFreeCirclesOnly(spheres, points);
    std::printf(
        "[ counts   ] %-12s %zu spheres, %zu triangles, %lld v-points, %zu triples "
        "checked, %lld free and %lld touched circles\n",
        name.c_str(), spheres.size(), complex->triangles.size(), static_cast<long long>(uncovered),
        triples.size(), static_cast<long long>(free), static_cast<long long>(touched));
  }
}

// Growth against a brute-force recomputation: each sphere's new radius is the largest of its
// old radius and the distances from its centre to the brute-force nearest boundary points of
// its envelope points.
void ExpectGrowthMatchesBruteForce(const Mesh& mesh, const SphereSet& input) {
  const BoundaryOracle oracle = BuildOracle(mesh);
  const absl::StatusOr<DilationResult> result = DilateSpheres(oracle, input);
  ASSERT_TRUE(result.ok()) << result.status();
  const EnvelopePoints points = Envelope(input.spheres);
  EXPECT_EQ(result->v_points, static_cast<std::int64_t>(points.v_points.size()));
  EXPECT_EQ(result->edge_points, static_cast<std::int64_t>(points.circle_points.size()));
  ASSERT_EQ(result->set.spheres.size(), input.spheres.size());
  EXPECT_FALSE(result->set.has_contacts());

  std::vector<double> expected(input.spheres.size());
  for (std::size_t s = 0; s < expected.size(); ++s) expected[s] = input.spheres[s].radius;
  std::vector<const EnvelopePoint*> all;
  for (const EnvelopePoint& p : points.v_points) all.push_back(&p);
  for (const EnvelopePoint& p : points.circle_points) all.push_back(&p);
  for (const EnvelopePoint* p : all) {
    const Vector3 m = BruteForceClosest(mesh, p->point).point;
    for (std::int32_t s : p->spheres) {
      if (s < 0) continue;
      const auto si = static_cast<std::size_t>(s);
      expected[si] = std::max(expected[si], (input.spheres[si].center - m).norm());
      // The grown sphere covers m.
      EXPECT_LE((result->set.spheres[si].center - m).norm(),
                result->set.spheres[si].radius * (1 + 1e-12));
    }
  }
  std::int64_t grown = 0;
  double max_growth = 0.0;
  for (std::size_t s = 0; s < expected.size(); ++s) {
    const Sphere& before = input.spheres[s];
    const Sphere& after = result->set.spheres[s];
    EXPECT_EQ(after.center, before.center) << "sphere " << s;
    EXPECT_GE(after.radius, before.radius) << "sphere " << s;
    EXPECT_NEAR(after.radius, expected[s], 1e-12 * expected[s]) << "sphere " << s;
    grown += after.radius > before.radius;
    max_growth = std::max(max_growth, after.radius - before.radius);
  }
  EXPECT_EQ(result->grown, grown);
  EXPECT_DOUBLE_EQ(result->max_growth, max_growth);
  EXPECT_GT(grown, static_cast<std::int64_t>(input.spheres.size() / 4));

  // Deterministic, and independent of the order of the envelope points.
  const absl::StatusOr<DilationResult> again = DilateSpheres(oracle, input);
  ASSERT_TRUE(again.ok());
  for (std::size_t s = 0; s < expected.size(); ++s) {
    EXPECT_EQ(again->set.spheres[s].radius, result->set.spheres[s].radius);
  }
}

TEST(DilateSpheres, GrowthMatchesBruteForceOnRandomInternalSpheres) {
  const Mesh mesh = Icosphere(3);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> coord(-0.85, 0.85);
    SphereSet set;
    while (set.spheres.size() < 80) {
      const Vector3 c(coord(rng), coord(rng), coord(rng));
      if (c.norm() > 0.85) continue;
      // Internal and tangent, like medial spheres, but nowhere near the medial axis.
      set.spheres.push_back({c, BruteForceDistance(mesh, c)});
    }
    ExpectGrowthMatchesBruteForce(mesh, set);
  }
}

TEST(DilateSpheres, GrowthMatchesBruteForceOnMedialSpheresOfRealMeshes) {
  for (const std::string name : {"eight.off", "knot1.off", "fandisk.off", "elephant.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const MedialSet& medial = Medial(name);
    ASSERT_TRUE(medial.set.has_contacts()) << name;
    ExpectGrowthMatchesBruteForce(medial.mesh, medial.set);
  }
}

// A partial growth moves each radius that fraction of the way to the paper's; 0 changes
// nothing; values outside [0, 1] are refused.
TEST(DilateSpheres, PartialGrowthScalesEveryIncrease) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const MedialSet& medial = Medial("eight.off");
  const BoundaryOracle oracle = BuildOracle(medial.mesh);
  const absl::StatusOr<DilationResult> full = DilateSpheres(oracle, medial.set);
  DilationOptions half_options, none_options, bad_options;
  half_options.growth = 0.5;
  none_options.growth = 0.0;
  bad_options.growth = 1.5;
  const absl::StatusOr<DilationResult> half = DilateSpheres(oracle, medial.set, half_options);
  const absl::StatusOr<DilationResult> none = DilateSpheres(oracle, medial.set, none_options);
  ASSERT_TRUE(full.ok() && half.ok() && none.ok());
  for (std::size_t i = 0; i < medial.set.size(); ++i) {
    const double r = medial.set.spheres[i].radius;
    EXPECT_NEAR(half->set.spheres[i].radius, r + 0.5 * (full->set.spheres[i].radius - r),
                1e-15 * (1 + r));
    EXPECT_EQ(none->set.spheres[i].radius, r);
  }
  EXPECT_NEAR(half->max_growth, 0.5 * full->max_growth, 1e-15);
  EXPECT_FALSE(DilateSpheres(oracle, medial.set, bad_options).ok());
}

// Section VI-A's claim: better boundary coverage. Figures are printed for the report.
TEST(DilateSpheres, CoverageRisesAndHausdorffFallsOnRealMeshes) {
  for (const std::string name : {"eight.off", "knot1.off", "fandisk.off", "elephant.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const MedialSet& medial = Medial(name);
    const BoundaryOracle oracle = BuildOracle(medial.mesh);
    const absl::StatusOr<DilationResult> dilated = DilateSpheres(oracle, medial.set);
    ASSERT_TRUE(dilated.ok()) << dilated.status();
    QualityOptions quality;
    quality.surface_samples = 50'000;
    const absl::StatusOr<QualityReport> before = EvaluateSpheres(oracle, medial.spheres, quality);
    const absl::StatusOr<QualityReport> after =
        EvaluateSpheres(oracle, dilated->set.spheres, quality);
    ASSERT_TRUE(before.ok() && after.ok());
    EXPECT_GT(after->coverage, before->coverage) << name;
    EXPECT_LT(after->boundary_to_union_hausdorff, before->boundary_to_union_hausdorff) << name;
    EXPECT_LT(after->boundary_to_union_mean, before->boundary_to_union_mean) << name;
    EXPECT_FALSE(after->nerr_is_exact) << name;
    std::printf(
        "[ figures  ] %-12s %4zu spheres: coverage %.4f -> %.4f, Hausdorff %.5f -> %.5f, mean "
        "%.6f -> %.6f (bbox diagonal %.4f), protrusion max %.5f, v-points %lld, edge points "
        "%lld, grown %lld, max growth %.5f, %.1f ms\n",
        name.c_str(), medial.spheres.size(), before->coverage, after->coverage,
        before->boundary_to_union_hausdorff, after->boundary_to_union_hausdorff,
        before->boundary_to_union_mean, after->boundary_to_union_mean, after->bbox_diagonal,
        after->protrusion_max, static_cast<long long>(dilated->v_points),
        static_cast<long long>(dilated->edge_points), static_cast<long long>(dilated->grown),
        dilated->max_growth, 1e3 * dilated->seconds);
  }
}

TEST(DilateSpheres, BadInputIsNamedAndEmptyInputIsEmpty) {
  const BoundaryOracle oracle = BuildOracle(Icosphere(1));
  const absl::StatusOr<DilationResult> empty = DilateSpheres(oracle, SphereSet{});
  ASSERT_TRUE(empty.ok()) << empty.status();
  EXPECT_EQ(empty->set.size(), 0u);
  EXPECT_EQ(empty->v_points + empty->edge_points + empty->grown, 0);

  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Sphere> bad = {{Vector3(nan, 0, 0), 0.1}, {Vector3(0, inf, 0), 0.1},
                                   {Vector3::Zero(), nan},    {Vector3::Zero(), inf},
                                   {Vector3::Zero(), 0.0},    {Vector3::Zero(), -0.1}};
  for (const Sphere& b : bad) {
    SphereSet set;
    set.spheres = {{Vector3(0.1, 0, 0), 0.2}, b};
    const absl::StatusOr<DilationResult> result = DilateSpheres(oracle, set);
    ASSERT_FALSE(result.ok());
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(result.status().message().find("sphere 1"), std::string::npos)
        << result.status().message();
    EXPECT_FALSE(ComputeEnvelopePoints(set.spheres).ok());
  }
}

}  // namespace
}  // namespace inscribe
