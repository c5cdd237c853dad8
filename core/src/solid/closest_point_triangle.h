// Private: closest point on one triangle, in double precision.
#pragma once

#include "inscribe/geometry/mesh.h"

namespace inscribe::internal {

// Closest point to p on triangle (a, b, c), with barycentric weights (wa, wb, wc) summing to
// 1. Voronoi-region walk (Ericson, Real-Time Collision Detection, 5.1.5): in a vertex or edge
// region the weights outside it are exactly 0, which lets callers tell which feature (face,
// edge, vertex) is closest. Degenerate (zero-area) triangles are handled as segments.
Vector3 ClosestPointOnTriangle(const Vector3& p, const Vector3& a, const Vector3& b,
                               const Vector3& c, Vector3* barycentric);

}  // namespace inscribe::internal
