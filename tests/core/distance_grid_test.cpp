// Signed distance grids and primitives against independent oracles: a grid sampled from an
// analytic field (a union of balls, exact distance by brute force), and each primitive's
// distance from its closest point found by clamping or dense sampling.
#include "inscribe/env/distance_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "inscribe/env/combined_environment.h"
#include "inscribe/env/point_cloud.h"
#include "inscribe/env/primitives.h"

namespace inscribe {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Field {
  std::vector<Sphere> balls;
  // min over balls of |x - c| - r: 1-Lipschitz (a minimum of 1-Lipschitz functions), the
  // exact distance to the union outside it, negative exactly inside it.
  double operator()(const Vector3& x) const {
    double best = kInf;
    for (const Sphere& b : balls) best = std::min(best, (x - b.center).norm() - b.radius);
    return best;
  }
};

TEST(SignedDistanceGrid, IntervalsHoldTheSampledField) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> coordinate(-0.4, 0.4), radius(0.03, 0.12);
  Field field;
  for (int i = 0; i < 12; ++i) {
    field.balls.push_back(
        {Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), radius(rng)});
  }
  DistanceGridLayout layout;
  layout.dims = Vector3(1.0, 0.8, 0.9);
  layout.voxel_size = 0.02;
  layout.pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vector3(1, 2, 3).normalized()));
  layout.pose.translation = Vector3(0.05, -0.02, 0.1);
  absl::StatusOr<std::array<int, 3>> n = DistanceGridVoxels(layout);
  ASSERT_TRUE(n.ok()) << n.status();
  EXPECT_EQ((*n)[0], 50);
  EXPECT_EQ((*n)[1], 40);
  EXPECT_EQ((*n)[2], 45);
  // Sampled through SamplePosition of a first grid, so the values are the field's at the samples.
  std::vector<float> values(static_cast<std::size_t>((*n)[0]) * (*n)[1] * (*n)[2], 0.0f);
  absl::StatusOr<SignedDistanceGrid> probe = SignedDistanceGrid::Create(layout, values);
  ASSERT_TRUE(probe.ok()) << probe.status();
  double error = 0.0;
  for (int x = 0; x < (*n)[0]; ++x) {
    for (int y = 0; y < (*n)[1]; ++y) {
      for (int z = 0; z < (*n)[2]; ++z) {
        const double f = field(probe->SamplePosition(x, y, z));
        const float stored = static_cast<float>(f);
        error = std::max(error, std::abs(static_cast<double>(stored) - f));
        values[(static_cast<std::size_t>(x) * (*n)[1] + y) * (*n)[2] + z] = stored;
      }
    }
  }
  DistanceGridOptions options;
  options.value_error = error;  // the float rounding: the grid's stated error
  absl::StatusOr<SignedDistanceGrid> grid = SignedDistanceGrid::Create(layout, values, options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  std::uniform_real_distribution<double> anywhere(-0.9, 0.9), ball_radius(0.0, 0.1);
  int clear = 0, colliding = 0;
  for (int i = 0; i < 20000; ++i) {
    const Sphere ball{Vector3(anywhere(rng), anywhere(rng), anywhere(rng)), ball_radius(rng)};
    const double truth = field(ball.center) - ball.radius;
    ClearanceInterval interval;
    grid->Clearances(absl::MakeConstSpan(&ball, 1), {}, absl::MakeSpan(&interval, 1));
    ASSERT_LE(interval.lower, truth) << i;
    ASSERT_GE(interval.upper, truth) << i;
    const Vector3 local = layout.pose.Inverse() * ball.center;
    if ((local.cwiseAbs().array() < 0.5 * layout.dims.array()).all()) {  // inside the grid
      ASSERT_LE(interval.upper - interval.lower,
                2 * error + std::sqrt(3.0) * layout.voxel_size + 1e-9);
    }
    const bool says_collides = grid->FirstColliding(absl::MakeConstSpan(&ball, 1)) == 0;
    if (truth <= 0) ASSERT_TRUE(says_collides) << i;  // never a missed collision
    clear += !says_collides;
    colliding += truth <= 0;
  }
  EXPECT_GT(clear, 1000);
  EXPECT_GT(colliding, 200);
}

TEST(SignedDistanceGrid, TruncatedValuesGiveNoUpperBound) {
  DistanceGridLayout layout;
  layout.dims = Vector3(0.1, 0.1, 0.1);
  layout.voxel_size = 0.05;
  DistanceGridOptions options;
  options.truncation = 0.2;
  absl::StatusOr<SignedDistanceGrid> grid = SignedDistanceGrid::Create(
      layout, std::vector<float>(8, std::numeric_limits<float>::infinity()), options);
  ASSERT_TRUE(grid.ok()) << grid.status();
  ClearanceInterval interval;
  const Sphere ball{Vector3::Zero(), 0.01};
  grid->Clearances(absl::MakeConstSpan(&ball, 1), {}, absl::MakeSpan(&interval, 1));
  EXPECT_EQ(interval.upper, kInf);
}

TEST(SignedDistanceGrid, BadLayoutsNameTheField) {
  DistanceGridLayout layout;
  layout.dims = Vector3(1.0, 1.0, 1.01);
  layout.voxel_size = 0.02;
  absl::StatusOr<std::array<int, 3>> n = DistanceGridVoxels(layout);
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.status().message().find("dims z"), std::string::npos);
  layout.dims = Vector3(0.04, 0.04, 0.04);
  std::vector<float> values(8, 1.0f);
  values[5] = std::nanf("");
  absl::StatusOr<SignedDistanceGrid> grid = SignedDistanceGrid::Create(layout, values);
  ASSERT_FALSE(grid.ok());
  EXPECT_NE(grid.status().message().find("value 5"), std::string::npos);
  EXPECT_FALSE(SignedDistanceGrid::Create(layout, std::vector<float>(7, 1.0f)).ok());
  DistanceGridOptions options;
  options.lipschitz = 0.0;
  EXPECT_FALSE(SignedDistanceGrid::Create(layout, std::vector<float>(8, 1.0f), options).ok());
}

