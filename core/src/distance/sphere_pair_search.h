// The float-filtered branch and bound behind SeparationDistance (separation_distance.h): the
// fast path for sets whose magnitudes let float rounding be bounded.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"

namespace inscribe::internal {

// b's frame seen from a's: x_a = rotation * x_b + translation (rotation as computed from the
// poses, unit to rounding).
struct RelativeFrame {
  Eigen::Matrix3d rotation;
  Vector3 translation;
};

// r p + t, each coordinate summed as (r0 p0 + r1 p1) + r2 p2, then t. Scalar code, always
// inlined: Eigen's 3x3 product was a call where a search moves a centre per step.
inline Vector3 RotateAndShift(const Eigen::Matrix3d& r, const Vector3& p, const Vector3& t) {
  return Vector3(r(0, 0) * p.x() + r(0, 1) * p.y() + r(0, 2) * p.z() + t.x(),
                 r(1, 0) * p.x() + r(1, 1) * p.y() + r(1, 2) * p.z() + t.y(),
                 r(2, 0) * p.x() + r(2, 1) * p.y() + r(2, 2) * p.z() + t.z());
}

// p, a point of b's frame, in a's frame.
inline Vector3 MoveToA(const RelativeFrame& f, const Vector3& p) {
  return RotateAndShift(f.rotation, p, f.translation);
}

// A sphere pair's value: centre distance less both radii, b's centre already in a's frame
// (MoveToA). Every exact path evaluates a pair here (BruteForceSeparationDistance, both
// searches, SpherePairDistance), so their answers agree to the bit.
inline double SphereGap(const Vector3& center_a, double radius_a, const Vector3& moved_center_b,
                        double radius_b) {
  return (center_a - moved_center_b).norm() - radius_a - radius_b;
}

// The pruning threshold once a pair of value d is the best found: pairs bounded at or above it
// cannot improve the answer beyond the request's tolerance, or cannot answer closer_than yes.
inline double PruneThreshold(const DistanceRequest& request, double d) {
  const double tolerance = std::max(request.abs_err, request.rel_err * std::abs(d));
  return std::min({d - tolerance, request.closer_than, request.max_distance});
}

// Float filters with an AVX2 variant (functions built with target("avx2"), chosen at run
// time): x86-64 builds by GCC or Clang.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define INSCRIBE_AVX2_FILTER 1
#endif

// SeparationDistance without its checks, for a caller that checked the poses (CheckPose) and
// the request once: Scene's narrow phase, the batch entry points.
DistanceResult CheckedSeparationDistance(const SphereHierarchy& a, const RigidPose& pose_a,
                                         const SphereHierarchy& b, const RigidPose& pose_b,
                                         const DistanceRequest& request);

// SpherePairDistance without its checks: i and j within the sets, poses checked.
DistanceResult CheckedSpherePairDistance(const std::vector<Sphere>& a, const RigidPose& pose_a,
                                         const std::vector<Sphere>& b, const RigidPose& pose_b,
                                         std::int32_t i, std::int32_t j);

// Whether the float filters (the search's sphere pairs, the scene's sweep) take eight lanes per
// instruction sequence with AVX2 (the same float operations per lane as the SSE2 variants'
// four, no fused multiply-add): true when the CPU and the OS support it. Tests clear it to run
// the SSE2 variants; never changed while queries run.
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
