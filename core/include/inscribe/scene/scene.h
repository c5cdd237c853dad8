// Scenes: many posed objects (a simulator's frame), a broad phase over their bounding spheres,
// and per frame every pair of objects closer than a threshold, with its distance and witnesses
// (a certified interval when both objects carry covers).
//
// Each object is a sphere set's hierarchy (shared, immutable; many objects may share one) at a
// world pose, with a collision group and mask: a pair is considered only when each object's
// group meets the other's mask, and it is not on the ignore list (a robot's adjacent links).
// The broad phase sweeps the objects' world boxes (each object's box in its own frame, turned
// with it), sorted along one axis and kept sorted between frames (few swaps when objects move a
// little), and keeps a pair when its world boxes, its bounding spheres and its oriented boxes
// are all within the threshold, so a frame costs about O(n + s) for n objects and s pairs
// overlapping along the sweep axis; the narrow phase then runs a pruned distance query per
// candidate (DistanceRequest::max_distance = the threshold).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"

namespace inscribe {

// Chosen by the caller, unique within a scene.
using SceneObjectId = std::uint64_t;

// Every group bit: the default mask (an object is checked against every group).
inline constexpr std::uint32_t kAllSceneGroups = 0xffffffffu;

struct SceneObject {
  SceneObjectId id = 0;
  // The spheres whose distance the scene reports (required).
  std::shared_ptr<const SphereHierarchy> spheres;
  // Optional, both or neither: the solid's internal spheres (best its cover's cores,
  // UpperBoundSpheres) and its certified cover, reaching at most cover_delta outside the solid.
  // A pair of two such objects is answered with a certified interval (CertifiedDistances).
  std::shared_ptr<const SphereHierarchy> internal, cover;
  double cover_delta = 0.0;
  RigidPose pose;
  // Pair (a, b) is considered when (a.group & b.mask) != 0 and (b.group & a.mask) != 0.
  std::uint32_t group = 1;
  std::uint32_t mask = kAllSceneGroups;

  bool certified() const { return cover != nullptr; }
};

// OK, or INVALID_ARGUMENT naming the problem: missing spheres, only one of internal and cover,
// a cover delta that is negative or not finite, a pose that is not finite or whose quaternion
// is not within 1e-3 of unit length. O(1).
absl::Status CheckSceneObject(const SceneObject& object);

struct SceneQuery {
  // Pairs closer than this are reported (mesh units; negative asks for overlaps deeper than
  // -threshold; +infinity for every pair). A certified pair is reported when its solids may be
  // closer: when its covers' distance less the margin (its lower bound before clamping at 0)
  // is below the threshold; a pair left out is certainly no closer.
  double threshold = 0.0;
  // Tolerances of the plain distances (DistanceRequest::abs_err, rel_err); certified intervals
  // are always computed exactly.
  double abs_err = 0.0;
  double rel_err = 0.0;
  // Only whether each pair is closer than the threshold (collision checking): a plain pair's
  // search stops at the first sphere pair below it (DistanceRequest::closer_than), so
  // result.distance is that pair's value, below the threshold but not always the minimum.
  // A pair reported in the scene's last frame is first tried through the sphere pair it was
  // reported with, so which sphere pair answers may depend on earlier frames. The same pairs
  // are reported; certified pairs are answered in full either way.
  bool stop_at_first = false;
  // Answer the candidates on TBB's threads when the frame is worth it (true: more than a few
  // candidates, and the scene's last frame took 100 us or more of narrow phase), or all on the
  // calling thread (false: a server answering a small frame on its own thread).
  bool parallel = true;
  // At most this many pairs are returned: the nearest ones (by distance, or by the covers'
  // distance for certified pairs), with SceneFrame::truncated set when more were close.
  std::size_t max_pairs = 100'000;
};

// OK, or INVALID_ARGUMENT naming the field: a NaN or -infinite threshold, bad tolerances,
// max_pairs of 0.
absl::Status CheckSceneQuery(const SceneQuery& query);

struct ScenePair {
  SceneObjectId a = 0, b = 0;  // a < b
  // The spheres' distance and world witnesses (DistanceResult; the covers' query for a
  // certified pair, whose witnesses are where the covers come closest).
  DistanceResult result;
  // Both objects certified: lower <= exact distance between the solids <= upper.
  bool certified = false;
  double lower = 0.0;
  double upper = std::numeric_limits<double>::infinity();
};

struct SceneFrame {
  // Sorted by (a, b).
  std::vector<ScenePair> pairs;
  // Pairs that passed the filters and whose bounding spheres are closer than the threshold
  // (the narrow phase's work), and pairs found close before max_pairs applied.
  std::int64_t candidate_pairs = 0;
  std::int64_t close_pairs = 0;
  bool truncated = false;
};

// Not thread-safe: one thread at a time may change or query a scene. The hierarchies are only
// read, so scenes on other threads may share them.
class Scene {
 public:
  Scene() = default;

