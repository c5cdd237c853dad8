// The random poses of the paper's Table II protocol (Section VI-D), shared by bench/paper_table2
// and bench/cover_bench so that both measure on the same draws.
#pragma once

#include <cstdint>
#include <vector>

#include "inscribe/geometry/rigid_pose.h"

namespace inscribe::bench {

// Where copy b's centre may be: a centre distance drawn uniformly from [lo, hi] bounding-box
// diagonals, in a uniformly random direction.
struct PoseSetSpec {
  const char* name;
  double lo, hi;
};
inline constexpr PoseSetSpec kPoseSets[] = {{"near", 0.4, 0.9}, {"far", 0.6, 1.5}};

// World poses of the two copies of a model centred on its bounding box (so that the
// translation is the distance between the boxes' centres).
struct PosePair {
  RigidPose a, b;
};

// `count` pose pairs: both copies randomly rotated (uniform on SO(3)), a at the origin, b at a
// centre distance of [lo, hi] * diagonal (mesh units). The same seed gives the same draws for
// every model: only the scale by its diagonal differs.
std::vector<PosePair> RandomPosePairs(int count, const PoseSetSpec& spec, double diagonal,
                                      std::uint64_t seed);

}  // namespace inscribe::bench
