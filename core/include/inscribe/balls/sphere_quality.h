// How well a set of spheres approximates a closed mesh: exact volumetric error (paper Section
// IV, Lemma 1), protrusion, boundary coverage and distance, (sigma, theta)-fatness (Section
// VI-B). Works for any sphere set, ours or another tool's, so they compare on one footing.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

struct QualityOptions {
  // Points drawn uniformly (by area) on the boundary for coverage and boundary-to-union
  // distance. Deterministic for a given seed. 0 skips the sampled measures.
  std::int64_t surface_samples = 100'000;
  std::uint64_t seed = 1;
  // A boundary sample counts as covered when it lies within this distance of the union.
  // Mesh units; < 0 means 1e-3 of the bounding-box diagonal.
  double coverage_tolerance = -1.0;
  // A sphere counts as protruding when it reaches further than this outside the mesh. Mesh
  // units; < 0 means 1e-9 of the bounding-box diagonal (rounding of exact-distance radii).
  double protrusion_tolerance = -1.0;
  // sigma the set was generated with, for the fatness test; 0 when unknown (another tool's
  // set): the report then gives the largest sigma for which the set is fat.
  double voxel_size = 0.0;
};

struct QualityReport {
  std::int64_t spheres = 0;
  double volume_mesh = 0.0;   // divergence theorem, mesh units cubed
  double volume_union = 0.0;  // exact union-of-balls volume (power diagram; not sampled)
  // Err / vol(mesh). When no sphere protrudes (within protrusion_tolerance) this is exact:
  // Err = vol(mesh) - vol(union) (Lemma 1). Otherwise it is Lemma 1's lower bound
  // |vol(union) - vol(mesh)| / vol(mesh), and nerr_is_exact is false.
  double nerr = 0.0;
  bool nerr_is_exact = false;

  // Per sphere, r + signed distance of the centre (negative inside), clipped at 0: how far the
  // ball reaches outside the mesh (an upper bound, exact unless the outside near the contact is
  // thinner than the protrusion). Mesh units, over all spheres.
  double protrusion_max = 0.0;
  double protrusion_mean = 0.0;
  double protrusion_p95 = 0.0;
  std::int64_t protruding_spheres = 0;
  double protrusion_tolerance = 0.0;
  double bbox_diagonal = 0.0;  // to read the lengths above relative to the mesh size

  // Sampled on the boundary (surface_samples points): distance from each sample to the union
  // (0 when inside a ball; equal to the distance to the union's envelope for samples outside
  // it). Hausdorff is the maximum over samples, a one-sided Hausdorff distance from the
  // boundary to the union, sampled.
  std::int64_t surface_samples = 0;
  double coverage = 0.0;  // fraction of samples within coverage_tolerance of the union
  double coverage_tolerance = 0.0;
  double boundary_to_union_mean = 0.0;
  double boundary_to_union_hausdorff = 0.0;

  // (sigma, theta)-fatness, Section VI-B: the result is fat for voxel size sigma when
  // sigma <= r_min / sqrt(3), so spheres in adjacent voxels always touch (Lemma 3).
  double radius_min = 0.0;
  double radius_max = 0.0;
  double fat_up_to_voxel_size = 0.0;  // r_min / sqrt(3)
  double voxel_size = 0.0;            // as given in the options (0 = unknown)
  bool fat = false;                   // voxel_size > 0 and voxel_size <= fat_up_to_voxel_size
  double fraction_radius_over_sqrt3_sigma = 0.0;  // spheres with r >= sqrt(3) sigma (sigma > 0)

  double seconds = 0.0;
};

// How far each sphere reaches outside the solid, in order: max(0, r + signed distance of its
// centre), mesh units (what QualityReport's protrusion figures summarise). Parallel (TBB);
// one closest-point query per sphere.
std::vector<double> SphereProtrusions(const BoundaryOracle& oracle,
                                      const std::vector<Sphere>& spheres);

// OK, or INVALID_ARGUMENT for surface samples outside [0, 1e8] or a negative or non-finite
// voxel size. O(1).
absl::Status CheckQualityOptions(const QualityOptions& options);

// Errors: INVALID_ARGUMENT for a sphere with non-finite centre or radius <= 0 (naming its
// index), bad options, a mesh with no positive volume; INTERNAL from the union volume.
// Cost: union volume O(n log n); protrusion n queries; sampling O(samples * n) (parallel).
absl::StatusOr<QualityReport> EvaluateSpheres(const BoundaryOracle& oracle,
                                              const std::vector<Sphere>& spheres,
                                              const QualityOptions& options = {});

}  // namespace inscribe
