#include "inscribe/distance/rss.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "inscribe/medial/medial_spheres.h"
#include "inscribe/solid/boundary_oracle.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using Matrix3 = Eigen::Matrix3d;

// ---- Slow, obvious references --------------------------------------------------------------

// Distance from x to the rectangle of `r`: project into its frame and clamp.
double PointToRectangle(const Vector3& x, const Rss& r) {
  const Vector3 local = r.axes.transpose() * (x - r.origin);
  const double dx = local.x() - std::clamp(local.x(), 0.0, r.length[0]);
  const double dy = local.y() - std::clamp(local.y(), 0.0, r.length[1]);
  return std::sqrt(dx * dx + dy * dy + local.z() * local.z());
}

// n x n grid on the rectangle (a single row or point along a zero-length edge).
std::vector<Vector3> Grid(const Rss& r, int n) {
  std::vector<Vector3> points;
  const int ns = r.length[0] > 0 ? n : 1;
  const int nt = r.length[1] > 0 ? n : 1;
  for (int i = 0; i < ns; ++i) {
    for (int j = 0; j < nt; ++j) {
      const double s = ns > 1 ? r.length[0] * i / (ns - 1) : 0.0;
      const double t = nt > 1 ? r.length[1] * j / (nt - 1) : 0.0;
      points.push_back(r.origin + s * r.axes.col(0) + t * r.axes.col(1));
    }
  }
  return points;
}

// Largest distance from a point of the rectangle to the nearest grid point: half a cell's
// diagonal.
double GridSpacing(const Rss& r, int n) {
  return 0.5 * std::hypot(r.length[0], r.length[1]) / (n - 1);
}

// Minimum over both grids of all pairwise distances: >= the distance, and within the two
// grids' spacings of it.
double SampledDistance(const Rss& a, const Rss& b, int n) {
  const std::vector<Vector3> pa = Grid(a, n);
  const std::vector<Vector3> pb = Grid(b, n);
  double best = std::numeric_limits<double>::infinity();
  for (const Vector3& x : pa) {
    for (const Vector3& y : pb) best = std::min(best, (x - y).squaredNorm());
  }
  return std::sqrt(best);
}

// Minimum over a grid on one rectangle of the exact distance to the other, both ways round:
// >= the distance, and within one grid's spacing of it. Cheap enough for thousands of pairs.
double HalfSampledDistance(const Rss& a, const Rss& b, int n) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vector3& x : Grid(a, n)) best = std::min(best, PointToRectangle(x, b));
  for (const Vector3& y : Grid(b, n)) best = std::min(best, PointToRectangle(y, a));
  return best;
}

std::array<Vector3, 4> CornersOf(const Rss& r) {
  const Vector3 u = r.length[0] * r.axes.col(0);
  const Vector3 v = r.length[1] * r.axes.col(1);
  return {r.origin, r.origin + u, r.origin + v, r.origin + u + v};
}

// Gap between the rectangles' projections on the unit direction n (b's minus a's): a lower
// bound on their distance (separating-plane duality); the distance itself for n along the
// closest pair's difference.
double SeparationAlong(const Vector3& n, const Rss& a, const Rss& b) {
  double a_max = -std::numeric_limits<double>::infinity();
  double b_min = std::numeric_limits<double>::infinity();
  for (const Vector3& x : CornersOf(a)) a_max = std::max(a_max, n.dot(x));
  for (const Vector3& y : CornersOf(b)) b_min = std::min(b_min, n.dot(y));
  return b_min - a_max;
}

// ---- Random configurations -------------------------------------------------------------------

Matrix3 RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
      .normalized()
      .toRotationMatrix();
}

Matrix3 RotationAboutZ(double angle) {
  return Eigen::AngleAxisd(angle, Vector3::UnitZ()).toRotationMatrix();
}

Rss Rectangle(const Matrix3& axes, const Vector3& origin, double l0, double l1) {
  Rss r;
  r.axes = axes;
  r.origin = origin;
  r.length[0] = l0;
  r.length[1] = l1;
  return r;
}

