// The cloud filters against brute force: every point classified by its own loop, every voxel
// by a std::map of its integer coordinates, every self-filter point against every ball.
#include "inscribe/env/point_filters.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <tuple>
#include <vector>

namespace inscribe {
namespace {

std::vector<Vector3> RandomPoints(int n, std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> coordinate(-spread, spread);
  std::vector<Vector3> points;
  for (int i = 0; i < n; ++i)
    points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  return points;
}

TEST(FilterPoints, CountsEveryReason) {
  std::mt19937_64 rng(1);
  std::vector<Vector3> points = RandomPoints(5000, rng, 2.0);
  points[10].x() = std::nan("");
  points[20].z() = std::numeric_limits<double>::infinity();
  PointFilterOptions options;
  options.workspace = BoundingBox{Vector3(-1, -1.5, -1), Vector3(1.5, 1, 1)};
  options.sensor = Vector3(0.2, 0.1, 0);
  options.min_range = 0.3;
  options.max_range = 1.4;
  absl::StatusOr<FilteredPoints> out = FilterPoints(points, options);
  ASSERT_TRUE(out.ok()) << out.status();
  std::int64_t non_finite = 0, outside = 0, range = 0;
  std::vector<std::int64_t> kept;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vector3& p = points[i];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
      ++non_finite;
    } else if (p.x() < -1 || p.x() > 1.5 || p.y() < -1.5 || p.y() > 1 || p.z() < -1 || p.z() > 1) {
      ++outside;
    } else if (std::hypot(p.x() - 0.2, p.y() - 0.1, p.z()) < 0.3 ||
               std::hypot(p.x() - 0.2, p.y() - 0.1, p.z()) > 1.4) {
      ++range;
    } else {
      kept.push_back(static_cast<std::int64_t>(i));
    }
  }
  EXPECT_EQ(out->dropped_non_finite, non_finite);
  EXPECT_EQ(out->dropped_outside_workspace, outside);
  EXPECT_EQ(out->dropped_out_of_range, range);
  EXPECT_EQ(out->kept, kept);
  ASSERT_EQ(out->points.size(), kept.size());
  options.min_range = 2.0;
  options.max_range = 1.0;
  absl::StatusOr<FilteredPoints> bad = FilterPoints(points, options);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("min_range"), std::string::npos);
}

TEST(VoxelDownsample, OnePointPerVoxelWithinMaxShift) {
  std::mt19937_64 rng(2);
  const std::vector<Vector3> points = RandomPoints(20000, rng, 0.5);
  const double voxel = 0.05;
  absl::StatusOr<DownsampledPoints> out = VoxelDownsample(points, voxel);
  ASSERT_TRUE(out.ok()) << out.status();
  std::map<std::tuple<long, long, long>, std::int64_t> first;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto key = std::make_tuple(std::lround(std::floor(points[i].x() / voxel)),
                                     std::lround(std::floor(points[i].y() / voxel)),
                                     std::lround(std::floor(points[i].z() / voxel)));
    first.emplace(key, static_cast<std::int64_t>(i));
  }
  ASSERT_EQ(out->points.size(), first.size());
  EXPECT_EQ(out->dropped, static_cast<std::int64_t>(points.size() - first.size()));
  std::vector<std::int64_t> expected;
  for (const auto& [key, index] : first) expected.push_back(index);
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(out->kept, expected);
  // Every input point is within max_shift of a kept one, and max_shift <= sqrt(3) voxel.
  EXPECT_LE(out->max_shift, std::sqrt(3.0) * voxel * (1 + 1e-12));
  for (std::size_t i = 0; i < points.size(); i += 7) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vector3& k : out->points) nearest = std::min(nearest, (points[i] - k).norm());
    ASSERT_LE(nearest, out->max_shift);
  }
  EXPECT_FALSE(VoxelDownsample(points, 0.0).ok());
  const std::vector<Vector3> far = {Vector3(1e9, 0, 0)};
  absl::StatusOr<DownsampledPoints> too_far = VoxelDownsample(far, 1e-3);
  ASSERT_FALSE(too_far.ok());
  EXPECT_NE(too_far.status().message().find("voxel_size"), std::string::npos);
}

TEST(SelfFilterPoints, DropsExactlyThePointsInsideBalls) {
  std::mt19937_64 rng(3);
  const std::vector<Vector3> points = RandomPoints(30000, rng, 1.0);
  std::uniform_real_distribution<double> coordinate(-0.8, 0.8), radius(0.01, 0.15);
  for (const int count : {1, 7, 60}) {
    std::vector<Sphere> balls;
    for (int b = 0; b < count; ++b) {
      balls.push_back({Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), radius(rng)});
    }
    absl::StatusOr<SelfFilteredPoints> out = SelfFilterPoints(points, balls);
    ASSERT_TRUE(out.ok()) << out.status();
    std::vector<std::int64_t> kept;
    for (std::size_t i = 0; i < points.size(); ++i) {
      bool inside = false;
      for (const Sphere& ball : balls) {
        inside = inside || (points[i] - ball.center).norm() <= ball.radius;
      }
      if (!inside) kept.push_back(static_cast<std::int64_t>(i));
    }
    EXPECT_EQ(out->kept, kept) << count << " balls";
    EXPECT_EQ(out->dropped, static_cast<std::int64_t>(points.size() - kept.size()));
    EXPECT_GT(out->dropped, 0);
  }
  const std::vector<Sphere> bad = {{Vector3(0, 0, 0), -1.0}};
  EXPECT_FALSE(SelfFilterPoints(points, bad).ok());
}

}  // namespace
}  // namespace inscribe
