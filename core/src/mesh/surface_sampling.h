// What the sampled quality measures (EvaluateSpheres, ComputeEnvelopeDistances) share: points
// drawn uniformly by area on a mesh's boundary, reproducibly, and the check of their input
// spheres.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe::internal {

// `count` points (count by 3, mesh frame) uniformly distributed by area over the mesh's
// triangles; zero-area triangles are never picked. Point i draws from its own generator seeded
// by (seed, i), so the points do not depend on thread count or scheduling, and a prefix of a
// larger draw is the smaller draw. EvaluateSpheres and ComputeEnvelopeDistances both sample
// the boundary with it, so their values for the same seed are per point comparable. No rows
// when the mesh has no triangle of positive area. Parallel (TBB); cost O(#T + count log #T).
Vertices SampleBoundaryByArea(const Mesh& mesh, std::int64_t count, std::uint64_t seed);

}  // namespace inscribe::internal