// A point of the rectangle at parameters (s, t) in [0, 1]^2.
Vector3 At(const Rss& r, double s, double t) {
  return r.origin + s * r.length[0] * r.axes.col(0) + t * r.length[1] * r.axes.col(1);
}

// Configurations of rectangle pairs; kMismatched: a long rectangle and a tiny one.
enum class Kind {
  kGeneral,
  kParallel,
  kCoplanar,
  kNearParallel,
  kCrossing,
  kTouching,
  kDegenerate,
  kFar,
  kMismatched,
  kCount
};
constexpr const char* kKindNames[] = {"general",       "parallel", "coplanar",
                                      "near-parallel", "crossing", "touching",
                                      "degenerate",    "far",      "mismatched"};

struct RectanglePair {
  Rss a, b;
  bool intersecting;  // known by construction to share a point
};

RectanglePair RandomPair(std::mt19937_64& rng, Kind kind) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  auto offset = [&](double spread) {
    return Vector3(uniform(-spread, spread), uniform(-spread, spread), uniform(-spread, spread));
  };
  RectanglePair p;
  p.intersecting = false;
  // Exactly representable axis-aligned frames half of the time for the coplanar case.
  const Matrix3 frame =
      kind == Kind::kCoplanar && unit(rng) < 0.5 ? Matrix3::Identity() : RandomRotation(rng);
  p.a = Rectangle(frame, offset(1.0), uniform(0.05, 2.0), uniform(0.05, 2.0));
  const Vector3 n = frame.col(2);
  switch (kind) {
    case Kind::kGeneral:
    case Kind::kDegenerate:
      p.b = Rectangle(RandomRotation(rng), offset(1.5), uniform(0.05, 2.0), uniform(0.05, 2.0));
      if (kind == Kind::kDegenerate) {
        const int which = static_cast<int>(rng() % 6);
        if (which == 0 || which == 2) p.b.length[0] = 0.0;
        if (which == 1 || which == 2) p.b.length[1] = 0.0;
        if (which == 3 || which == 5) p.a.length[rng() % 2] = 0.0;
        if (which >= 4) p.b.length[0] = p.b.length[1] = 0.0;
        if (which == 5) p.a.length[0] = p.a.length[1] = 0.0;
      }
      break;
    case Kind::kParallel:
    case Kind::kCoplanar:
    case Kind::kNearParallel: {
      Matrix3 axes = frame * RotationAboutZ(uniform(0.0, 2 * M_PI));
      if (kind == Kind::kCoplanar && frame == Matrix3::Identity()) {
        axes = RotationAboutZ(M_PI / 2 * static_cast<double>(rng() % 4));
        axes = axes.array().round().matrix();  // exact quarter turns
      }
      if (kind == Kind::kNearParallel) {
        const double angle = std::pow(10.0, uniform(-9.0, -3.0));
        axes = Eigen::AngleAxisd(angle, Vector3(unit(rng), unit(rng), 0).normalized()) * axes;
      }
      const double height =
          kind == Kind::kCoplanar ? 0.0 : (unit(rng) < 0.5 ? -1 : 1) * uniform(0.0, 1.0);
      Vector3 origin = p.a.origin + frame * Vector3(uniform(-2, 2), uniform(-2, 2), height);
      if (kind == Kind::kCoplanar && frame == Matrix3::Identity()) {
        origin = (origin * 8).array().round().matrix() / 8;
        origin.z() = p.a.origin.z();
      }
      p.b = Rectangle(axes, origin, uniform(0.05, 2.0), uniform(0.05, 2.0));
      break;
    }
    case Kind::kCrossing: {
      // b passes through an interior point of a.
      const Vector3 x = At(p.a, unit(rng), unit(rng));
      p.b = Rectangle(RandomRotation(rng), Vector3::Zero(), uniform(0.05, 2.0), uniform(0.05, 2.0));
      p.b.origin = x - At(p.b, unit(rng), unit(rng));
      p.intersecting = true;
      break;
    }
    case Kind::kTouching: {
      // A corner or an edge point of b on a point, edge or corner of a, b on one side of a.
      const double s = rng() % 3 == 0 ? static_cast<double>(rng() % 2) : unit(rng);
      const double t = rng() % 3 == 0 ? static_cast<double>(rng() % 2) : unit(rng);
      const Vector3 x = At(p.a, s, t);
      Matrix3 axes = RandomRotation(rng);
      for (int k = 0; k < 2; ++k) {
        if (axes.col(k).dot(n) < 0) axes.col(k) = -axes.col(k);
      }
      axes.col(2) = axes.col(0).cross(axes.col(1));
      p.b = Rectangle(axes, Vector3::Zero(), uniform(0.05, 2.0), uniform(0.05, 2.0));
      p.b.origin = x - At(p.b, rng() % 2 == 0 ? 0.0 : unit(rng), 0.0);
      p.intersecting = true;
      break;
    }
    case Kind::kFar:
      p.b =
          Rectangle(RandomRotation(rng), offset(1.0) + offset(1.0).normalized() * uniform(10, 100),
                    uniform(0.05, 2.0), uniform(0.05, 2.0));
      break;
    case Kind::kMismatched:
      p.a.length[0] = uniform(5.0, 10.0);
      p.b = Rectangle(RandomRotation(rng), offset(1.5), uniform(0.001, 0.05), uniform(0.001, 0.05));
      break;
    case Kind::kCount:
      break;
  }
  if (unit(rng) < 0.5) std::swap(p.a, p.b);
  return p;
}

