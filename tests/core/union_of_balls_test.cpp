#include "inscribe/balls/union_of_balls.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "support/sphere_sets.h"
#include "support/test_meshes.h"
#include "support/union_volume_reference.h"

namespace inscribe {
namespace {

using testing::RandomBalls;
// References independent of the library: slice quadrature and Monte Carlo.
using testing::BallGrid;
using testing::MonteCarloEstimate;
using testing::MonteCarloVolume;
using testing::SliceQuadratureVolume;

constexpr double kPi = 3.14159265358979323846;

double BallVolume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

// vol(b1 ∩ b2), written as one polynomial (not as two caps, like the library).
double LensVolume(double r1, double r2, double d) {
  if (d >= r1 + r2) return 0.0;
  if (d <= std::abs(r1 - r2)) return BallVolume(std::min(r1, r2));
  const double t = r1 + r2 - d;
  return kPi * t * t * (d * d + 2 * d * r2 - 3 * r2 * r2 + 2 * d * r1 + 6 * r1 * r2 - 3 * r1 * r1) /
         (12 * d);
}

Sphere Ball(double x, double y, double z, double r) { return Sphere{Vector3(x, y, z), r}; }

double Volume(const std::vector<Sphere>& balls) {
  absl::StatusOr<double> v = UnionVolume(balls);
  EXPECT_TRUE(v.ok()) << v.status();
  return v.ok() ? *v : std::nan("");
}

DualComplex Complex(const std::vector<Sphere>& balls) {
  absl::StatusOr<DualComplex> c = ComputeDualComplex(balls);
  EXPECT_TRUE(c.ok()) << c.status();
  return c.ok() ? *std::move(c) : DualComplex{};
}

// Random sets dense enough that their complexes have many triangles and tetrahedra (about
// 2.7 tetrahedra per ball at n = 1000): a side of the cube root of n, radii 0.6 to 1.2.
std::vector<Sphere> OverlappingBalls(int n, std::uint64_t seed) {
  return RandomBalls(n, std::cbrt(static_cast<double>(n)), 0.6, 1.2, seed);
}

int ExtraMonteCarloSets() {
  const char* env = std::getenv("INSCRIBE_MC_SETS");
  return env == nullptr ? 0 : std::max(0, std::atoi(env));
}

void ExpectMonteCarloAgreement(const std::vector<Sphere>& balls, std::int64_t samples,
                               std::uint64_t seed) {
  const double exact = Volume(balls);
  const MonteCarloEstimate mc = MonteCarloVolume(balls, samples, seed);
  EXPECT_NEAR(exact, mc.volume, 3 * mc.standard_error)
      << balls.size() << " balls, seed " << seed << ": off by "
      << (exact - mc.volume) / mc.standard_error << " standard errors";
}

// ---- UnionVolume: analytic cases.

TEST(UnionVolume, EmptyInputIsZero) {
  EXPECT_EQ(Volume({}), 0.0);
  EXPECT_TRUE(Complex({}).vertices.empty());
}

TEST(UnionVolume, OneBall) { EXPECT_NEAR(Volume({Ball(1, 2, 3, 0.7)}), BallVolume(0.7), 1e-15); }

TEST(UnionVolume, TwoOverlappingBallsMatchTheLensFormula) {
  // (r1, r2, d): equal; unequal with the small centre outside, on, inside the big sphere.
  const double cases[][3] = {{1, 1, 1},     {1, 1, 1.9},   {1, 1, 0.01},  {1, 0.5, 1.2},
                             {1, 0.5, 1.0}, {1, 0.5, 0.7}, {2, 0.3, 1.8}, {1, 1e-3, 1.0}};
  for (const auto& c : cases) {
    const double expected = BallVolume(c[0]) + BallVolume(c[1]) - LensVolume(c[0], c[1], c[2]);
    // Arbitrary direction between the centres.
    const Vector3 dir = Vector3(0.48, -0.6, 0.64);
    const double v =
        Volume({{Vector3(0.3, 0.1, -0.2), c[0]}, {Vector3(0.3, 0.1, -0.2) + c[2] * dir, c[1]}});
    EXPECT_NEAR(v, expected, 1e-13 * expected) << c[0] << " " << c[1] << " " << c[2];
  }
}

TEST(UnionVolume, TwoNestedBallsIsTheBigOne) {
  EXPECT_NEAR(Volume({Ball(0, 0, 0, 2), Ball(0.5, 0.2, -0.3, 1)}), BallVolume(2), 1e-14);
  EXPECT_NEAR(Volume({Ball(0.5, 0.2, -0.3, 1), Ball(0, 0, 0, 2)}), BallVolume(2), 1e-14);
  // Nearly touching from inside: the small ball's power cell is not empty, but its cell
  // restricted to the union is.
  const DualComplex c = Complex({Ball(0, 0, 0, 2), Ball(0.999, 0, 0, 1)});
  EXPECT_EQ(c.vertices, std::vector<std::int32_t>({0}));
  EXPECT_EQ(c.redundant, std::vector<std::int32_t>({1}));
  EXPECT_TRUE(c.edges.empty());
}

TEST(UnionVolume, TwoDisjointBallsAdd) {
  EXPECT_NEAR(Volume({Ball(0, 0, 0, 1), Ball(3, 0, 0, 1.5)}), BallVolume(1) + BallVolume(1.5),
              1e-14);
  EXPECT_TRUE(Complex({Ball(0, 0, 0, 1), Ball(3, 0, 0, 1.5)}).edges.empty());
}

TEST(UnionVolume, TwoIdenticalBallsCountOnce) {
  const DualComplex c = Complex({Ball(1, 1, 1, 1), Ball(1, 1, 1, 1)});
  EXPECT_EQ(c.vertices, std::vector<std::int32_t>({0}));
  EXPECT_EQ(c.redundant, std::vector<std::int32_t>({1}));
  EXPECT_NEAR(Volume({Ball(1, 1, 1, 1), Ball(1, 1, 1, 1)}), BallVolume(1), 1e-14);
}

TEST(UnionVolume, TwoTangentBalls) {
  // Touching from outside: volumes add. Touching from inside: the big one.
  EXPECT_NEAR(Volume({Ball(0, 0, 0, 1), Ball(0, 0, 2.5, 1.5)}), BallVolume(1) + BallVolume(1.5),
              1e-14);
  EXPECT_NEAR(Volume({Ball(0, 0, 0, 2), Ball(0, 0, 1, 1)}), BallVolume(2), 1e-14);
}

TEST(UnionVolume, ThreeEqualBallsOnALine) {
  // b1 ∩ b3 ⊂ b2 (convexity), so vol = 3 V - 2 lens(d) whatever d.
  for (double d : {0.3, 0.9, 1.0, 1.5, 1.99}) {
    const double expected = 3 * BallVolume(1) - 2 * LensVolume(1, 1, d);
    const double v = Volume({Ball(0, 0, 0, 1), Ball(d, 0, 0, 1), Ball(2 * d, 0, 0, 1)});
    EXPECT_NEAR(v, expected, 1e-13 * expected) << "d = " << d;
  }
}

TEST(UnionVolume, ThreeEqualBallsOnAnEquilateralTriangleMatchQuadrature) {
  // Circumradius 1. Radius > 1: the spheres share two points and the triangle is in the
  // complex; radius < 1: it is not, though every pair overlaps.
  for (double r : {0.6, 0.9, 0.99, 1.0, 1.01, 1.2, 2.0, 5.0}) {
    std::vector<Sphere> balls;
    for (int k = 0; k < 3; ++k) {
      balls.push_back(Ball(std::cos(2 * kPi * k / 3), std::sin(2 * kPi * k / 3), 0, r));
    }
    const double reference = SliceQuadratureVolume(balls);
    EXPECT_NEAR(Volume(balls), reference, 1e-12 * reference) << "r = " << r;
    // r = 1 is tangent up to the rounding of the centres: either answer is right.
    if (r != 1.0) {
      EXPECT_EQ(Complex(balls).triangles.size(), r > 1.0 ? 1u : 0u) << "r = " << r;
    }
  }
}

TEST(UnionVolume, ThreeBallsWhoseCommonPointsLieOutsideTheTriangleOfCentres) {
  // Big balls at (±1, 0, 0) radius 1.5; a smaller one at (0, 0.5, 0) whose sphere crosses
  // their circle of intersection near (0, 1.118, 0): the common points of the three spheres are
  // far outside the triangle of centres, and the arc of that circle inside the third ball is
  // short. As r3 falls to sqrt(1.25) - 0.5 the triangle leaves the complex, and then the small
  // ball (inside the union of the others) leaves it too.
  for (double r3 : {0.62, 0.625, 0.65, 0.7, 0.9, 1.2, 0.6, 0.5}) {
    const std::vector<Sphere> balls = {Ball(-1, 0, 0, 1.5), Ball(1, 0, 0, 1.5),
                                       Ball(0, 0.5, 0, r3)};
    const double reference = SliceQuadratureVolume(balls);
    EXPECT_NEAR(Volume(balls), reference, 1e-12 * reference) << "r3 = " << r3;
    const DualComplex c = Complex(balls);
    const bool common_points = r3 > std::sqrt(1.25) - 0.5;
    EXPECT_EQ(c.triangles.size(), common_points ? 1u : 0u) << "r3 = " << r3;
    EXPECT_EQ(c.redundant,
              common_points ? std::vector<std::int32_t>{} : std::vector<std::int32_t>{2})
        << "r3 = " << r3;
  }
}

// ---- UnionVolume: random sets against the references.

TEST(UnionVolume, RandomSetsMatchSliceQuadrature) {
  std::size_t triangles = 0;
  std::size_t tetrahedra = 0;
  for (std::uint64_t seed = 1; seed <= 14; ++seed) {
    const int n = seed <= 10 ? 5 : 20;
    // Small sets crowded into a unit cube so that they overlap a lot.
    const std::vector<Sphere> balls =
        n == 5 ? RandomBalls(n, 1.0, 0.3, 0.9, seed) : OverlappingBalls(n, seed);
    const DualComplex c = Complex(balls);
    triangles += c.triangles.size();
    tetrahedra += c.tetrahedra.size();
    const double reference = SliceQuadratureVolume(balls);
    EXPECT_NEAR(Volume(balls), reference, 1e-12 * reference) << n << " balls, seed " << seed;
  }
  // The sets must exercise the 3- and 4-ball terms.
  EXPECT_GT(triangles, 150u);
  EXPECT_GT(tetrahedra, 50u);
}

TEST(UnionVolume, RandomSetsMatchMonteCarlo) {
  // Default: one 20-ball and one 100-ball set at 10^7 samples; INSCRIBE_MC_SETS=k adds k
  // seeds of each of 5, 20 and 100 balls.
  ExpectMonteCarloAgreement(OverlappingBalls(20, 101), 10'000'000, 7);
  ExpectMonteCarloAgreement(OverlappingBalls(100, 102), 10'000'000, 8);
  for (int k = 0; k < ExtraMonteCarloSets(); ++k) {
    for (int n : {5, 20, 100}) {
      const std::uint64_t seed = 1000 + 10 * static_cast<std::uint64_t>(k) + n;
      ExpectMonteCarloAgreement(OverlappingBalls(n, seed), 10'000'000, seed);
    }
  }
}

TEST(UnionVolume, BallsOnARealMeshMatchMonteCarlo) {
  // Balls at every 4th vertex of CGAL's eight.off, radius 10% of the bounding box diagonal:
  // a thick shell of heavily overlapping balls, with the irregular spacing of a real mesh.
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  ASSERT_GT(mesh.num_vertices(), 0);
  const double r = 0.1 * ComputeBoundingBox(mesh.vertices).diagonal();
  std::vector<Sphere> balls;
  for (Eigen::Index v = 0; v < mesh.num_vertices(); v += 4) {
    balls.push_back({mesh.vertices.row(v).transpose(), r * (1 + 0.3 * std::sin(v))});
  }
  const DualComplex c = Complex(balls);
  EXPECT_GT(c.tetrahedra.size(), 100u);
  ExpectMonteCarloAgreement(balls, 10'000'000, 9);
}

// ---- UnionVolume: degenerate input.

TEST(UnionVolume, CoSphericalCubeCornersMatchQuadratureAndPerturbation) {
  // 8 equal balls on the corners of the unit cube: every 4 corners of a face are co-circular
  // and all 8 co-spherical (half-diagonal 0.866), so the regular triangulation is resolved by
  // symbolic perturbation. Radii straddle the power vertex at the cube centre.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-1e-7, 1e-7);
  for (double r : {0.55, 0.7, 0.8, 0.86, std::sqrt(0.75), 0.87, 0.95, 1.3}) {
    std::vector<Sphere> balls;
    std::vector<Sphere> perturbed;
    for (int k = 0; k < 8; ++k) {
      balls.push_back(Ball(k & 1, (k >> 1) & 1, (k >> 2) & 1, r));
      perturbed.push_back(balls.back());
      perturbed.back().center += Vector3(jitter(rng), jitter(rng), jitter(rng));
    }
    const double v = Volume(balls);
    const double reference = SliceQuadratureVolume(balls);
    EXPECT_NEAR(v, reference, 1e-12 * reference) << "r = " << r;
    EXPECT_NEAR(v, Volume(perturbed), 1e-6 * v) << "r = " << r;
    if (r != std::sqrt(0.75)) {
      EXPECT_EQ(Complex(balls).tetrahedra.empty(), r < std::sqrt(0.75)) << "r = " << r;
    }
  }
}

TEST(UnionVolume, CoplanarCentresMatchQuadrature) {
  // A 4 x 4 grid in the plane z = 0.25 (regular triangulation of dimension 2, many co-circular
  // quadruples), and the same grid with radii varying by row.
  for (double r : {0.45, 0.55, 0.7071067811865476, 0.8, 1.5}) {
    for (bool vary : {false, true}) {
      std::vector<Sphere> balls;
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) balls.push_back(Ball(i, j, 0.25, vary ? r + 0.1 * i : r));
      }
      const double reference = SliceQuadratureVolume(balls);
      EXPECT_NEAR(Volume(balls), reference, 1e-12 * reference) << "r = " << r;
      EXPECT_TRUE(Complex(balls).tetrahedra.empty());
    }
  }
}

