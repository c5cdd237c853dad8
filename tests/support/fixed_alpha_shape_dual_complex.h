// A reference dual complex for tests of ComputeDualComplex (inscribe/union_of_balls.h):
// CGAL's Fixed_alpha_shape_3 at alpha = 0 over CGAL's regular triangulation, written apart
// from the library (its own duplicate removal and padding), so a fault in either is seen.
#pragma once

#include <vector>

#include "inscribe/balls/union_of_balls.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe::testing {

// The dual complex of `balls` in ComputeDualComplex's conventions (input indices, sorted
// tuples and lists; of exact duplicates the lowest index is kept), classified by
// Fixed_alpha_shape_3<Regular_triangulation_3> at alpha = 0. Centres spanning fewer than 3
// dimensions get four far zero-weight points. balls: valid (CheckSphere) and non-empty.
// Cost: several times ComputeDualComplex (a std::map of all edges, repeated circulation).
DualComplex FixedAlphaShapeDualComplex(const std::vector<Sphere>& balls);

}  // namespace inscribe::testing