// ---- RectangleDistance ------------------------------------------------------------------------

// Witness points on their rectangles, realising the distance, and optimal: the gap between
// the projections along their difference equals the distance (duality), so no pair is closer.
void ExpectExactWitnesses(const RectanglePair& p, double d, const Vector3& pa, const Vector3& pb) {
  const double tol = 1e-12 * (1.0 + pa.norm() + pb.norm());
  EXPECT_LE(PointToRectangle(pa, p.a), tol);
  EXPECT_LE(PointToRectangle(pb, p.b), tol);
  EXPECT_NEAR((pa - pb).norm(), d, tol);
  if (d > 1e-3) {
    EXPECT_GE(SeparationAlong((pb - pa) / d, p.a, p.b), d - 1e-10);
  }
  if (p.intersecting) {
    EXPECT_LE(d, tol);
  }
}

TEST(RectangleDistance, MatchesDenseSamplingOfBothRectangles) {
  std::mt19937_64 rng(11);
  constexpr int kN = 60;
  for (int i = 0; i < 180; ++i) {
    const Kind kind = static_cast<Kind>(i % static_cast<int>(Kind::kCount));
    const RectanglePair p = RandomPair(rng, kind);
    SCOPED_TRACE(::testing::Message() << "pair " << i << " (" << kKindNames[i % 9] << ")");
    const double d = RectangleDistance(p.a, p.b, nullptr, nullptr);
    const double sampled = SampledDistance(p.a, p.b, kN);
    EXPECT_GE(sampled, d - 1e-12);
    EXPECT_LE(sampled, d + GridSpacing(p.a, kN) + GridSpacing(p.b, kN) + 1e-12);
  }
}

