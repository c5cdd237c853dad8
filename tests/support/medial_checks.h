// The guarantees every internal sphere set keeps (paper Section III), checked against the slow
// obvious distance scan.
#pragma once

#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe::testing {

// Every sphere internal (centre inside; radius = brute-force distance to the boundary, so it
// cannot stick out by more than rounding) and tangent (its contact lies on the boundary at
// distance r from the centre). Reports failures through GoogleTest.
void ExpectInternalAndTangent(const BoundaryOracle& oracle, const SphereSet& set);

}  // namespace inscribe::testing