// Closest points by other means: clamping (box, cylinder) and dense sampling of the axis
// (capsule); inside points by the shape's definition.
double OracleDistance(const Primitive& p, const Vector3& world) {
  const Vector3 x = p.pose.rotation.conjugate() * (world - p.pose.translation);
  switch (p.shape) {
    case PrimitiveShape::kBox: {
      const Vector3 clamped = x.cwiseMax(-p.half_extents).cwiseMin(p.half_extents);
      if (clamped != x) return (x - clamped).norm();
      return -(p.half_extents - x.cwiseAbs()).minCoeff();
    }
    case PrimitiveShape::kSphere:
      return x.norm() - p.radius;
    case PrimitiveShape::kCapsule: {
      double best = kInf;
      for (int k = 0; k <= 20000; ++k) {
        const double z = -p.half_length + 2 * p.half_length * k / 20000.0;
        best = std::min(best, (x - Vector3(0, 0, z)).norm());
      }
      return best - p.radius;
    }
    case PrimitiveShape::kCylinder: {
      const double rho = std::sqrt(x.x() * x.x() + x.y() * x.y());
      const double cr = std::min(rho, p.radius),
                   cz = std::clamp(x.z(), -p.half_length, p.half_length);
      if (rho > p.radius || std::abs(x.z()) > p.half_length) {
        return std::sqrt((rho - cr) * (rho - cr) + (x.z() - cz) * (x.z() - cz));
      }
      return -std::min(p.radius - rho, p.half_length - std::abs(x.z()));
    }
    case PrimitiveShape::kPlane:
      return x.z();
  }
  return 0;
}

TEST(PrimitiveEnvironment, DistancesEqualOracles) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Primitive> primitives;
  for (PrimitiveShape shape :
       {PrimitiveShape::kBox, PrimitiveShape::kSphere, PrimitiveShape::kCapsule,
        PrimitiveShape::kCylinder, PrimitiveShape::kPlane}) {
    Primitive p;
    p.shape = shape;
    p.pose.rotation = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
    p.pose.translation = Vector3(u(rng), u(rng), u(rng)) * 0.3;
    p.half_extents = Vector3(0.1, 0.2, 0.15);
    p.radius = 0.12;
    p.half_length = 0.2;
    for (int i = 0; i < 3000; ++i) {
      const Vector3 x(u(rng), u(rng), u(rng));
      const double tolerance = shape == PrimitiveShape::kCapsule ? 1e-4 : 1e-12;
      ASSERT_NEAR(PrimitiveSignedDistance(p, x), OracleDistance(p, x), tolerance)
          << PrimitiveShapeName(shape) << " point " << i;
    }
    primitives.push_back(p);
  }
  absl::StatusOr<PrimitiveEnvironment> environment = PrimitiveEnvironment::Create(primitives);
  ASSERT_TRUE(environment.ok()) << environment.status();
  for (int i = 0; i < 3000; ++i) {
    const Sphere ball{Vector3(u(rng), u(rng), u(rng)) * 1.5, 0.05};
    double truth = kInf;
    for (const Primitive& p : primitives) truth = std::min(truth, OracleDistance(p, ball.center));
    truth -= ball.radius;
    ClearanceInterval interval;
    environment->Clearances(absl::MakeConstSpan(&ball, 1), {}, absl::MakeSpan(&interval, 1));
    ASSERT_LE(interval.lower, truth + 1e-4);
    ASSERT_GE(interval.upper, truth - 1e-4);
    if (std::abs(truth) > 1e-4) {
      ASSERT_EQ(environment->FirstColliding(absl::MakeConstSpan(&ball, 1)) == 0, truth <= 0);
    }
  }
  Primitive bad;
  bad.shape = PrimitiveShape::kCylinder;
  bad.radius = 0.1;
  absl::StatusOr<PrimitiveEnvironment> refused = PrimitiveEnvironment::Create({bad});
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("half_length"), std::string::npos);
}

TEST(CombinedEnvironment, TakesTheSmallestClearance) {
  Primitive floor;
  floor.shape = PrimitiveShape::kPlane;
  absl::StatusOr<PrimitiveEnvironment> primitives = PrimitiveEnvironment::Create({floor});
  ASSERT_TRUE(primitives.ok());
  const std::vector<Vector3> points = {Vector3(0, 0, 1.0)};
  absl::StatusOr<PointCloud> cloud = PointCloud::Create(points, {});
  ASSERT_TRUE(cloud.ok());
  const CombinedEnvironment both({&*primitives, &*cloud});
  const std::vector<Sphere> balls = {{Vector3(0, 0, 0.6), 0.1},    // 0.5 above the floor, 0.3
                                     {Vector3(0, 0, 0.95), 0.1},   // touches the point
                                     {Vector3(0, 0, 0.05), 0.1}};  // in the floor
  std::vector<ClearanceInterval> out(3);
  both.Clearances(balls, {}, absl::MakeSpan(out));
  EXPECT_NEAR(out[0].lower, 0.3, 1e-9);
  EXPECT_NEAR(out[2].upper, -0.05, 1e-9);
  EXPECT_EQ(both.FirstColliding(balls), 1);
  EXPECT_EQ(both.FirstColliding(absl::MakeConstSpan(balls).subspan(0, 1)), -1);
}

}  // namespace
}  // namespace inscribe