TEST(RectangleDistance, MatchesHalfSamplingAndWitnessesAreOptimal) {
  std::mt19937_64 rng(12);
  constexpr int kN = 60;
  std::array<int, static_cast<int>(Kind::kCount)> zero_count{};
  for (int i = 0; i < 9000; ++i) {
    const int k = i % static_cast<int>(Kind::kCount);
    const RectanglePair p = RandomPair(rng, static_cast<Kind>(k));
    SCOPED_TRACE(::testing::Message() << "pair " << i << " (" << kKindNames[k] << ")");
    Vector3 pa, pb;
    const double d = RectangleDistance(p.a, p.b, &pa, &pb);
    ExpectExactWitnesses(p, d, pa, pb);
    const double sampled = HalfSampledDistance(p.a, p.b, kN);
    EXPECT_GE(sampled, d - 1e-12);
    EXPECT_LE(sampled, d + std::min(GridSpacing(p.a, kN), GridSpacing(p.b, kN)) + 1e-12);
    // Symmetric in its arguments.
    EXPECT_NEAR(RectangleDistance(p.b, p.a, nullptr, nullptr), d, 1e-12 * (1 + d));
    // RssDistance (radii 0), with b given in a frame of its own placed by a random pose: its
    // transform and its shortcuts for point rectangles.
    const Matrix3 rotation = RandomRotation(rng);
    const Vector3 translation = RandomRotation(rng).col(0) * 3.0;
    Rss b_local = p.b;
    b_local.axes = rotation.transpose() * p.b.axes;
    b_local.origin = rotation.transpose() * (p.b.origin - translation);
    EXPECT_NEAR(RssDistance(p.a, rotation, translation, b_local), d, 1e-12 * (4 + d));
    zero_count[static_cast<std::size_t>(k)] += d == 0.0;
    if (::testing::Test::HasFailure()) break;
  }
  // Crossings are found as exact zeros with a common point, not as rounding-sized distances.
  EXPECT_EQ(zero_count[static_cast<int>(Kind::kCrossing)], 1000);
}

TEST(RectangleDistance, HandPickedConfigurations) {
  const Matrix3 id = Matrix3::Identity();
  const Rss unit = Rectangle(id, Vector3::Zero(), 1, 1);
  Vector3 pa, pb;
  // Parallel, overlapping in projection: the height.
  EXPECT_DOUBLE_EQ(RectangleDistance(unit, Rectangle(id, Vector3(0.5, 0.5, 2), 1, 1), &pa, &pb),
                   2.0);
  // Coplanar, apart along x.
  EXPECT_DOUBLE_EQ(RectangleDistance(unit, Rectangle(id, Vector3(3, 0.2, 0), 1, 1), &pa, &pb), 2.0);
  // Skew edges: a vertical wall whose edge x = 2 (along z) passes a's edge x = 1 (along y).
  Matrix3 upright;
  upright << 0, 1, 0, 0, 0, 1, 1, 0, 0;  // edges along z and x, normal along y
  const Rss wall = Rectangle(upright, Vector3(2, 0.5, -1), 2, 3);
  EXPECT_DOUBLE_EQ(RectangleDistance(unit, wall, &pa, &pb), 1.0);
  EXPECT_TRUE(pa.isApprox(Vector3(1, 0.5, 0)));
  EXPECT_TRUE(pb.isApprox(Vector3(2, 0.5, 0)));
  // A "+" cross of two coplanar strips: intersecting, no corner inside the other.
  const Rss strip_x = Rectangle(id, Vector3(-2, -0.5, 0), 4, 1);
  const Rss strip_y = Rectangle(id, Vector3(-0.5, -2, 0), 1, 4);
  EXPECT_LE(RectangleDistance(strip_x, strip_y, &pa, &pb), 1e-15);
  // Segment against point, point against point.
  const Rss segment = Rectangle(id, Vector3(0, 0, 0), 2, 0);
  const Rss point = Rectangle(id, Vector3(1, 3, 4), 0, 0);
  EXPECT_DOUBLE_EQ(RectangleDistance(segment, point, &pa, &pb), 5.0);
  EXPECT_TRUE(pa.isApprox(Vector3(1, 0, 0)));
  EXPECT_DOUBLE_EQ(RectangleDistance(point, Rectangle(id, Vector3(1, 3, 5), 0, 0), &pa, &pb), 1.0);
}

// ---- RssDistance ------------------------------------------------------------------------------

