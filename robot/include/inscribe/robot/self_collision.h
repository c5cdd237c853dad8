// A robot's self-collision matrix: which link pairs a planner may skip, classified as MoveIt's
// setup assistant does (compute_default_collisions.cpp), with certified distance intervals.
//
// Pairs: every two links that have spheres (links without are in no pair, as MoveIt uses only
// links with collision geometry). Each pair gets the first class that applies:
//   Adjacent   the links are joined by a joint, or through a path of links without spheres
//              (MoveIt's connection graph with geometry-less links collapsed);
//   Default    colliding at the default configuration (DefaultConfiguration);
//   Always     colliding in at least always_fraction of the samples;
//   Never      colliding in none of the samples;
//   Sometimes  otherwise: the pair stays enabled.
// "Colliding" at a configuration means the written spheres are not certified apart: the lower
// bound of the pair's interval (below) is 0. So "never" says the written spheres (and, for
// certified covers, the links' solids) were apart in every sample.
//
// Per sample and pair, with d(X, Y) the signed distance between two posed sphere unions
// (min over sphere pairs of |c - c'| - r - r'), S the written spheres, I the inner spheres
// and delta the links' certified protrusions (certificate delta plus padding):
//   lower = max(0, d(S_a, S_b) - margin)
//   upper = max(lower, min(d(I_a, I_b), max(0, d(S_a, S_b)) + delta_a + delta_b) + margin)
// margin = kCertifiedDistanceMargin * scale + kCertifiedDistanceFloor (certified_distance.h),
// scale the largest |translation| + |centre| + radius of the two posed links. With certified
// covers, lower <= the links' exact distance <= upper (certified_distance.h explains why);
// links that are not certified are their spheres: delta 0 and I = S.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/urdf_spherize.h"

namespace inscribe::robot {

// Largest SelfCollisionOptions::samples.
inline constexpr std::int64_t kMaxSelfCollisionSamples = 100'000'000;

// One link's geometry in its link frame, metres.
struct LinkCollisionGeometry {
  // What a planner checks: the written spheres (for a certified cover, its spheres with the
  // padding added to their radii). Empty: the link has no geometry.
  std::vector<Sphere> spheres;
  // Set when `spheres` provably hold the link's solid and reach at most this far outside it
  // (the cover certificate's delta plus the padding); finite, >= 0.
  std::optional<double> certified_delta;
  // Optional balls inside the link's solid (CoverCores / UpperBoundSpheres of the unpadded
  // cover): tighter upper bounds. Used only with certified_delta.
  std::vector<Sphere> inner;
};

// What SpherizeRobot made for each link, as the matrix takes it: the written spheres; for a
// certified cover its delta (padding included) and its cores as `inner`. One entry per link,
// in the robot's order; skipped links and links without geometry get no spheres. O(#spheres).
std::vector<LinkCollisionGeometry> LinkCollisionGeometries(
    const std::vector<LinkSpherizeResult>& links);

enum class CollisionPairClass { kAdjacent, kDefault, kAlways, kNever, kSometimes };

// "Adjacent", "Default", "Always", "Never" (MoveIt's SRDF reasons, exactly), "Sometimes".
const char* CollisionPairClassName(CollisionPairClass type);

struct SelfCollisionOptions {
  // Random configurations (ConfigurationSampler with `seed`); MoveIt's default is 10,000.
  // 1..kMaxSelfCollisionSamples.
  std::int64_t samples = 10'000;
  std::uint64_t seed = 0;
  // A pair colliding in at least this fraction of the samples is "Always" (MoveIt's
  // min_collision_fraction, 0.95). In (0, 1].
  double always_fraction = 0.95;
  // Whether adjacent pairs are checked at the samples too. Their class does not depend on it
  // (MoveIt never checks them); false skips their work (often the most: they touch at every
  // sample), and leaves their statistics empty (LinkPairCollision::sampled).
  bool sample_adjacent = true;
  // Cancellation (CANCELLED) and progress in [0, 1], both on the calling thread between
  // blocks of samples.
  GenerationControl control;
};

// One link pair's interval at one configuration, metres.
struct LinkPairInterval {
  int link_a = -1, link_b = -1;  // link indices (Kinematics order), link_a < link_b
  double lower = 0.0, upper = 0.0;
  double sphere_distance = 0.0;  // d(S_a, S_b), signed: negative when the spheres overlap
  bool colliding() const { return !(lower > 0.0); }
};

struct LinkPairCollision {
  int link_a = -1, link_b = -1;  // link_a < link_b
  CollisionPairClass type = CollisionPairClass::kSometimes;
  // False for adjacent pairs left out (SelfCollisionOptions::sample_adjacent): colliding
  // counts 0, minima NaN.
  bool sampled = true;
  bool colliding_at_default = false;
  std::int64_t colliding_samples = 0;
  double colliding_fraction = 0.0;  // colliding_samples / samples
  // The smallest lower and upper bounds and signed sphere distance over the samples, metres.
  double min_lower = 0.0, min_upper = 0.0, min_sphere_distance = 0.0;
};

struct SelfCollisionMatrix {
  std::vector<std::string> links;  // link names, Kinematics order
  // Every pair of links with spheres, by (link_a, link_b) ascending.
  std::vector<LinkPairCollision> pairs;
  std::int64_t samples = 0;
  std::uint64_t seed = 0;
  double always_fraction = 0.0;
  // Every link with spheres has certified_delta: the bounds hold for the solids.
  bool certified = false;
  double seconds = 0.0;
};

// OK, or INVALID_ARGUMENT naming the problem: not one geometry per link, a sphere of `spheres`
// or `inner` that CheckSphere refuses (naming the link and the sphere), a certified_delta that
// is negative or not finite. O(#spheres).
absl::Status CheckLinkCollisionGeometry(const Kinematics& kinematics,
                                        const std::vector<LinkCollisionGeometry>& links);

// The interval of every pair of links with spheres at configuration q, by (link_a, link_b)
// ascending. Errors: CheckLinkCollisionGeometry's, LinkPoses'. O(#pairs * spheres^2).
absl::StatusOr<std::vector<LinkPairInterval>> LinkPairIntervals(
    const Kinematics& kinematics, const std::vector<LinkCollisionGeometry>& links,
    absl::Span<const double> q);

// The matrix over options.samples configurations (see above). Deterministic for a seed
// whatever the thread count (TBB; the per-pair statistics are counts and minima, and work that
// cannot change them is skipped: pairs whose bounding balls are farther apart than anything
// they have shown, sphere rows that cannot beat the pair's minima). Errors:
// CheckLinkCollisionGeometry's; INVALID_ARGUMENT for samples outside
// 1..kMaxSelfCollisionSamples or always_fraction outside (0, 1]; CANCELLED. Cost at most
// O(samples * (#links + sum over pairs of |S_a| |S_b| + |I_a| |I_b|)), far less for pairs that
// stay apart.
absl::StatusOr<SelfCollisionMatrix> ComputeSelfCollisionMatrix(
    const Kinematics& kinematics, const std::vector<LinkCollisionGeometry>& links,
    const SelfCollisionOptions& options = {});

// Whether a planner may skip the pair: every class but kSometimes.
inline bool CollisionDisabled(CollisionPairClass type) {
  return type != CollisionPairClass::kSometimes;
}

}  // namespace inscribe::robot
