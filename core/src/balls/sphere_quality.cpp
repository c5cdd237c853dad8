// EvaluateSpheres: see sphere_quality.h.
#include "inscribe/balls/sphere_quality.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "inscribe/balls/union_of_balls.h"
#include "mesh/surface_sampling.h"

namespace inscribe {
namespace {

constexpr double kSqrt3 = 1.7320508075688772;

// Distance from x to the union of the balls (0 inside one). Brute force over the balls, with
// an early exit once x is inside one.
double DistanceToUnion(const Vector3& x, const std::vector<Sphere>& spheres) {
  double best = std::numeric_limits<double>::infinity();
  for (const Sphere& sphere : spheres) {
    const double gap = (x - sphere.center).norm() - sphere.radius;
    if (gap < best) {
      best = gap;
      if (best <= 0.0) return 0.0;
    }
  }
  return best;
}

}  // namespace

std::vector<double> SphereProtrusions(const BoundaryOracle& oracle,
                                      const std::vector<Sphere>& spheres) {
  std::vector<double> protrusion(spheres.size());
  internal::ParallelForRange(
      std::size_t{0}, spheres.size(), 64, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i != end; ++i) {
          protrusion[i] =
              std::max(0.0, spheres[i].radius + oracle.SignedDistance(spheres[i].center));
        }
      });
  return protrusion;
}

absl::Status CheckQualityOptions(const QualityOptions& options) {
  if (options.surface_samples < 0 || options.surface_samples > 100'000'000) {
    return absl::InvalidArgumentError(
        absl::StrCat("surface samples must lie in [0, 100000000], got ", options.surface_samples));
  }
  if (!std::isfinite(options.voxel_size) || options.voxel_size < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("voxel size must be finite and >= 0, got ", options.voxel_size));
  }
  return absl::OkStatus();
}

absl::StatusOr<QualityReport> EvaluateSpheres(const BoundaryOracle& oracle,
                                              const std::vector<Sphere>& spheres,
                                              const QualityOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const Mesh& mesh = oracle.mesh();
  if (absl::Status status = CheckSpheres(spheres); !status.ok()) {
    return status;
  }
  if (absl::Status status = CheckQualityOptions(options); !status.ok()) return status;
  QualityReport report;
  report.spheres = static_cast<std::int64_t>(spheres.size());
  report.bbox_diagonal = ComputeBoundingBox(mesh.vertices).diagonal();
  report.volume_mesh = SignedVolume(mesh);
  if (!(report.volume_mesh > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("mesh volume is ", report.volume_mesh,
                                                   "; a closed, outward-oriented mesh is needed"));
  }
  report.protrusion_tolerance = options.protrusion_tolerance >= 0.0 ? options.protrusion_tolerance
                                                                    : 1e-9 * report.bbox_diagonal;
  report.coverage_tolerance =
      options.coverage_tolerance >= 0.0 ? options.coverage_tolerance : 1e-3 * report.bbox_diagonal;

  absl::StatusOr<double> union_volume = UnionVolume(spheres);
  if (!union_volume.ok()) return union_volume.status();
  report.volume_union = *union_volume;

  const std::vector<double> protrusion = SphereProtrusions(oracle, spheres);
  if (!spheres.empty()) {
    double sum = 0.0;
    for (double p : protrusion) {
      sum += p;
      report.protrusion_max = std::max(report.protrusion_max, p);
      report.protruding_spheres += p > report.protrusion_tolerance;
    }
    report.protrusion_mean = sum / static_cast<double>(spheres.size());
    std::vector<double> sorted = protrusion;
    const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * sorted.size())) - 1;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(rank),
                     sorted.end());
    report.protrusion_p95 = sorted[rank];
  }
  report.nerr_is_exact = report.protruding_spheres == 0;
  report.nerr = report.nerr_is_exact
                    ? (report.volume_mesh - report.volume_union) / report.volume_mesh
                    : std::abs(report.volume_union - report.volume_mesh) / report.volume_mesh;

  // Sampled boundary measures.
  report.surface_samples = options.surface_samples;
  // The same points as ComputeEnvelopeDistances' boundary samples for the same seed.
  const Vertices samples =
      options.surface_samples > 0
          ? internal::SampleBoundaryByArea(mesh, options.surface_samples, options.seed)
          : Vertices(0, 3);
  if (samples.rows() > 0) {
    // Per-sample distances first, then serial sums: the report is the same bit for bit on
    // every run.
    std::vector<double> distances(static_cast<std::size_t>(samples.rows()));
    internal::ParallelForRange(
        std::int64_t{0}, samples.rows(), 256, [&](std::int64_t begin, std::int64_t end) {
          for (std::int64_t i = begin; i != end; ++i) {
            distances[static_cast<std::size_t>(i)] =
                spheres.empty() ? std::numeric_limits<double>::infinity()
                                : DistanceToUnion(samples.row(i).transpose(), spheres);
          }
        });
    double sum = 0.0;
    std::int64_t covered = 0;
    for (double distance : distances) {
      sum += distance;
      report.boundary_to_union_hausdorff = std::max(report.boundary_to_union_hausdorff, distance);
      covered += distance <= report.coverage_tolerance;
    }
    report.boundary_to_union_mean = sum / static_cast<double>(distances.size());
    report.coverage = static_cast<double>(covered) / static_cast<double>(distances.size());
  }

  // Fatness.
  if (!spheres.empty()) {
    report.radius_min = std::numeric_limits<double>::infinity();
    for (const Sphere& s : spheres) {
      report.radius_min = std::min(report.radius_min, s.radius);
      report.radius_max = std::max(report.radius_max, s.radius);
    }
    report.fat_up_to_voxel_size = report.radius_min / kSqrt3;
  }
  report.voxel_size = options.voxel_size;
  if (options.voxel_size > 0.0 && !spheres.empty()) {
    report.fat = options.voxel_size <= report.fat_up_to_voxel_size;
    std::int64_t large = 0;
    for (const Sphere& s : spheres) large += s.radius >= kSqrt3 * options.voxel_size;
    report.fraction_radius_over_sqrt3_sigma =
        static_cast<double>(large) / static_cast<double>(spheres.size());
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace inscribe