// Balls along a gently curved sheet (like a medial sheet, radii varying smoothly) or in a
// blob, around the origin: n balls of radius ~0.05-0.3 within about [-1, 1]^3.
std::vector<Sphere> RandomBalls(std::mt19937_64& rng, int n, bool sheet) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Matrix3 frame = RandomRotation(rng);
  const double bend = 0.3 * unit(rng);
  std::vector<Sphere> balls(static_cast<std::size_t>(n));
  for (Sphere& b : balls) {
    const double x = 2 * unit(rng) - 1, y = 0.6 * (2 * unit(rng) - 1);
    const double z = sheet ? bend * x * x : 0.5 * (2 * unit(rng) - 1);
    b.center = frame * Vector3(x, y, z);
    b.radius = sheet ? 0.05 + 0.2 * (0.5 + 0.5 * std::sin(2 * x + y)) : 0.05 + 0.25 * unit(rng);
  }
  return balls;
}

std::vector<std::int32_t> AllIndices(std::size_t n) {
  std::vector<std::int32_t> indices(n);
  std::iota(indices.begin(), indices.end(), 0);
  return indices;
}

// RssDistance lower-bounds every pair of balls, one from each RSS, and equals the rectangles'
// distance (computed in a common frame) minus the radii.
void ExpectLowerBoundForAllBallPairs(const std::vector<Sphere>& balls_a, const Rss& a,
                                     const std::vector<Sphere>& balls_b, const Rss& b,
                                     const Matrix3& rotation, const Vector3& translation) {
  const double bound = RssDistance(a, rotation, translation, b);
  double closest = std::numeric_limits<double>::infinity();
  for (const Sphere& x : balls_a) {
    for (const Sphere& y : balls_b) {
      const Vector3 moved = rotation * y.center + translation;
      closest = std::min(closest, (x.center - moved).norm() - x.radius - y.radius);
    }
  }
  EXPECT_LE(bound, closest + 1e-12);
  Rss moved = b;
  moved.axes = rotation * b.axes;
  moved.origin = rotation * b.origin + translation;
  EXPECT_NEAR(bound, RectangleDistance(a, moved, nullptr, nullptr) - a.radius - b.radius,
              1e-12 * (1 + translation.norm()));
}

TEST(RssDistance, LowerBoundsEveryBallPairUnderRandomPoses) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int overlapping = 0;
  for (int trial = 0; trial < 600; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    const std::vector<Sphere> balls_a = RandomBalls(rng, 40, trial % 2 == 0);
    const std::vector<Sphere> balls_b = RandomBalls(rng, 40, trial % 3 == 0);
    const Rss a = FitRss(balls_a, AllIndices(balls_a.size()).data(), balls_a.size());
    const Rss b = FitRss(balls_b, AllIndices(balls_b.size()).data(), balls_b.size());
    const Matrix3 rotation = RandomRotation(rng);
    const Vector3 translation = RandomRotation(rng).col(0) * 4.0 * unit(rng);
    ExpectLowerBoundForAllBallPairs(balls_a, a, balls_b, b, rotation, translation);
    overlapping += RssDistance(a, rotation, translation, b) < 0;
    if (::testing::Test::HasFailure()) break;
  }
  EXPECT_GT(overlapping, 50);  // the poses cover overlapping and separated volumes
  EXPECT_LT(overlapping, 550);
}

// ---- FitRss -----------------------------------------------------------------------------------

