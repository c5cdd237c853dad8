// The one containment rule of covers, shared by the certificate and the repairs that make it
// pass: a ball is convex, so it contains an axis-aligned box exactly when it contains the
// box's corner farthest from its centre.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "inscribe/geometry/mesh.h"

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

// Levels of the certificate's octree at most: 2^20 cells per side keeps every corner an exact
// double.
inline constexpr int kMaxCoverLevel = 20;

// Where the certificate's octree lies: a cube of power-of-two side a little over the box's
// largest side, its origin on the grid of the finest possible cells (so every corner
// origin + i * side / 2^level is exact), and the finest level, the first whose cells are no
// larger than resolution * scale (scale: the box's largest side).
struct OctreeFrame {
  double scale = 1.0, side = 1.0;
  Vector3 origin = Vector3::Zero();
  int finest = 0;

  double finest_side() const { return std::ldexp(side, -finest); }
};

inline OctreeFrame MakeOctreeFrame(const BoundingBox& box, double resolution) {
  OctreeFrame frame;
  frame.scale = std::max(box.extent().maxCoeff(), std::numeric_limits<double>::min());
  frame.side = std::exp2(std::ceil(std::log2(frame.scale * (1.0 + 1e-6))));
  const double unit = std::ldexp(frame.side, -kMaxCoverLevel);
  for (int k = 0; k < 3; ++k) frame.origin[k] = std::floor(box.min[k] / unit) * unit;
  // The origin moved down by less than one unit; the side covers that (side >= scale (1 +
  // 1e-6) and unit <= 2 scale 2^-20 < 1e-6 scale).
  while (frame.finest < kMaxCoverLevel &&
         std::ldexp(frame.side, -frame.finest) > resolution * frame.scale) {
    ++frame.finest;
  }
  return frame;
}

}  // namespace inscribe::internal
