#include "inscribe/balls/sphere_quality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "base/parallel.h"
#include "inscribe/medial/medial_spheres.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::Box;
using testing::LoadTestMesh;

BoundaryOracle MakeOracle(const Mesh& mesh) {
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  EXPECT_TRUE(oracle.ok()) << oracle.status();
  return *std::move(oracle);
}

bool InUnion(const Vector3& x, const std::vector<Sphere>& spheres) {
  for (const Sphere& s : spheres) {
    if ((x - s.center).squaredNorm() <= s.radius * s.radius) return true;
  }
  return false;
}

// Err = vol(U \ mesh) + vol(mesh \ U) by Monte Carlo over the bounding box: the slow, obvious
// reference for nerr. Returns {estimate, standard error}.
std::pair<double, double> MonteCarloError(const BoundaryOracle& oracle,
                                          const std::vector<Sphere>& spheres,
                                          std::int64_t samples) {
  const BoundingBox box = ComputeBoundingBox(oracle.mesh().vertices);
  const double box_volume = box.extent().prod();
  const std::int64_t hits = internal::ParallelReduce(
      std::int64_t{0}, samples, 4096, std::int64_t{0},
      [&](std::int64_t begin, std::int64_t end, std::int64_t count) {
        std::mt19937_64 random(static_cast<std::uint64_t>(begin) * 7919u + 17u);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        for (std::int64_t i = begin; i != end; ++i) {
          const Vector3 x = box.min + box.extent().cwiseProduct(
                                          Vector3(unit(random), unit(random), unit(random)));
          const bool in_mesh = oracle.Classify(x) == Side::kInside;
          count += in_mesh != InUnion(x, spheres);
        }
        return count;
      },
      [](std::int64_t a, std::int64_t b) { return a + b; });
  const double p = static_cast<double>(hits) / static_cast<double>(samples);
  return {p * box_volume, box_volume * std::sqrt(p * (1.0 - p) / static_cast<double>(samples))};
}

