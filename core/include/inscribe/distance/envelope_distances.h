// Signed distances between a closed mesh's boundary and the envelope (the boundary) of a union
// of balls, sampled both ways: the two histograms of the paper's Fig. 7 (Section VI-A).
//
// Sign convention (the paper's): a distance is positive when the point of the envelope that
// gives it lies outside the polyhedron, negative when it lies inside. Internal spheres tangent
// to the boundary (S_D) therefore give values <= 0 both ways; spheres that protrude give
// positive ones.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

struct EnvelopeDistanceRequest {
  // N: points drawn uniformly by area on the mesh's boundary. The same points as
  // EvaluateSpheres' surface samples for the same seed. 0 skips this direction.
  std::int64_t boundary_samples = 100'000;
  // M: points drawn uniformly by area on the envelope of the union. 0 skips this direction.
  std::int64_t envelope_samples = 100'000;
  // Results are the same bit for bit for the same inputs and seed, on any number of threads.
  std::uint64_t seed = 1;
  // Envelope points are found by rejection (see EnvelopeDistanceResult::envelope_attempts); a
  // sample needing more candidates than this fails the call with RESOURCE_EXHAUSTED, so that a
  // set whose envelope is a vanishing part of its spheres' area (thousands of copies of one
  // ball) cannot hang. The acceptance rate is envelope area / sum of sphere areas.
  std::int64_t max_attempts_per_sample = 1'000'000;
};

// Summary of one direction's values, mesh units. All 0 when there are no samples.
struct SignedDistanceSummary {
  double mean_absolute = 0.0;  // the dashed/dotted lines of Fig. 7
  double mean = 0.0;
  double min = 0.0;
  double max = 0.0;
};

struct EnvelopeDistanceResult {
  // Boundary to envelope: per boundary point p (boundary_points, N by 3, mesh frame) the value
  // -min_i (|p - c_i| - r_i). For p outside the union this is exactly minus its distance to the
  // envelope: negative, the envelope falls short of the boundary there. For p inside the union
  // it is
  // max_i (r_i - |p - c_i|), the depth of p in its deepest ball: positive, and a lower bound of
  // p's distance to the envelope (equal to it where p lies in one ball only and that ball's
  // nearest surface point is not covered by another).
  Vertices boundary_points;
  std::vector<double> boundary_to_envelope;
  SignedDistanceSummary boundary_to_envelope_summary;

  // Envelope to boundary: per envelope point q (envelope_points, M by 3, mesh frame) the exact
  // signed distance from q to the mesh's boundary (BoundaryOracle::SignedDistance: positive
  // outside the polyhedron). envelope_sphere[k] is the sphere whose surface holds point k.
  Vertices envelope_points;
  std::vector<std::int32_t> envelope_sphere;
  std::vector<double> envelope_to_boundary;
  SignedDistanceSummary envelope_to_boundary_summary;
  // Candidates drawn on the spheres to get the M envelope points (>= M). The envelope's area is
  // estimated by envelope_area = (sum of 4 pi r_i^2) * M / envelope_attempts (mesh units
  // squared; 0 when M = 0).
  std::int64_t envelope_attempts = 0;
  double envelope_area = 0.0;

  double seconds = 0.0;  // wall time of the call
};

// Samples both directions. Boundary points: uniform by area over the triangles. Envelope
// points: a sphere is picked with probability proportional to r_i^2, a point uniform on it,
// and the point is rejected when it lies strictly inside another ball (|q - c_j| < r_j, j != i;
// of several exactly equal spheres only the first counts); the accepted points are exactly
// uniform by area on the envelope. Nearest-ball and containment queries go through a
// SphereHierarchy (bounding spheres), giving the same answers as a scan over all balls.
//
// Errors: INVALID_ARGUMENT for an empty sphere set, a sphere with a non-finite centre or radius
// or a radius <= 0 (naming its index), negative or over 100'000'000 sample counts,
// max_attempts_per_sample < 1, a mesh of no positive area when boundary_samples > 0;
// RESOURCE_EXHAUSTED as described for max_attempts_per_sample.
//
// Cost: O(n log n) to build the hierarchy, then per boundary point one nearest-ball query and
// per envelope point (1 / acceptance rate) containment queries, each about O(log n) on spread
// out balls, plus one signed-distance query on the mesh. Parallel (TBB).
absl::StatusOr<EnvelopeDistanceResult> ComputeEnvelopeDistances(
    const BoundaryOracle& oracle, const std::vector<Sphere>& spheres,
    const EnvelopeDistanceRequest& request = {});

}  // namespace inscribe
