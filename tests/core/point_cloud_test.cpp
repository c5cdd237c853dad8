// PointCloud against a brute force over every point in long double (shares no code with the
// index: no cells, no distance transform), on random clouds and on CGAL demo meshes' vertices.
#include "inscribe/env/point_cloud.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "env/distance_transform.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// min over points of |c - p| - r_p (long double), the ball's radius not taken off.
long double BruteSurfaceDistance(const std::vector<Vector3>& points,
                                 const std::vector<double>& radii, const Vector3& c) {
  long double best = std::numeric_limits<long double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const long double dx = static_cast<long double>(c.x()) - points[i].x();
    const long double dy = static_cast<long double>(c.y()) - points[i].y();
    const long double dz = static_cast<long double>(c.z()) - points[i].z();
    best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz) - radii[i]);
  }
  return best;
}

struct RandomCloud {
  std::vector<Vector3> points;
  std::vector<double> radii;
};

RandomCloud MakeRandomCloud(int n, std::mt19937_64& rng, bool varied_radii) {
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0), radius(0.0, 0.02);
  RandomCloud cloud;
  // Half uniform, half clustered on a few blobs: empty space and dense cells both.
  std::normal_distribution<double> blob(0.0, 0.05);
  std::vector<Vector3> centres;
  for (int k = 0; k < 5; ++k)
    centres.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
  for (int i = 0; i < n; ++i) {
    if (i % 2 == 0) {
      cloud.points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));
    } else {
      cloud.points.push_back(centres[i % 5] + Vector3(blob(rng), blob(rng), blob(rng)));
    }
    cloud.radii.push_back(varied_radii ? radius(rng) : 0.01);
  }
  return cloud;
}

void ExpectMatchesBruteForce(const PointCloud& cloud, const std::vector<Vector3>& points,
                             const std::vector<double>& radii, int balls, std::mt19937_64& rng,
                             double spread) {
  std::uniform_real_distribution<double> coordinate(-spread, spread), radius(0.0, 0.12);
  int collisions = 0;
  for (int b = 0; b < balls; ++b) {
    const Sphere ball{Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), radius(rng)};
    const long double truth = BruteSurfaceDistance(points, radii, ball.center) - ball.radius;
    const bool colliding = truth <= 0;
    collisions += colliding;
    ASSERT_EQ(cloud.FirstColliding(absl::MakeConstSpan(&ball, 1)) == 0, colliding)
        << "ball " << b << " truth " << static_cast<double>(truth);
    for (const ClearanceRequest& request :
         {ClearanceRequest{0.0, kInf}, ClearanceRequest{kInf, kInf}, ClearanceRequest{0.01, kInf},
          ClearanceRequest{0.0, 0.1}}) {
      ClearanceInterval interval;
      cloud.Clearances(absl::MakeConstSpan(&ball, 1), request, absl::MakeSpan(&interval, 1));
      ASSERT_LE(interval.lower, truth) << "ball " << b << " tolerance " << request.tolerance;
      ASSERT_GE(interval.upper, truth) << "ball " << b << " tolerance " << request.tolerance;
      if (interval.lower < request.max_distance - 1e-9) {
        ASSERT_LE(interval.upper - interval.lower, request.tolerance + 1e-9)
            << "ball " << b << " tolerance " << request.tolerance;
      } else {
        ASSERT_GE(truth, request.max_distance - 1e-9);
      }
    }
  }
  // The draws must exercise both answers.
  EXPECT_GT(collisions, balls / 20);
  EXPECT_LT(collisions, balls - balls / 20);
}

TEST(PointCloud, RandomCloudsEqualBruteForce) {
  std::mt19937_64 rng(1);
  for (const bool varied : {false, true}) {
    for (const double cell : {0.0, 0.02, 0.3}) {
      const RandomCloud random = MakeRandomCloud(3000, rng, varied);
      PointCloudOptions options;
      options.point_radius = 0.01;
      options.cell_size = cell;
      absl::StatusOr<PointCloud> cloud =
          PointCloud::Create(random.points, varied ? random.radii : std::vector<double>{}, options);
      ASSERT_TRUE(cloud.ok()) << cloud.status();
      ExpectMatchesBruteForce(*cloud, random.points, random.radii, 1500, rng, 1.3);
    }
  }
}

TEST(PointCloud, BatchAnswersTheFirstCollidingBall) {
  std::mt19937_64 rng(2);
  const RandomCloud random = MakeRandomCloud(2000, rng, false);
  absl::StatusOr<PointCloud> cloud = PointCloud::Create(random.points, random.radii);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  std::uniform_real_distribution<double> coordinate(-1.5, 1.5), radius(0.0, 0.05);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Sphere> balls(60);
    int expected = -1;
    for (int i = 0; i < 60; ++i) {
      balls[i] = {Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), radius(rng)};
      if (expected < 0 &&
          BruteSurfaceDistance(random.points, random.radii, balls[i].center) - balls[i].radius <=
              0) {
        expected = i;
      }
    }
    ASSERT_EQ(cloud->FirstColliding(balls), expected) << "trial " << trial;
    std::vector<ClearanceInterval> out(60);
    cloud->Clearances(balls, {}, absl::MakeSpan(out));
    for (int i = 0; i < 60; ++i) {
      const long double truth =
          BruteSurfaceDistance(random.points, random.radii, balls[i].center) - balls[i].radius;
      ASSERT_LE(out[i].lower, truth);
      ASSERT_GE(out[i].upper, truth);
    }
  }
}