// Every ball inside; axes orthonormal and right-handed; and tight for its rectangle: some ball
// touches the swept surface.
void ExpectContainsAll(const std::vector<Sphere>& balls, const std::vector<std::int32_t>& indices,
                       const Rss& r) {
  EXPECT_TRUE((r.axes.transpose() * r.axes).isApprox(Matrix3::Identity(), 1e-12));
  EXPECT_NEAR(r.axes.determinant(), 1.0, 1e-12);
  EXPECT_GE(r.length[0], 0.0);
  EXPECT_GE(r.length[1], 0.0);
  double needed = 0.0;
  double magnitude = 0.0;
  for (const std::int32_t i : indices) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    magnitude = std::max(magnitude, b.center.cwiseAbs().maxCoeff());
    const double reach = PointToRectangle(b.center, r) + b.radius;
    EXPECT_LE(reach, r.radius * (1 + 1e-12)) << "ball " << i;
    needed = std::max(needed, reach);
  }
  // Tight up to FitRss's rounding pad (a few ulps of the radius and the coordinates).
  EXPECT_GE(needed, r.radius - 1e-13 * (r.radius + magnitude));
  // And as thin as the balls allow along its normal: the radius is half their spread.
  double top = -std::numeric_limits<double>::infinity(), bottom = -top;
  for (const std::int32_t i : indices) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    top = std::max(top, r.axes.col(2).dot(b.center) + b.radius);
    bottom = std::min(bottom, r.axes.col(2).dot(b.center) - b.radius);
  }
  EXPECT_NEAR(r.radius, 0.5 * (top - bottom), 1e-13 * (r.radius + magnitude));
}

// Moving any edge of positive length inward by `step` lets some ball out: the rectangle is no
// bigger than its balls require (for this orientation and radius).
void ExpectNoEdgeCanMoveIn(const std::vector<Sphere>& balls, const Rss& r, double step) {
  for (int k = 0; k < 2; ++k) {
    if (r.length[k] < 2 * step) continue;
    for (int side = 0; side < 2; ++side) {
      Rss shrunk = r;
      shrunk.length[k] -= step;
      if (side == 0) shrunk.origin += step * r.axes.col(k);
      double needed = 0.0;
      for (const Sphere& b : balls) {
        needed = std::max(needed, PointToRectangle(b.center, shrunk) + b.radius);
      }
      EXPECT_GT(needed, r.radius) << "edge " << k << " side " << side;
    }
  }
}

TEST(FitRss, ContainsRandomBallSetsAndIsTight) {
  std::mt19937_64 rng(31);
  for (int trial = 0; trial < 400; ++trial) {
    SCOPED_TRACE(::testing::Message() << "trial " << trial);
    std::vector<Sphere> balls = RandomBalls(rng, 2 + trial % 60, trial % 2 == 0);
    if (trial % 5 == 0) {  // far from the origin: the rounding pad must cover the offset
      for (Sphere& b : balls) b.center += Vector3(1e3, -2e3, 5e2);
    }
    const std::vector<std::int32_t> indices = AllIndices(balls.size());
    const Rss r = FitRss(balls, indices.data(), indices.size());
    ExpectContainsAll(balls, indices, r);
    ExpectNoEdgeCanMoveIn(balls, r, 1e-4);
    if (::testing::Test::HasFailure()) break;
  }
}

TEST(FitRss, UsesOnlyTheIndexedBalls) {
  std::mt19937_64 rng(32);
  const std::vector<Sphere> balls = RandomBalls(rng, 100, true);
  const std::vector<std::int32_t> subset = {3, 17, 42, 43, 99, 5};
  const Rss r = FitRss(balls, subset.data(), subset.size());
  ExpectContainsAll(balls, subset, r);
  std::vector<Sphere> picked;
  for (const std::int32_t i : subset) picked.push_back(balls[static_cast<std::size_t>(i)]);
  const Rss same = FitRss(picked, AllIndices(picked.size()).data(), picked.size());
  EXPECT_EQ(r.radius, same.radius);
  EXPECT_TRUE(r.origin.isApprox(same.origin, 1e-15));
}

