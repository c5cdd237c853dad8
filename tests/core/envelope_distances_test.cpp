#include "inscribe/distance/envelope_distances.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <limits>
#include <vector>

#include "inscribe/balls/sphere_quality.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/sphere_dilation.h"
#include "support/sphere_sets.h"
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

EnvelopeDistanceResult Compute(const BoundaryOracle& oracle, const std::vector<Sphere>& spheres,
                               std::int64_t boundary, std::int64_t envelope,
                               std::uint64_t seed = 1) {
  EnvelopeDistanceRequest request;
  request.boundary_samples = boundary;
  request.envelope_samples = envelope;
  request.seed = seed;
  absl::StatusOr<EnvelopeDistanceResult> result =
      ComputeEnvelopeDistances(oracle, spheres, request);
  EXPECT_TRUE(result.ok()) << result.status();
  return result.ok() ? *std::move(result) : EnvelopeDistanceResult{};
}

// The reference for boundary to envelope: -min_i (|p - c_i| - r_i) over every ball.
double BruteBoundaryToEnvelope(const Vector3& p, const std::vector<Sphere>& spheres) {
  double best = std::numeric_limits<double>::infinity();
  for (const Sphere& s : spheres) best = std::min(best, (p - s.center).norm() - s.radius);
  return -best;
}

// The reference for "q on sphere `own` is on the envelope": inside no other ball, and the
// first of equal spheres.
bool BruteOnEnvelope(const Vector3& q, std::int32_t own, const std::vector<Sphere>& spheres) {
  const Sphere& o = spheres[static_cast<std::size_t>(own)];
  for (std::size_t j = 0; j < spheres.size(); ++j) {
    const Sphere& s = spheres[j];
    if (static_cast<std::int32_t>(j) == own) continue;
    if (s.center == o.center && s.radius == o.radius) {
      if (static_cast<std::int32_t>(j) < own) return false;
      continue;
    }
    if ((q - s.center).squaredNorm() < s.radius * s.radius) return false;
  }
  return true;
}

// Every value checked against the brute-force scans, bit for bit.
void ExpectMatchesBruteForce(const BoundaryOracle& oracle, const std::vector<Sphere>& spheres,
                             const EnvelopeDistanceResult& r) {
  ASSERT_EQ(r.boundary_points.rows(), static_cast<std::int64_t>(r.boundary_to_envelope.size()));
  for (std::int64_t i = 0; i < r.boundary_points.rows(); ++i) {
    const Vector3 p = r.boundary_points.row(i).transpose();
    ASSERT_EQ(r.boundary_to_envelope[static_cast<std::size_t>(i)],
              BruteBoundaryToEnvelope(p, spheres))
        << "boundary sample " << i;
  }
  ASSERT_EQ(r.envelope_points.rows(), static_cast<std::int64_t>(r.envelope_to_boundary.size()));
  ASSERT_EQ(r.envelope_sphere.size(), r.envelope_to_boundary.size());
  for (std::int64_t k = 0; k < r.envelope_points.rows(); ++k) {
    const Vector3 q = r.envelope_points.row(k).transpose();
    const std::int32_t own = r.envelope_sphere[static_cast<std::size_t>(k)];
    ASSERT_GE(own, 0);
    const Sphere& s = spheres[static_cast<std::size_t>(own)];
    ASSERT_NEAR((q - s.center).norm(), s.radius, 1e-12 * (1.0 + s.radius)) << "sample " << k;
    ASSERT_TRUE(BruteOnEnvelope(q, own, spheres)) << "envelope sample " << k;
    ASSERT_EQ(r.envelope_to_boundary[static_cast<std::size_t>(k)], oracle.SignedDistance(q))
        << "envelope sample " << k;
  }
}

