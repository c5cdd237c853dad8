// The float-filtered branch and bound behind SeparationDistance (separation_distance.h): the
// fast path for sets whose magnitudes let float rounding be bounded.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "inscribe/separation_distance.h"
#include "inscribe/sphere_hierarchy.h"

namespace inscribe::internal {

// b's frame seen from a's: x_a = rotation * x_b + translation (rotation as computed from the
// poses, unit to rounding).
struct RelativeFrame {
  Eigen::Matrix3d rotation;
  Vector3 translation;
};

// The pruning threshold once a pair of value d is the best found: pairs bounded at or above it
// cannot improve the answer beyond the request's tolerance, or cannot answer closer_than yes.
inline double PruneThreshold(const DistanceRequest& request, double d) {
  const double tolerance = std::max(request.abs_err, request.rel_err * std::abs(d));
  return std::min({d - tolerance, request.closer_than, request.max_distance});
}

// Whether the sphere-pair filter takes eight pairs per instruction sequence with AVX2 (the
// same float operations per lane as the SSE2 filter's four, no fused multiply-add): true when
// the CPU and the OS support it (x86-64 builds by GCC or Clang). Tests clear it to run the
// SSE2 filter; never changed while queries run.
extern bool use_avx2_filter;

// The exact answer of SeparationDistance (without witnesses) by a depth-first branch and
// bound over the hierarchies' Quads (a step bounds up to four grandchildren of one node, or
// up to 4 x 4 of both nodes when their sizes are close, four at a time in float) and
// float-filtered comparisons of the sphere pairs below small node pairs (each sphere first
// tested against the other node's sphere); every pair the filters let through is evaluated in
// double exactly as BruteForceSeparationDistance does. Returns false, leaving *out alone, when the
// sets' and the pose's magnitudes fall outside the range where the float margins are proven
// (kFloatMinExponent, kFloatMaxExponent in the .cpp): the caller then runs the double search.
// Cost: about O(log n) steps per query on separated sets; memory: per-thread scratch of
// O(b's spheres), kept between queries.
bool FloatFilteredSearch(const SphereHierarchy& a, const SphereHierarchy& b,
                         const RelativeFrame& relative, const DistanceRequest& request,
                         DistanceResult* out);

}  // namespace inscribe::internal
