// Conservative dilation (paper Section VI-A): internal spheres S_D grown into S_D+ so that their
// envelope covers more of the boundary. The corners of the union's envelope (v-points, where
// three spheres meet) and the circles where two spheres meet with no third cutting them are the
// places where the envelope of internal spheres falls furthest short of the boundary; each
// sphere meeting there grows just enough to reach the boundary point nearest to such a point.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

struct DilationOptions {
  // Also use the singleton edges of the dual complex (two spheres meeting in a circle that no
  // third sphere cuts): two opposite points on that circle, each treated like a v-point of the
  // two spheres. Without them, pairs of spheres with no v-point never grow.
  bool singleton_edges = true;
  // Chooses the angle of each singleton edge's pair of circle points: a hash of (seed, i, j),
  // so the points are the same for the same seed and edge whatever the thread count.
  std::uint64_t seed = 1;
  // How far towards the paper's radius each sphere grows, in [0, 1]: r' = r + growth (R - r)
  // with R the paper's max over the sphere's envelope points of |c - m|. A tangent sphere that
  // grows by g sticks out by g at its own contact point while it closes a gap of about g at the
  // envelope point, so the full growth (1, the paper) trades gaps for protrusions one for one;
  // less keeps part of each gap and part of the protrusion. bench/run-table2 measures both.
  double growth = 1.0;
};

// A point where two or three spheres of a set meet on the envelope of their union.
struct EnvelopePoint {
  Vector3 point = Vector3::Zero();  // mesh frame
  // Indices of the spheres meeting there, ascending; spheres[2] = -1 for a circle point (two
  // spheres). The point lies on each of them: | |point - c| - r | <= 1e-9 r.
  std::array<std::int32_t, 3> spheres = {-1, -1, -1};
};

// The envelope's corners and singleton-edge circle points of a sphere set (Section VI-A).
struct EnvelopePoints {
  // For each triangle (i, j, k) of the dual complex (ComputeDualComplex), in the complex's
  // order, its (up to) two triple points, the one on the side of (c_j - c_i) x (c_k - c_i)
  // first; kept unless strictly inside another sphere of the set (|x - c| < r (1 - 1e-12)).
  // Three spheres that only touch (the two points' squared half-distance rounds to <= 0)
  // give one point.
  std::vector<EnvelopePoint> v_points;
  // For each edge (i, j) of the dual complex that is in no triangle, in the complex's order:
  // two opposite points of the circle where spheres i and j meet (angle from the seed), each
  // kept unless strictly inside another sphere. Empty when options.singleton_edges is false.
  std::vector<EnvelopePoint> circle_points;
  std::int64_t complex_triangles = 0;  // triangles of the dual complex
  std::int64_t singleton_edges = 0;    // its edges in no triangle
  // Triangles and singleton edges whose points could not be computed to within 1e-9 r of
  // their spheres and were skipped: centres collinear or spheres not meeting once rounded,
  // or coordinates so large against r that a double cannot place the point. Expected 0 for
  // input that is not degenerate to within about 1e-7 relative.
  std::int64_t degenerate = 0;
};

// V-points and singleton-edge circle points of `spheres` (centres in mesh frame, radii in mesh
// units). Deterministic: the same input and options give the same points in the same order.
//
// Errors: INVALID_ARGUMENT naming the first sphere with a non-finite centre or radius, or a
// radius <= 0; ComputeDualComplex's errors. Empty input gives no points.
// Cost: ComputeDualComplex (O(n log n) expected), plus per triangle and singleton edge a
// closed-form solve and a point-in-balls query on a flat bounding-box tree over the spheres
// (O(log n) for well-spread spheres); parallel (TBB).
absl::StatusOr<EnvelopePoints> ComputeEnvelopePoints(const std::vector<Sphere>& spheres,
                                                     const DilationOptions& options = {});

// OK, or INVALID_ARGUMENT for a growth outside [0, 1]. O(1).
absl::Status CheckDilationOptions(const DilationOptions& options);

struct DilationResult {
  // The same spheres in the same order with the same centres; radii never smaller. Contacts
  // are dropped: a grown sphere no longer touches the boundary at one point.
  SphereSet set;
  std::int64_t v_points = 0;     // EnvelopePoints::v_points.size()
  std::int64_t edge_points = 0;  // EnvelopePoints::circle_points.size()
  std::int64_t degenerate = 0;   // EnvelopePoints::degenerate
  std::int64_t grown = 0;        // spheres whose radius increased
  double max_growth = 0.0;       // largest radius increase, mesh units
  double seconds = 0.0;          // wall time, dual complex included
};

// S_D+ from S_D: for every point x of ComputeEnvelopePoints(spheres, options), m = the
// boundary point nearest to x (oracle.ClosestPoint), and each sphere s meeting at x grows to
// r_s = max(r_s, |c_s - m|). Every radius is computed from the original spheres, so the result
// does not depend on the order of the points or of the threads; it is the same bit for bit for
// the same input.
//
// Meant for internal spheres tangent to the boundary (GenerateMedialSpheres' output); any valid
// set is accepted. The grown spheres protrude from the solid: Lemma 1 then gives only a lower
// bound on the volumetric error (EvaluateSpheres reports nerr_is_exact = false).
//
// Errors: as ComputeEnvelopePoints. Empty input gives an empty set.
// Cost: ComputeEnvelopePoints plus one closest-point query per sphere (bounds for the next
// step) and one bounded closest-point query per envelope point; parallel (TBB).
absl::StatusOr<DilationResult> DilateSpheres(const BoundaryOracle& oracle, const SphereSet& spheres,
                                             const DilationOptions& options = {});

}  // namespace inscribe