TEST(EnvelopeDistances, MatchBruteForceOnRandomSphereSets) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    // Sheet-like medial layouts and scattered balls, some far from and some around the box.
    for (const std::vector<Sphere>& spheres :
         {testing::RandomSpheres(300, seed), testing::RandomBalls(200, 1.4, 0.01, 0.3, seed),
          testing::RandomBalls(5, 1.0, 0.05, 0.2, seed)}) {
      const EnvelopeDistanceResult r = Compute(oracle, spheres, 3000, 3000, seed);
      ExpectMatchesBruteForce(oracle, spheres, r);
      EXPECT_GE(r.envelope_attempts, 3000);
    }
  }
}

TEST(EnvelopeDistances, MatchBruteForceOnARealMesh) {
  const Mesh mesh = LoadTestMesh("bunny00.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  MedialSphereOptions options;
  options.voxel_size = ComputeBoundingBox(mesh.vertices).diagonal() / 25.0;
  absl::StatusOr<MedialSphereResult> medial = GenerateMedialSpheres(oracle, options);
  ASSERT_TRUE(medial.ok()) << medial.status();
  const std::vector<Sphere>& spheres = medial->set.spheres;
  ASSERT_GT(spheres.size(), 100u);
  const EnvelopeDistanceResult r = Compute(oracle, spheres, 20'000, 20'000);
  ExpectMatchesBruteForce(oracle, spheres, r);

  // Internal spheres tangent to the boundary (S_D): the envelope lies inside or on the
  // boundary and the boundary outside or on every ball, so both directions are <= 0 up to the
  // rounding of exact-distance radii (the paper, end of Section VI-A).
  const double diagonal = ComputeBoundingBox(mesh.vertices).diagonal();
  EXPECT_LE(r.boundary_to_envelope_summary.max, 1e-9 * diagonal);
  EXPECT_LE(r.envelope_to_boundary_summary.max, 1e-9 * diagonal);
  EXPECT_LT(r.boundary_to_envelope_summary.min, 0.0);
  EXPECT_LT(r.envelope_to_boundary_summary.min, 0.0);

  // The boundary samples are EvaluateSpheres' ones: its distance to the union is max(0, -v).
  QualityOptions quality;
  quality.surface_samples = 20'000;
  absl::StatusOr<QualityReport> report = EvaluateSpheres(oracle, spheres, quality);
  ASSERT_TRUE(report.ok()) << report.status();
  double sum = 0.0;
  for (double v : r.boundary_to_envelope) sum += std::max(0.0, -v);
  EXPECT_NEAR(sum / 20'000.0, report->boundary_to_union_mean, 1e-12 * diagonal);

  // Grown spheres (S_D+, the paper's full growth) reach outside: positive values appear both
  // ways, and less of the boundary is left outside the union (the negative part shrinks).
  // They trade gaps for protrusions one for one, so the mean |d| itself does not shrink; with
  // half the growth (sphere_dilation.h) it does, both ways.
  const auto uncovered_mean = [](const EnvelopeDistanceResult& e) {
    double total = 0.0;
    for (double v : e.boundary_to_envelope) total += std::max(0.0, -v);
    return total / static_cast<double>(e.boundary_to_envelope.size());
  };
  absl::StatusOr<DilationResult> grown = DilateSpheres(oracle, medial->set);
  ASSERT_TRUE(grown.ok()) << grown.status();
  const EnvelopeDistanceResult g = Compute(oracle, grown->set.spheres, 20'000, 20'000);
  ExpectMatchesBruteForce(oracle, grown->set.spheres, g);
  EXPECT_GT(g.boundary_to_envelope_summary.max, 0.0);
  EXPECT_GT(g.envelope_to_boundary_summary.max, 0.0);
  EXPECT_LT(uncovered_mean(g), 0.5 * uncovered_mean(r));

  DilationOptions half;
  half.growth = 0.5;
  absl::StatusOr<DilationResult> half_grown = DilateSpheres(oracle, medial->set, half);
  ASSERT_TRUE(half_grown.ok()) << half_grown.status();
  const EnvelopeDistanceResult h = Compute(oracle, half_grown->set.spheres, 20'000, 20'000);
  EXPECT_LT(h.boundary_to_envelope_summary.mean_absolute,
            r.boundary_to_envelope_summary.mean_absolute);
  EXPECT_LT(h.envelope_to_boundary_summary.mean_absolute,
            r.envelope_to_boundary_summary.mean_absolute);
}

TEST(EnvelopeDistances, BallInscribedInACubeHasClosedFormValues) {
  // The unit ball in the cube [-1, 1]^3. A boundary point p is outside the ball (or on it):
  // value 1 - |p|. An envelope point q on the sphere has signed distance max|q_k| - 1 to the
  // cube.
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Constant(-1.0), Vector3::Ones()));
  const std::vector<Sphere> ball = {{Vector3::Zero(), 1.0}};
  const EnvelopeDistanceResult r = Compute(oracle, ball, 20'000, 20'000);
  for (std::int64_t i = 0; i < r.boundary_points.rows(); ++i) {
    const Vector3 p = r.boundary_points.row(i).transpose();
    ASSERT_NEAR(r.boundary_to_envelope[static_cast<std::size_t>(i)], 1.0 - p.norm(), 1e-15);
    ASSERT_LE(r.boundary_to_envelope[static_cast<std::size_t>(i)], 1e-15);
  }
  for (std::int64_t k = 0; k < r.envelope_points.rows(); ++k) {
    const Vector3 q = r.envelope_points.row(k).transpose();
    ASSERT_NEAR(r.envelope_to_boundary[static_cast<std::size_t>(k)], q.cwiseAbs().maxCoeff() - 1.0,
                1e-14);
  }
  // One ball: every candidate is on the envelope, whose area is the sphere's.
  EXPECT_EQ(r.envelope_attempts, 20'000);
  EXPECT_NEAR(r.envelope_area, 4.0 * M_PI, 1e-12);
  // Uniform on the sphere: E[|z|] = 1/2, and boundary points uniform over the six faces: the
  // mean of 1 - |p| over a face [-1, 1]^2 at distance 1 is 1 - 1.28079 (numerically integrated).
  double mean_abs_z = 0.0;
  for (std::int64_t k = 0; k < r.envelope_points.rows(); ++k) {
    mean_abs_z += std::abs(r.envelope_points(k, 2));
  }
  EXPECT_NEAR(mean_abs_z / 20'000.0, 0.5, 0.01);
  EXPECT_NEAR(r.boundary_to_envelope_summary.mean, 1.0 - 1.28079, 0.005);
  EXPECT_GT(r.boundary_to_envelope_summary.min, 1.0 - std::sqrt(3.0));
  EXPECT_LT(r.envelope_to_boundary_summary.max, 0.0);
  EXPECT_GE(r.envelope_to_boundary_summary.min, 1.0 / std::sqrt(3.0) - 1.0 - 1e-15);
}

TEST(EnvelopeDistances, EnvelopeSamplesAreUniformByArea) {
  // Balls of radius 1 and 1/2, centres 1 apart: the planes of their intersection circle cut
  // off caps of area 2 pi * 1 * 0.125 from the big sphere and 2 pi * 0.5 * 0.375 from the
  // small one, leaving 3.75 pi and 0.625 pi on the envelope: 1/7 of it on the small sphere.
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Constant(-2.0), Vector3::Constant(2.0)));
  const std::vector<Sphere> spheres = {{Vector3::Zero(), 1.0}, {Vector3(1.0, 0.0, 0.0), 0.5}};
  const EnvelopeDistanceResult r = Compute(oracle, spheres, 0, 200'000);
  std::int64_t on_small = 0;
  for (std::int32_t own : r.envelope_sphere) on_small += own == 1;
  // Standard error sqrt(p (1 - p) / M) = 0.0008.
  EXPECT_NEAR(static_cast<double>(on_small) / 200'000.0, 1.0 / 7.0, 0.004);
  EXPECT_NEAR(r.envelope_area, 4.375 * M_PI, 0.01 * 4.375 * M_PI);
  EXPECT_TRUE(r.boundary_to_envelope.empty());
  EXPECT_EQ(r.boundary_points.rows(), 0);
}

TEST(EnvelopeDistances, EqualSpheresCountOnce) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Constant(-2.0), Vector3::Constant(2.0)));
  const Sphere ball{Vector3(0.1, 0.2, 0.3), 0.7};
  const EnvelopeDistanceResult r = Compute(oracle, {ball, ball, ball}, 100, 10'000);
  for (std::int32_t own : r.envelope_sphere) ASSERT_EQ(own, 0);
  EXPECT_NEAR(r.envelope_area, 4.0 * M_PI * 0.49, 0.03 * 4.0 * M_PI * 0.49);
}