TEST(UnionVolume, DuplicateBallsCountOnce) {
  const std::vector<Sphere> base = OverlappingBalls(10, 21);
  std::vector<Sphere> doubled = base;
  doubled.insert(doubled.end(), base.begin(), base.end());
  doubled.push_back(base[3]);
  const DualComplex c = Complex(doubled);
  for (std::int32_t i : c.vertices) EXPECT_LT(i, 10);  // the first copy is kept
  EXPECT_EQ(c.vertices.size() + c.redundant.size(), doubled.size());
  EXPECT_NEAR(Volume(doubled), Volume(base), 1e-13 * Volume(base));
}

TEST(UnionVolume, TinyBallsInsideBigOnesAreRedundant) {
  std::vector<Sphere> balls = OverlappingBalls(15, 22);
  const double before = Volume(balls);
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 30; ++k) {
    const Sphere& host = balls[static_cast<std::size_t>(k % 15)];
    Vector3 offset(unit(rng), unit(rng), unit(rng));
    offset *= 0.8 * host.radius / std::max(1.0, offset.norm());
    balls.push_back({host.center + offset, 0.01 * host.radius});
  }
  const DualComplex c = Complex(balls);
  for (std::int32_t i : c.vertices) EXPECT_LT(i, 15);
  EXPECT_NEAR(Volume(balls), before, 1e-13 * before);
}