TEST(SphereQuality, ExactNerrAgreesWithMonteCarloOnARealMesh) {
  const Mesh mesh = LoadTestMesh("eight.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  MedialSphereOptions options;
  options.voxel_size = 0.06 * ComputeBoundingBox(mesh.vertices).diagonal();
  const absl::StatusOr<MedialSphereResult> generated = GenerateMedialSpheres(oracle, options);
  ASSERT_TRUE(generated.ok()) << generated.status();
  const absl::StatusOr<QualityReport> report =
      EvaluateSpheres(oracle, generated->set.spheres, QualityOptions{});
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_TRUE(report->nerr_is_exact);
  EXPECT_EQ(report->protruding_spheres, 0);
  EXPECT_GT(report->nerr, 0.0);
  EXPECT_LT(report->nerr, 1.0);
  const auto [err, standard_error] = MonteCarloError(oracle, generated->set.spheres, 2'000'000);
  EXPECT_NEAR(report->nerr * report->volume_mesh, err, 3.0 * standard_error + 1e-12)
      << "exact " << report->nerr * report->volume_mesh << " vs Monte Carlo " << err << " +- "
      << standard_error;
}

TEST(SphereQuality, ProtrudingSpheresGiveALabelledLowerBound) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  // Inside at depth 0.1 with radius 0.3: sticks out by 0.2.
  const std::vector<Sphere> spheres = {{Vector3(0.9, 0.5, 0.5), 0.3},
                                       {Vector3(0.3, 0.3, 0.3), 0.2}};
  QualityOptions options;
  options.surface_samples = 1000;
  const absl::StatusOr<QualityReport> report = EvaluateSpheres(oracle, spheres, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_FALSE(report->nerr_is_exact);
  EXPECT_EQ(report->protruding_spheres, 1);
  EXPECT_NEAR(report->protrusion_max, 0.2, 1e-12);
  EXPECT_NEAR(report->protrusion_mean, 0.1, 1e-12);
  EXPECT_NEAR(report->protrusion_p95, 0.2, 1e-12);
  EXPECT_NEAR(report->nerr, std::abs(report->volume_union - 1.0), 1e-12);
  // The bound really is below the Monte Carlo error.
  const auto [err, standard_error] = MonteCarloError(oracle, spheres, 1'000'000);
  EXPECT_LE(report->nerr, err + 3.0 * standard_error);
}

TEST(SphereQuality, CoverageAndHausdorffMatchAnalyticValues) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  const std::vector<Sphere> spheres = {{Vector3::Constant(0.5), 0.5}};
  QualityOptions options;
  options.surface_samples = 100'000;
  options.coverage_tolerance = 0.05;
  const absl::StatusOr<QualityReport> report = EvaluateSpheres(oracle, spheres, options);
  ASSERT_TRUE(report.ok()) << report.status();
  EXPECT_NEAR(report->volume_union, M_PI / 6.0, 1e-12);
  EXPECT_NEAR(report->nerr, 1.0 - M_PI / 6.0, 1e-12);
  EXPECT_TRUE(report->nerr_is_exact);
  // Farthest boundary points are the corners, sqrt(3)/2 from the centre.
  const double corner = std::sqrt(3.0) / 2.0 - 0.5;
  EXPECT_LE(report->boundary_to_union_hausdorff, corner + 1e-12);
  EXPECT_GT(report->boundary_to_union_hausdorff, corner - 0.01);
  // Mean over a face of sqrt(1/4 + u^2 + v^2) - 1/2 by the midpoint rule on a fine grid.
  double face_mean = 0.0;
  const int n = 1000;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double u = (i + 0.5) / n - 0.5;
      const double v = (j + 0.5) / n - 0.5;
      face_mean += std::sqrt(0.25 + u * u + v * v) - 0.5;
    }
  }
  face_mean /= n * n;
  EXPECT_NEAR(report->boundary_to_union_mean, face_mean, 1e-3);
  // Covered: within 0.05 of the ball, a disc of radius^2 0.55^2 - 0.25 on each face.
  const double covered = M_PI * (0.55 * 0.55 - 0.25);
  const double standard_error = std::sqrt(covered * (1 - covered) / 100'000.0);
  EXPECT_NEAR(report->coverage, covered, 4.0 * standard_error);
  EXPECT_EQ(report->surface_samples, 100'000);
  EXPECT_NEAR(report->fat_up_to_voxel_size, 0.5 / std::sqrt(3.0), 1e-15);
}

TEST(SphereQuality, FatnessAgainstTheVoxelSize) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  const std::vector<Sphere> spheres = {{Vector3::Constant(0.5), 0.4},
                                       {Vector3::Constant(0.3), 0.1}};
  QualityOptions options;
  options.surface_samples = 0;
  options.voxel_size = 0.05;  // sqrt(3) * 0.05 = 0.0866 <= 0.1: fat
  absl::StatusOr<QualityReport> report = EvaluateSpheres(oracle, spheres, options);
  ASSERT_TRUE(report.ok());
  EXPECT_TRUE(report->fat);
  EXPECT_DOUBLE_EQ(report->fraction_radius_over_sqrt3_sigma, 1.0);
  options.voxel_size = 0.1;  // 0.173 > 0.1: not fat
  report = EvaluateSpheres(oracle, spheres, options);
  ASSERT_TRUE(report.ok());
  EXPECT_FALSE(report->fat);
  EXPECT_DOUBLE_EQ(report->fraction_radius_over_sqrt3_sigma, 0.5);
  EXPECT_EQ(report->surface_samples, 0);
}

TEST(SphereQuality, BadSpheresAreClearErrors) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  absl::StatusOr<QualityReport> report =
      EvaluateSpheres(oracle, {{Vector3::Constant(0.5), 0.1}, {Vector3::Constant(0.5), 0.0}});
  EXPECT_EQ(report.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(report.status().message()).find("sphere 1"), std::string::npos);
  report = EvaluateSpheres(oracle, {{Vector3(std::nan(""), 0, 0), 0.1}});
  EXPECT_EQ(report.status().code(), absl::StatusCode::kInvalidArgument);
  QualityOptions options;
  options.surface_samples = -1;
  EXPECT_EQ(EvaluateSpheres(oracle, {}, options).status().code(),
            absl::StatusCode::kInvalidArgument);
  // No spheres at all: everything is error.
  options.surface_samples = 100;
  report = EvaluateSpheres(oracle, {}, options);
  ASSERT_TRUE(report.ok());
  EXPECT_DOUBLE_EQ(report->nerr, 1.0);
  EXPECT_EQ(report->coverage, 0.0);
}

}  // namespace
}  // namespace inscribe
