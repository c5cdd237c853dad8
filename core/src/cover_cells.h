// The one containment rule of covers, shared by the certificate and the repairs that make it
// pass: a ball is convex, so it contains an axis-aligned box exactly when it contains the
// box's corner farthest from its centre.
#pragma once

#include <algorithm>
#include <cmath>

#include "inscribe/mesh.h"

namespace inscribe::internal {

// Squared distance from `centre` to the farthest corner of the box [lo, hi].
inline double FarthestCornerSquared(const Vector3& centre, const Vector3& lo, const Vector3& hi) {
  double far2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double reach = std::max(std::abs(centre[k] - lo[k]), std::abs(centre[k] - hi[k]));
    far2 += reach * reach;
  }
  return far2;
}

}  // namespace inscribe::internal