TEST(PointCloud, MeshVerticesEqualBruteForce) {
  for (const char* name : {"eight.off", "bunny00.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const Mesh mesh = testing::LoadTestMesh(name);
    // Scaled into a 1 m box.
    const BoundingBox box = ComputeBoundingBox(mesh.vertices);
    const double scale = 1.0 / box.extent().maxCoeff();
    std::vector<Vector3> points;
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
      points.push_back((Vector3(mesh.vertices.row(v)) - box.min) * scale - Vector3::Constant(0.5));
    }
    PointCloudOptions options;
    options.point_radius = 0.005;
    absl::StatusOr<PointCloud> cloud = PointCloud::Create(points, {}, options);
    ASSERT_TRUE(cloud.ok()) << cloud.status();
    std::mt19937_64 rng(3);
    ExpectMatchesBruteForce(*cloud, points, std::vector<double>(points.size(), 0.005), 400, rng,
                            0.7);
  }
}

TEST(PointCloud, TinyCellBudgetStillSound) {
  std::mt19937_64 rng(4);
  const RandomCloud random = MakeRandomCloud(1000, rng, true);
  PointCloudOptions options;
  options.cell_size = 0.001;
  options.max_cells = 64;
  absl::StatusOr<PointCloud> cloud = PointCloud::Create(random.points, random.radii, options);
  ASSERT_TRUE(cloud.ok()) << cloud.status();
  EXPECT_LE(cloud->cells(), 64);
  EXPECT_GT(cloud->cell_size(), 0.001);
  ExpectMatchesBruteForce(*cloud, random.points, random.radii, 300, rng, 1.0);
}

TEST(PointCloud, EmptyAndSinglePointClouds) {
  absl::StatusOr<PointCloud> empty = PointCloud::Create({}, {});
  ASSERT_TRUE(empty.ok());
  const Sphere ball{Vector3(0, 0, 0), 1.0};
  EXPECT_EQ(empty->FirstColliding(absl::MakeConstSpan(&ball, 1)), -1);
  const std::vector<Vector3> one = {Vector3(0.5, 0, 0)};
  absl::StatusOr<PointCloud> single = PointCloud::Create(one, {});
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->FirstColliding(absl::MakeConstSpan(&ball, 1)), 0);
  ClearanceInterval interval;
  const Sphere small{Vector3(0, 0, 0), 0.1};
  single->Clearances(absl::MakeConstSpan(&small, 1), {}, absl::MakeSpan(&interval, 1));
  EXPECT_NEAR(interval.lower, 0.4, 1e-12);
  EXPECT_NEAR(interval.upper, 0.4, 1e-12);
}

TEST(PointCloud, BadInputNamesTheFix) {
  const std::vector<Vector3> bad = {Vector3(0, 0, 0), Vector3(std::nan(""), 0, 0)};
  absl::StatusOr<PointCloud> cloud = PointCloud::Create(bad, {});
  ASSERT_FALSE(cloud.ok());
  EXPECT_NE(cloud.status().message().find("point 1"), std::string::npos);
  EXPECT_NE(cloud.status().message().find("FilterPoints"), std::string::npos);
  const std::vector<Vector3> good = {Vector3(0, 0, 0)};
  EXPECT_FALSE(PointCloud::Create(good, std::vector<double>{-1.0}).ok());
  EXPECT_FALSE(PointCloud::Create(good, std::vector<double>{1.0, 2.0}).ok());
  PointCloudOptions options;
  options.query_radius = 0.0;
  absl::StatusOr<PointCloud> no_radius = PointCloud::Create(good, {}, options);
  ASSERT_FALSE(no_radius.ok());
  EXPECT_NE(no_radius.status().message().find("query_radius"), std::string::npos);
  EXPECT_FALSE(CheckClearanceRequest({-1.0, kInf}).ok());
  EXPECT_FALSE(CheckClearanceRequest({0.0, 0.0}).ok());
}

// The private distance transform against the brute force minimum over occupied cells.
TEST(CellDistanceTransform, EqualsBruteForce) {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    std::uniform_int_distribution<int> size(1, 12);
    const int n[3] = {size(rng), size(rng), size(rng)};
    const int cells = n[0] * n[1] * n[2];
    std::vector<std::uint8_t> occupied(cells);
    std::bernoulli_distribution fill(trial % 4 == 0 ? 0.002 : 0.05);
    for (auto& o : occupied) o = fill(rng);
    const internal::CellDistanceTransform transform =
        internal::ComputeCellDistanceTransform(occupied, n);
    for (int k = 0; k < cells; ++k) {
      const int x = k / (n[1] * n[2]), y = (k / n[2]) % n[1], z = k % n[2];
      std::int64_t best = internal::kNoSite;
      for (int m = 0; m < cells; ++m) {
        if (!occupied[m]) continue;
        const int dx = x - m / (n[1] * n[2]), dy = y - (m / n[2]) % n[1], dz = z - m % n[2];
        best = std::min<std::int64_t>(best, dx * dx + dy * dy + dz * dz);
      }
      ASSERT_EQ(transform.d2[k], best) << "trial " << trial << " cell " << k;
      if (best < internal::kNoSite) {
        const std::int64_t s = transform.site[k];
        ASSERT_TRUE(occupied[s]);
        const int dx = x - static_cast<int>(s / (n[1] * n[2])),
                  dy = y - static_cast<int>((s / n[2]) % n[1]), dz = z - static_cast<int>(s % n[2]);
        ASSERT_EQ(dx * dx + dy * dy + dz * dz, best);
      }
    }
  }
}

}  // namespace
}  // namespace inscribe