TEST(FitRss, FlatSheetOfEqualBallsHasTheirRadius) {
  std::mt19937_64 rng(33);
  for (int trial = 0; trial < 20; ++trial) {
    const Matrix3 frame = RandomRotation(rng);
    const Vector3 offset = 10.0 * RandomRotation(rng).col(0);
    std::vector<Sphere> balls;
    for (int i = 0; i < 10; ++i) {
      for (int j = 0; j < 4; ++j)
        balls.push_back({offset + frame * Vector3(0.3 * i, 0.2 * j, 0), 0.25});
    }
    const std::vector<std::int32_t> indices = AllIndices(balls.size());
    const Rss r = FitRss(balls, indices.data(), indices.size());
    ExpectContainsAll(balls, indices, r);
    EXPECT_NEAR(r.radius, 0.25, 1e-9);
    EXPECT_NEAR(r.length[0], 2.7, 1e-9);  // the centres' extents, the longer one first
    EXPECT_NEAR(r.length[1], 0.6, 1e-9);
    EXPECT_NEAR(std::abs(r.axes.col(2).dot(frame.col(2))), 1.0, 1e-12);
  }
}

TEST(FitRss, DegenerateSets) {
  // A single ball: a point rectangle at its centre with its radius, exactly.
  const std::vector<Sphere> one = {{Vector3(1, 2, 3), 0.5}};
  const std::int32_t zero = 0;
  const Rss single = FitRss(one, &zero, 1);
  EXPECT_EQ(single.origin, Vector3(1, 2, 3));
  EXPECT_EQ(single.radius, 0.5);
  EXPECT_EQ(single.length[0], 0.0);
  EXPECT_EQ(single.length[1], 0.0);

  // Coincident centres: a point rectangle, the largest radius.
  std::vector<Sphere> coincident;
  for (double r : {0.1, 0.7, 0.3}) coincident.push_back({Vector3(-4, 0.5, 2), r});
  const std::vector<std::int32_t> three = AllIndices(3);
  const Rss point = FitRss(coincident, three.data(), 3);
  ExpectContainsAll(coincident, three, point);
  EXPECT_NEAR(point.radius, 0.7, 1e-12);
  EXPECT_LE(point.length[0] + point.length[1], 1e-12);

  // Collinear centres with equal radii: a segment along the line, the balls' radius.
  std::vector<Sphere> line;
  const Vector3 direction = Vector3(1, 2, -2) / 3;
  for (int i = 0; i < 7; ++i) line.push_back({Vector3(1, 1, 1) + 0.5 * i * direction, 0.2});
  const std::vector<std::int32_t> seven = AllIndices(7);
  const Rss segment = FitRss(line, seven.data(), 7);
  ExpectContainsAll(line, seven, segment);
  EXPECT_NEAR(segment.radius, 0.2, 1e-12);
  EXPECT_NEAR(segment.length[0], 3.0, 1e-12);
  EXPECT_NEAR(segment.length[1], 0.0, 1e-12);
  EXPECT_NEAR(std::abs(segment.axes.col(0).dot(direction)), 1.0, 1e-12);

  // Four points (zero radii) in a plane: a flat rectangle through them, radius 0.
  const std::vector<Sphere> points = {{Vector3(0, 0, 0), 0.0},
                                      {Vector3(1, 1, 0), 0.0},
                                      {Vector3(2, 0, 0), 0.0},
                                      {Vector3(1, -1, 0), 0.0}};
  const std::vector<std::int32_t> four = AllIndices(4);
  const Rss square = FitRss(points, four.data(), 4);
  ExpectContainsAll(points, four, square);
  EXPECT_LE(square.radius, 1e-12);
}

// ---- Real input: medial spheres of a mesh, grouped like a hierarchy's nodes ---------------

