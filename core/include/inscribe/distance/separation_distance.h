// Separation distance between two unions of spheres, each with a rigid pose (paper Section
// VI): the fast stand-in for exact mesh-mesh distance.
#pragma once

#include <atomic>
#include <cstdint>
#include <limits>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

struct DistanceRequest {
  // Tolerances: the answer D may exceed the true distance d by at most
  // max(abs_err, rel_err * |D|), which lets the search stop sooner. Both 0 (the default): the
  // exact minimum over all sphere pairs. Mesh units and a fraction; finite and >= 0.
  double abs_err = 0.0;
  double rel_err = 0.0;
  // A yes/no question instead: are the unions closer than this (mesh units; may be negative:
  // "do they overlap by more than -closer_than")? The search stops at the first pair that
  // is, and never opens node pairs that cannot be. Unset (infinity): a distance query.
  double closer_than = std::numeric_limits<double>::infinity();
  // Only distances below this are wanted (mesh units; may be negative): pairs of volumes
  // bounded at or above it are never opened, and when no sphere pair is below it the result
  // has distance +infinity and no pair (sphere_a = sphere_b = -1). The broad phase of a scene
  // asks this for "every pair closer than the threshold, with its distance". Unset
  // (infinity): no limit. Combined with closer_than, the smaller of the two prunes.
  double max_distance = std::numeric_limits<double>::infinity();
};

struct DistanceResult {
  // min over sphere pairs of |c_a - c_b| - r_a - r_b: positive = gap between the unions,
  // negative = the deepest overlap of two spheres. With closer_than set, the value of the pair
  // found closer than it when `closer`, else closer_than itself (no claim beyond >=). With
  // max_distance set and no pair below it: +infinity.
  double distance = std::numeric_limits<double>::infinity();
  // The pair realising `distance` (-1 when none, i.e. a closer_than query answered no).
  std::int32_t sphere_a = -1, sphere_b = -1;
  // World-frame witnesses: the points of the two spheres on the line through their centres,
  // facing each other (point_a = c_a + r_a u, point_b = c_b - r_b u, u the unit vector from
  // c_a to c_b); |point_a - point_b| = |distance|.
  Vector3 point_a = Vector3::Zero(), point_b = Vector3::Zero();
  // closer_than queries: true when some pair is closer than closer_than.
  bool closer = false;
  // Work done: bounding-volume pairs tested (of which rss_tests needed the RSS distance after
  // the cheap test of the spheres around the volumes), sphere pairs compared.
  std::int64_t volume_tests = 0, rss_tests = 0, sphere_tests = 0;
};

// Branch and bound over the two hierarchies (descending the larger volume, nearer pair first,
// pruning pairs whose bounding volumes are no closer than the best pair found less the
// tolerance). INVALID_ARGUMENT for a pose that is not finite and unit (CheckPose) or bad
// tolerances. Thread-safe: the hierarchies are only read.
absl::StatusOr<DistanceResult> SeparationDistance(const SphereHierarchy& a, const RigidPose& pose_a,
                                                  const SphereHierarchy& b, const RigidPose& pose_b,
                                                  const DistanceRequest& request = {});

// One query per pose of b relative to a (a at the identity), in parallel (TBB). Results are
// in pose order; the first invalid pose fails the whole call, naming its index.
absl::StatusOr<std::vector<DistanceResult>> SeparationDistances(
    const SphereHierarchy& a, const SphereHierarchy& b, const std::vector<RigidPose>& poses_b,
    const DistanceRequest& request = {});

// One posed pair of a batch: two hierarchies (not owned; they must outlive the call) and
// their world poses.
struct PosedPair {
  const SphereHierarchy* a = nullptr;
  const SphereHierarchy* b = nullptr;
  RigidPose pose_a, pose_b;
};

// SeparationDistance for every pair (entry i answers pairs[i]; witnesses in the world frame).
// Batches of up to 64 pairs run on the calling thread; larger ones in parallel (TBB), in
// chunks of 64 pairs between which `cancel` (may be null) is polled: CANCELLED once it is set.
// Errors: INVALID_ARGUMENT for a bad request, and "pairs[i]: ..." for the first pair with a
// null hierarchy or a bad pose.
absl::StatusOr<std::vector<DistanceResult>> PairSeparationDistances(
    const std::vector<PosedPair>& pairs, const DistanceRequest& request = {},
    const std::atomic<bool>* cancel = nullptr);

// The value of one sphere pair, a[i] against b[j], posed: the expression
// BruteForceSeparationDistance evaluates for that pair, bit for bit, with its witnesses
// (`closer` stays false). For callers that remember a pair between frames. INVALID_ARGUMENT
// for an index out of range or a bad pose.
absl::StatusOr<DistanceResult> SpherePairDistance(const std::vector<Sphere>& a,
                                                  const RigidPose& pose_a,
                                                  const std::vector<Sphere>& b,
                                                  const RigidPose& pose_b, std::int32_t i,
                                                  std::int32_t j);

// The same answer by comparing every sphere pair: O(#a #b), the reference the hierarchies are
// tested against, and the `--hierarchy none` of the CLI. Tolerances are ignored (exact);
// closer_than and max_distance are honoured.
absl::StatusOr<DistanceResult> BruteForceSeparationDistance(const std::vector<Sphere>& a,
                                                            const RigidPose& pose_a,
                                                            const std::vector<Sphere>& b,
                                                            const RigidPose& pose_b,
                                                            const DistanceRequest& request = {});

}  // namespace inscribe