TEST(UnionVolume, EqualCentresDifferentRadiiIsTheBiggest) {
  const std::vector<Sphere> balls = {Ball(1, 2, 3, 0.5), Ball(1, 2, 3, 1.5), Ball(1, 2, 3, 1.0)};
  EXPECT_NEAR(Volume(balls), BallVolume(1.5), 1e-14);
  const DualComplex c = Complex(balls);
  EXPECT_EQ(c.vertices, std::vector<std::int32_t>({1}));
  EXPECT_EQ(c.redundant, std::vector<std::int32_t>({0, 2}));
}

TEST(UnionVolume, LargeCoordinateOffset) {
  // Centres around 1e4, radii about 1: the answer must not lose the digits the offset takes.
  const std::vector<Sphere> base = OverlappingBalls(20, 24);
  std::vector<Sphere> far = base;
  for (Sphere& b : far) b.center += Vector3(1.0e4, -2.0e4, 1.5e4);
  const double reference = SliceQuadratureVolume(base);
  EXPECT_NEAR(Volume(far), reference, 1e-9 * reference);
  EXPECT_NEAR(Volume(far), Volume(base), 1e-10 * reference);
}

// ---- UnionVolume: invariance.

TEST(UnionVolume, TranslationAndPermutationInvariant) {
  for (std::uint64_t seed : {31, 32, 33}) {
    const std::vector<Sphere> balls = OverlappingBalls(60, seed);
    const double v = Volume(balls);
    std::vector<Sphere> moved = balls;
    for (Sphere& b : moved) b.center += Vector3(3.7, -12.1, 0.45);
    EXPECT_NEAR(Volume(moved), v, 1e-12 * v);
    std::vector<Sphere> shuffled = balls;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937_64(seed));
    EXPECT_NEAR(Volume(shuffled), v, 1e-12 * v);
  }
}