// Index sets of a binary hierarchy over `spheres` by median splits along the widest axis of
// the centres, every node down to leaves of at most 4: the sets an RSS hierarchy fits.
void MedianSplit(const std::vector<Sphere>& spheres, std::vector<std::int32_t> indices,
                 std::vector<std::vector<std::int32_t>>* nodes) {
  nodes->push_back(indices);
  if (indices.size() <= 4) return;
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const std::int32_t i : indices) {
    lo = lo.cwiseMin(spheres[static_cast<std::size_t>(i)].center);
    hi = hi.cwiseMax(spheres[static_cast<std::size_t>(i)].center);
  }
  int axis;
  (hi - lo).maxCoeff(&axis);
  const auto middle = indices.begin() + static_cast<std::ptrdiff_t>(indices.size() / 2);
  std::nth_element(indices.begin(), middle, indices.end(), [&](std::int32_t x, std::int32_t y) {
    return spheres[static_cast<std::size_t>(x)].center[axis] <
           spheres[static_cast<std::size_t>(y)].center[axis];
  });
  MedianSplit(spheres, std::vector<std::int32_t>(indices.begin(), middle), nodes);
  MedianSplit(spheres, std::vector<std::int32_t>(middle, indices.end()), nodes);
}

TEST(Rss, MedialSpheresOfARealMesh) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  const absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  ASSERT_TRUE(oracle.ok()) << oracle.status();
  MedialSphereOptions options;
  const double diagonal = ComputeBoundingBox(mesh.vertices).diagonal();
  options.voxel_size = diagonal / 30;
  const absl::StatusOr<MedialSphereResult> generated = GenerateMedialSpheres(*oracle, options);
  ASSERT_TRUE(generated.ok()) << generated.status();
  const std::vector<Sphere>& spheres = generated->set.spheres;
  ASSERT_GT(spheres.size(), 100u);

  std::vector<std::vector<std::int32_t>> nodes;
  MedianSplit(spheres, AllIndices(spheres.size()), &nodes);
  std::vector<Rss> fitted;
  for (const std::vector<std::int32_t>& node : nodes) {
    fitted.push_back(FitRss(spheres, node.data(), node.size()));
    ExpectContainsAll(spheres, node, fitted.back());
  }
  // Medial sheets are flat: the leaves' slabs are much thinner than their rectangles are long.
  double leaf_radius = 0, leaf_extent = 0;
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    if (nodes[n].size() < 4) continue;
    leaf_radius += fitted[n].radius;
    leaf_extent += fitted[n].length[0];
  }
  EXPECT_GT(leaf_extent, leaf_radius);

  // Pairs of nodes of the object and of a moved copy of it.
  std::mt19937_64 rng(41);
  std::uniform_int_distribution<std::size_t> pick(0, nodes.size() - 1);
  for (int trial = 0; trial < 1500; ++trial) {
    const std::size_t i = pick(rng), j = pick(rng);
    SCOPED_TRACE(::testing::Message() << "nodes " << i << ", " << j);
    const Matrix3 rotation = trial % 2 == 0 ? Matrix3::Identity() : RandomRotation(rng);
    const Vector3 translation = trial % 2 == 0
                                    ? Vector3(Vector3::Zero())
                                    : Vector3(RandomRotation(rng).col(0) * 0.3 * diagonal);
    std::vector<Sphere> balls_i, balls_j;
    for (const std::int32_t k : nodes[i]) balls_i.push_back(spheres[static_cast<std::size_t>(k)]);
    for (const std::int32_t k : nodes[j]) balls_j.push_back(spheres[static_cast<std::size_t>(k)]);
    ExpectLowerBoundForAllBallPairs(balls_i, fitted[i], balls_j, fitted[j], rotation, translation);
    RectanglePair p{fitted[i], fitted[j], i == j && trial % 2 == 0};
    p.b.axes = rotation * p.b.axes;
    p.b.origin = rotation * p.b.origin + translation;
    Vector3 pa, pb;
    const double d = RectangleDistance(p.a, p.b, &pa, &pb);
    ExpectExactWitnesses(p, d, pa, pb);
    const double sampled = HalfSampledDistance(p.a, p.b, 40);
    EXPECT_GE(sampled, d - 1e-12);
    EXPECT_LE(sampled, d + std::min(GridSpacing(p.a, 40), GridSpacing(p.b, 40)) + 1e-12);
    if (::testing::Test::HasFailure()) break;
  }
}

}  // namespace
}  // namespace inscribe