TEST(EnvelopeDistances, DeterministicForASeedOnAnyNumberOfThreads) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  const std::vector<Sphere> spheres = testing::RandomSpheres(500, 7);
  const EnvelopeDistanceResult a = Compute(oracle, spheres, 5000, 5000, 42);
  EnvelopeDistanceResult b;
  tbb::task_arena one_thread(1);
  one_thread.execute([&] { b = Compute(oracle, spheres, 5000, 5000, 42); });
  EXPECT_EQ(a.boundary_to_envelope, b.boundary_to_envelope);
  EXPECT_EQ(a.envelope_to_boundary, b.envelope_to_boundary);
  EXPECT_EQ(a.envelope_sphere, b.envelope_sphere);
  EXPECT_EQ(a.envelope_attempts, b.envelope_attempts);
  EXPECT_EQ(a.envelope_to_boundary_summary.mean_absolute,
            b.envelope_to_boundary_summary.mean_absolute);
  const EnvelopeDistanceResult c = Compute(oracle, spheres, 5000, 5000, 43);
  EXPECT_NE(a.boundary_to_envelope, c.boundary_to_envelope);
  EXPECT_NE(a.envelope_to_boundary, c.envelope_to_boundary);
}

TEST(EnvelopeDistances, BadInputsAreClearErrors) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  const std::vector<Sphere> one = {{Vector3::Constant(0.5), 0.2}};
  absl::StatusOr<EnvelopeDistanceResult> r = ComputeEnvelopeDistances(oracle, {});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("no spheres"), std::string::npos) << r.status();

  r = ComputeEnvelopeDistances(oracle, {one[0], {Vector3::Zero(), -1.0}});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("sphere 1"), std::string::npos) << r.status();

  r = ComputeEnvelopeDistances(oracle, {{Vector3(NAN, 0, 0), 1.0}});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("sphere 0"), std::string::npos) << r.status();

  EnvelopeDistanceRequest request;
  request.envelope_samples = -1;
  r = ComputeEnvelopeDistances(oracle, one, request);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("envelope samples"), std::string::npos) << r.status();

  request = {};
  request.max_attempts_per_sample = 0;
  r = ComputeEnvelopeDistances(oracle, one, request);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);

  // 2000 copies of one ball: only 1 candidate in 2000 is accepted.
  request = {};
  request.envelope_samples = 1000;
  request.max_attempts_per_sample = 10;
  r = ComputeEnvelopeDistances(oracle, std::vector<Sphere>(2000, one[0]), request);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kResourceExhausted) << r.status();

  // No samples asked: empty results, zero summaries.
  request = {};
  request.boundary_samples = 0;
  request.envelope_samples = 0;
  r = ComputeEnvelopeDistances(oracle, one, request);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_TRUE(r->boundary_to_envelope.empty());
  EXPECT_TRUE(r->envelope_to_boundary.empty());
  EXPECT_EQ(r->envelope_to_boundary_summary.max, 0.0);
  EXPECT_EQ(r->envelope_area, 0.0);
}

}  // namespace
}  // namespace inscribe