  // Errors: CheckSceneObject's, ALREADY_EXISTS for an id in the scene.
  absl::Status Add(SceneObject object);
  // NOT_FOUND for an unknown id. Its ignore-list entries go with it.
  absl::Status Remove(SceneObjectId id);
  // New poses for some objects: all or nothing (the first unknown id or bad pose fails the
  // call, naming its index, and changes nothing).
  absl::Status SetPoses(const std::vector<std::pair<SceneObjectId, RigidPose>>& poses);
  absl::Status SetPose(SceneObjectId id, const RigidPose& pose);
  // Never report the pair (in either order). NOT_FOUND for an unknown id, INVALID_ARGUMENT for
  // a == b.
  absl::Status Ignore(SceneObjectId a, SceneObjectId b);

  std::size_t size() const { return objects_.size(); }
  bool contains(SceneObjectId id) const { return index_.count(id) != 0; }

  // Every considered pair closer than query.threshold. Pairs are answered in parallel (TBB)
  // when query.parallel and the frame is worth it (SceneQuery::parallel), polling `cancel` (may be
  // null): CANCELLED once it is set. Errors: CheckSceneQuery's; INVALID_ARGUMENT for a certified
  // pair whose coordinates are beyond kCertifiedDistanceMaxScale.
  absl::StatusOr<SceneFrame> ClosePairs(const SceneQuery& query,
                                        const std::atomic<bool>* cancel = nullptr);

 private:
  struct Entry {
    SceneObject object;         // pose normalised
    CertifiedObject certified;  // points into object's internal and cover when certified
    // A sphere around everything the object's queries read (spheres, internal, cover), in its
    // own frame and at its pose.
    Vector3 local_center = Vector3::Zero();
    double radius = 0.0;
    Vector3 world_center = Vector3::Zero();
    // The box around the same spheres: in the object's frame (centre, half sides), and the
    // world-axis box around it at its pose (centre, half sides |R| h). The local box at the
    // pose is an oriented box: centre box_center, axes the columns of `rotation`.
    Vector3 local_box_center = Vector3::Zero(), local_half = Vector3::Zero();
    Vector3 box_center = Vector3::Zero(), half = Vector3::Zero();
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    // |translation| + local_extent: the coordinate scale of the broad phase's rounding slack;
    // local_extent bounds |p| over the local sphere and box.
    double scale = 0.0;
    double local_extent = 0.0;
  };
  // The ignore list's key: the two ids, smaller first.
  static std::pair<SceneObjectId, SceneObjectId> PairKey(SceneObjectId a, SceneObjectId b) {
    return a < b ? std::make_pair(a, b) : std::make_pair(b, a);
  }
  // The broad phase, in two steps. PrepareSweep orders the objects along the sweep axis and
  // lays out their boxes (scratch below); SweepPairs then appends the pairs it keeps, as
  // positions in objects_.
  void PrepareSweep(double threshold);
  void SweepPairs(double threshold, std::vector<std::pair<std::uint32_t, std::uint32_t>>* out);

  std::vector<Entry> objects_;                             // dense; Remove moves the last in
  absl::flat_hash_map<SceneObjectId, std::size_t> index_;  // id -> position in objects_
  absl::flat_hash_set<std::pair<SceneObjectId, SceneObjectId>> ignored_;  // PairKey
  // objects_ positions sorted by the low end of their world boxes along sweep_axis_;
  // re-sorted from scratch after Add or Remove (order_valid_ false) or an axis change, else by
  // insertion from the last frame's order.
  std::vector<std::uint32_t> order_;
  int sweep_axis_ = 0;
  bool order_valid_ = false;
  // Sweep's scratch, kept between frames: the low ends along the sweep axis by position, and
  // in sweep order the world boxes (low ends, and high ends grown by the threshold and slack,
  // rounded outward to floats) and the bounding spheres (float centres and reaches), one
  // dense array per quantity and axis, padded by empty boxes.
  std::vector<double> lows_;
  std::vector<float> sorted_low_[3], sorted_high_[3], sorted_center_[3], sorted_rho_;
  // A frame's scratch, kept for its capacity: the sweep's survivors of a row, the candidate
  // pairs (positions in objects_), their answers, errors and ranks.
  struct FrameScratch {
    std::vector<std::uint32_t> survivors;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> candidates;
    std::vector<ScenePair> answers;
    std::vector<absl::Status> errors;
    std::vector<double> rank;
  };
  FrameScratch frame_scratch_;
  // The last frame's narrow phase on one thread (seconds; -1 before the first): whether the
  // next is worth forking.
  double last_narrow_seconds_ = -1.0;
  // The sphere pair each plain pair was last reported with (PairKey order: the smaller id's
  // sphere first). A stop_at_first query tries it before searching: objects move little
  // between frames, so a pair in contact is most often still in contact through it.
  absl::flat_hash_map<std::pair<SceneObjectId, SceneObjectId>,
                      std::pair<std::int32_t, std::int32_t>>
      last_pair_;
};

}  // namespace inscribe
