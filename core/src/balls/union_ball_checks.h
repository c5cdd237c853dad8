// Private: the balls the union-of-balls computations accept (union_of_balls.cpp for the dual
// complex, union_volume.cpp for the volume over it).
#pragma once

#include <vector>

#include "absl/status/status.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe::internal {

// OK, or INVALID_ARGUMENT naming the first bad ball: CheckSphere's rule, a centre coordinate
// or radius above 1e150 (the weights r^2 and squared distances would overflow), or more than
// 2^31 - 1 balls. O(n).
absl::Status CheckUnionBalls(const std::vector<Sphere>& balls);

}  // namespace inscribe::internal
