// Private: the dual complex by CGAL's Fixed_alpha_shape_3, the reference that
// ComputeDualComplex's own alpha = 0 classification is tested against.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/sphere.h"
#include "inscribe/union_of_balls.h"

namespace inscribe::internal {

// ComputeDualComplex(balls), classified by Fixed_alpha_shape_3<Regular_triangulation_3> at
// alpha = 0 instead of by ComputeDualComplex's direct pass over the same triangulation. Same
// errors and output conventions. Cost: several times ComputeDualComplex (a std::map of edges
// and repeated circulation around every edge).
absl::StatusOr<DualComplex> FixedAlphaShapeDualComplex(const std::vector<Sphere>& balls);

}  // namespace inscribe::internal