TEST(UnionVolume, ScalesWithTheCubeOfTheScale) {
  const std::vector<Sphere> balls = OverlappingBalls(60, 34);
  const double v = Volume(balls);
  for (double s : {1e-3, 0.37, 2.5, 1e3}) {
    std::vector<Sphere> scaled = balls;
    for (Sphere& b : scaled) {
      b.center *= s;
      b.radius *= s;
    }
    EXPECT_NEAR(Volume(scaled), s * s * s * v, 1e-12 * s * s * s * v) << "s = " << s;
  }
}

// ---- UnionVolume: errors.

TEST(UnionVolume, RejectsBadInputNamingTheBall) {
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  const struct {
    Sphere bad;
    const char* mentions;
  } cases[] = {{Ball(nan, 0, 0, 1), "sphere 1: center x nan is not finite"},
               {Ball(0, inf, 0, 1), "sphere 1: center y inf is not finite"},
               {Ball(0, 0, 0, 0), "sphere 1: radius 0 is not positive"},
               {Ball(0, 0, 0, -2), "sphere 1: radius -2 is not positive"},
               {Ball(0, 0, 0, nan), "sphere 1: radius nan is not finite"},
               {Ball(0, 0, 0, inf), "sphere 1: radius inf is not finite"},
               {Ball(0, 0, 0, 1e200), "ball 1: centre or radius above"},
               {Ball(-1e160, 0, 0, 1), "ball 1: centre or radius above"}};
  for (const auto& c : cases) {
    const std::vector<Sphere> balls = {Ball(0, 0, 0, 1), c.bad, Ball(1, 0, 0, 1)};
    const absl::StatusOr<double> v = UnionVolume(balls);
    ASSERT_FALSE(v.ok());
    EXPECT_EQ(v.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(std::string(v.status().message()).find(c.mentions), std::string::npos) << v.status();
    EXPECT_EQ(ComputeDualComplex(balls).status().code(), absl::StatusCode::kInvalidArgument);
  }
}

TEST(UnionVolume, RejectsAComplexWithIndicesOutOfRange) {
  const std::vector<Sphere> balls = {Ball(0, 0, 0, 1), Ball(1, 0, 0, 1)};
  DualComplex c = Complex(balls);
  ASSERT_TRUE(UnionVolume(balls, c).ok());
  c.edges.push_back({0, 2});
  const absl::StatusOr<double> v = UnionVolume(balls, c);
  ASSERT_FALSE(v.ok());
  EXPECT_EQ(v.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(v.status().message()).find("edge 1: ball index 2"), std::string::npos)
      << v.status();
}

// Found by fuzzing (UpdateDeformation with bounds on a mesh collapsed to ~1e-185): balls far
// smaller than the ulp of their position used to leave the padded triangulation flat, and CGAL's
// alpha shape then read unclassified vertices (UBSan: invalid enum value).
TEST(UnionVolume, TinyBallsFarFromTheOriginAreMeasured) {
  for (const double r : {1e-185, 1e-20}) {
    const std::vector<Sphere> balls = {Ball(1.1, 2, 0.06875, r), Ball(1.1, 2, 0.06875, r / 2)};
    const absl::StatusOr<double> v = UnionVolume(balls);
    ASSERT_TRUE(v.ok()) << v.status();
    EXPECT_NEAR(*v, BallVolume(r), 1e-12 * BallVolume(r));  // 0 for 1e-185 (r^3 underflows)
  }
}

// ---- DualComplex.

TEST(DualComplex, SingleBallAndTwoBalls) {
  const DualComplex one = Complex({Ball(0, 0, 0, 1)});
  EXPECT_EQ(one.vertices, std::vector<std::int32_t>({0}));
  EXPECT_TRUE(one.edges.empty() && one.redundant.empty());
  const DualComplex two = Complex({Ball(0, 0, 0, 1), Ball(1, 0, 0, 1)});
  EXPECT_EQ(two.vertices, std::vector<std::int32_t>({0, 1}));
  EXPECT_EQ(two.edges, (std::vector<std::array<std::int32_t, 2>>{{0, 1}}));
}

TEST(DualComplex, FourBallsOnATetrahedron) {
  // Regular tetrahedron with circumradius sqrt(3): balls of radius 2 contain its centre (one
  // tetrahedron); radius 1.5 < sqrt(3) overlap pairwise and by threes only.
  for (double r : {2.0, 1.65}) {
    const std::vector<Sphere> balls = {Ball(1, 1, 1, r), Ball(1, -1, -1, r), Ball(-1, 1, -1, r),
                                       Ball(-1, -1, 1, r)};
    const DualComplex c = Complex(balls);
    EXPECT_EQ(c.vertices.size(), 4u);
    EXPECT_EQ(c.edges.size(), 6u);
    EXPECT_EQ(c.triangles.size(), 4u);
    EXPECT_EQ(c.tetrahedra.size(), r > std::sqrt(3.0) ? 1u : 0u);
    const double reference = SliceQuadratureVolume(balls);
    EXPECT_NEAR(Volume(balls), reference, 1e-12 * reference) << "r = " << r;
  }
}

// Brute-force conditions every simplex must meet: faces present (closure), edges' spheres
// meet, triangles' spheres share points, tetrahedra's power point inside all four balls; and
// tuples sorted, lists sorted, vertices and redundant partitioning the input.
TEST(DualComplex, IsClosedSortedAndGeometricallyConsistent) {
  for (std::uint64_t seed : {41, 42}) {
    const std::vector<Sphere> balls = OverlappingBalls(150, seed);
    const DualComplex c = Complex(balls);
    EXPECT_TRUE(std::is_sorted(c.vertices.begin(), c.vertices.end()));
    EXPECT_TRUE(std::is_sorted(c.edges.begin(), c.edges.end()));
    EXPECT_TRUE(std::is_sorted(c.triangles.begin(), c.triangles.end()));
    EXPECT_TRUE(std::is_sorted(c.tetrahedra.begin(), c.tetrahedra.end()));
    std::vector<std::int32_t> all = c.vertices;
    all.insert(all.end(), c.redundant.begin(), c.redundant.end());
    std::sort(all.begin(), all.end());
    std::vector<std::int32_t> expected(balls.size());
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(all, expected);

    const std::set<std::array<std::int32_t, 2>> edges(c.edges.begin(), c.edges.end());
    const std::set<std::array<std::int32_t, 3>> triangles(c.triangles.begin(), c.triangles.end());
    const std::set<std::int32_t> vertices(c.vertices.begin(), c.vertices.end());
    const auto ball = [&balls](std::int32_t i) { return balls[static_cast<std::size_t>(i)]; };
    const auto power = [](const Sphere& b, const Vector3& x) {
      return (x - b.center).squaredNorm() - b.radius * b.radius;
    };
    for (const auto& e : c.edges) {
      EXPECT_TRUE(e[0] < e[1] && vertices.count(e[0]) && vertices.count(e[1]));
      EXPECT_LE((ball(e[1]).center - ball(e[0]).center).norm(),
                ball(e[0]).radius + ball(e[1]).radius);
    }
    for (const auto& t : c.triangles) {
      EXPECT_TRUE(t[0] < t[1] && t[1] < t[2]);
      EXPECT_TRUE(edges.count({t[0], t[1]}) && edges.count({t[0], t[2]}) &&
                  edges.count({t[1], t[2]}));
      // Point of the radical line in the plane of centres: power <= 0.
      const Vector3 c0 = ball(t[0]).center;
      Eigen::Matrix3d m;
      Vector3 rhs;
      for (int k = 0; k < 2; ++k) {
        const Sphere& b = ball(t[static_cast<std::size_t>(k + 1)]);
        m.row(k) = 2 * (b.center - c0).transpose();
        rhs(k) = (b.center - c0).squaredNorm() + ball(t[0]).radius * ball(t[0]).radius -
                 b.radius * b.radius;
      }
      m.row(2) = (ball(t[1]).center - c0).cross(ball(t[2]).center - c0).transpose();
      rhs(2) = 0;
      const Vector3 y = c0 + m.partialPivLu().solve(rhs);
      EXPECT_LE(power(ball(t[0]), y), 1e-9);
    }
    for (const auto& t : c.tetrahedra) {
      EXPECT_TRUE(t[0] < t[1] && t[1] < t[2] && t[2] < t[3]);
      for (int skip = 0; skip < 4; ++skip) {
        std::array<std::int32_t, 3> face;
        for (int k = 0, j = 0; k < 4; ++k) {
          if (k != skip) face[static_cast<std::size_t>(j++)] = t[static_cast<std::size_t>(k)];
        }
        EXPECT_TRUE(triangles.count(face));
      }
      const Vector3 c0 = ball(t[0]).center;
      Eigen::Matrix3d m;
      Vector3 rhs;
      for (int k = 0; k < 3; ++k) {
        const Sphere& b = ball(t[static_cast<std::size_t>(k + 1)]);
        m.row(k) = 2 * (b.center - c0).transpose();
        rhs(k) = (b.center - c0).squaredNorm() + ball(t[0]).radius * ball(t[0]).radius -
                 b.radius * b.radius;
      }
      const Vector3 z = c0 + m.partialPivLu().solve(rhs);
      for (std::int32_t i : t) EXPECT_LE(power(ball(i), z), 1e-9);
    }
    EXPECT_GT(c.tetrahedra.size(), 100u);
  }
}

TEST(DualComplex, PermutingTheInputPermutesTheComplex) {
  const std::vector<Sphere> balls = OverlappingBalls(80, 43);
  std::vector<std::int32_t> perm(balls.size());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), std::mt19937_64(44));
  std::vector<Sphere> shuffled(balls.size());
  for (std::size_t k = 0; k < perm.size(); ++k) {
    shuffled[static_cast<std::size_t>(perm[k])] = balls[k];
  }
  const DualComplex a = Complex(balls);
  const DualComplex b = Complex(shuffled);
  // Map a's simplices through perm and compare as sorted lists.
  const auto map = [&perm](auto simplices) {
    for (auto& s : simplices) {
      for (auto& i : s) i = perm[static_cast<std::size_t>(i)];
      std::sort(s.begin(), s.end());
    }
    std::sort(simplices.begin(), simplices.end());
    return simplices;
  };
  EXPECT_EQ(map(a.edges), b.edges);
  EXPECT_EQ(map(a.triangles), b.triangles);
  EXPECT_EQ(map(a.tetrahedra), b.tetrahedra);
}

