// The slow, obvious closest point on a mesh: every triangle scanned, for tests of the fast
// paths (the BVH, the oracle, generation, deformation updates).
#pragma once

#include "inscribe/geometry/mesh.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe::testing {

// The private point-triangle routine on every triangle in index order, keeping the first of
// equal squared distances (so the lowest index wins ties): what the oracle promises to equal
// bit for bit. Cost O(#T).
BoundaryPoint BruteForceClosest(const Mesh& mesh, const Vector3& p);

// BruteForceClosest(mesh, p).distance.
double BruteForceDistance(const Mesh& mesh, const Vector3& p);

}  // namespace inscribe::testing