TEST(DualComplex, DroppingRedundantBallsKeepsTheVolumeAndAReusedComplexAgrees) {
  // A dense set, so that some balls are covered by their neighbours.
  const std::vector<Sphere> balls = RandomBalls(200, 2.0, 0.2, 0.7, 45);
  const DualComplex c = Complex(balls);
  EXPECT_GT(c.redundant.size(), 5u);
  const double v = Volume(balls);
  absl::StatusOr<double> reused = UnionVolume(balls, c);
  ASSERT_TRUE(reused.ok()) << reused.status();
  EXPECT_EQ(*reused, v);
  std::vector<Sphere> kept;
  for (std::int32_t i : c.vertices) kept.push_back(balls[static_cast<std::size_t>(i)]);
  EXPECT_NEAR(Volume(kept), v, 1e-12 * v);
  // Each redundant ball lies in the union of the kept ones: sample it.
  const BallGrid grid(kept);
  std::mt19937_64 rng(46);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (std::int32_t i : c.redundant) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    for (int s = 0; s < 2000; ++s) {
      Vector3 p(unit(rng), unit(rng), unit(rng));
      if (p.squaredNorm() > 1) continue;
      EXPECT_TRUE(grid.Contains(b.center + b.radius * p)) << "redundant ball " << i;
    }
  }
}

}  // namespace
}  // namespace inscribe
