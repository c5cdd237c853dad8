// Bounding-volume hierarchies over sphere sets (paper Section VI-C), for fast separation
// distance between unions of spheres (separation_distance.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/distance/rss.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

enum class HierarchyVolume {
  // Rectangle swept spheres fitted to the spheres below each node (FitRss): tight around the
  // flat sheets of medial spheres, the paper's faster choice.
  kRss,
  // The smallest sphere enclosing the spheres below each node (CGAL Min_sphere_of_spheres_d),
  // padded outward by a few ulps.
  kSphere,
};

// "rss" or "sphere".
const char* HierarchyVolumeName(HierarchyVolume volume);

// A reference to a node or to a leaf: >= 0 an internal node, < 0 the leaf holding sphere
// (-1 - ref). Leaves hold one sphere each, which bounds itself exactly.
using HierarchyRef = std::int32_t;
inline bool IsLeaf(HierarchyRef ref) { return ref < 0; }
inline std::int32_t LeafSphere(HierarchyRef ref) { return -1 - ref; }

// A binary hierarchy built top down: each internal node splits its spheres, sorted along
// their principal axis (the least-squares line fit of the centres) or a coordinate axis, where
// the children's sizes times their squared extents (half the diagonal of the box around their
// spheres) sum to the least, with at least an eighth of the spheres on each side; coincident
// centres are split at the median. Flat arrays linked
// by index: n spheres give n - 1 internal nodes (none for one sphere), each holding its two
// children and one bounding volume of the chosen kind. Immutable once built; cheap to move,
// copyable; safe to query from many threads at once.
class SphereHierarchy {
 public:
  // Errors: INVALID_ARGUMENT for an empty set, a non-finite centre or radius, a radius <= 0,
  // or more than 2^30 spheres. Cost O(n log n) on balanced splits.
  static absl::StatusOr<SphereHierarchy> Build(std::vector<Sphere> spheres, HierarchyVolume volume);

  HierarchyVolume volume() const { return volume_; }
  const std::vector<Sphere>& spheres() const { return spheres_; }
  std::size_t num_nodes() const { return left_.size(); }
  HierarchyRef root() const { return root_; }
  HierarchyRef left(std::int32_t node) const { return left_[static_cast<std::size_t>(node)]; }
  HierarchyRef right(std::int32_t node) const { return right_[static_cast<std::size_t>(node)]; }
  // The node's bounding volume; only the one of volume()'s kind is stored.
  const Rss& rss(std::int32_t node) const { return rss_[static_cast<std::size_t>(node)]; }
  const Sphere& bounding_sphere(std::int32_t node) const {
    return bounding_spheres_[static_cast<std::size_t>(node)];
  }
  // A sphere around the node's volume: the volume itself for kSphere, the sphere around the
  // RSS (centred on its rectangle, radius = half its diagonal plus its radius) for kRss. The
  // double-precision search's cheap first test; derived, not serialised.
  const Sphere& outer_sphere(std::int32_t node) const {
    return outer_spheres_[static_cast<std::size_t>(node)];
  }
  // The spheres below a reference, as a range of leaf_order(): [first, first + count).
  // Derived from the tree (depth-first, left first), not serialised.
  std::int32_t first(HierarchyRef ref) const {
    return IsLeaf(ref) ? leaf_position_[static_cast<std::size_t>(LeafSphere(ref))]
                       : first_[static_cast<std::size_t>(ref)];
  }
  std::int32_t count(HierarchyRef ref) const {
    return IsLeaf(ref) ? 1 : count_[static_cast<std::size_t>(ref)];
  }
  // Sphere indices in the order the leaves are met depth-first.
  const std::vector<std::int32_t>& leaf_order() const { return leaf_order_; }
  // The spheres in leaf_order(): a node's spheres are the contiguous range [first, first +
  // count). Derived, not serialised.
  const std::vector<Sphere>& ordered_spheres() const { return ordered_spheres_; }

  // What the double-precision distance search (used when a query's magnitudes rule out the
  // float one) reads at each step about one node or leaf, in one record: the
  // sphere around it (outer_sphere(), or the leaf's own), its range in ordered_spheres(), and
  // a node's children (0 for a leaf). Derived, not serialised.
  struct Slot {
    Vector3 center;
    double radius;
    std::int32_t first, count;
    HierarchyRef left, right;
  };
  // Nodes first (slot = ref), then leaves (slot = num_nodes() + sphere).
  std::size_t slot_index(HierarchyRef ref) const {
    return ref >= 0 ? static_cast<std::size_t>(ref)
                    : left_.size() + static_cast<std::size_t>(LeafSphere(ref));
  }
  const Slot& slot(HierarchyRef ref) const { return slots_[slot_index(ref)]; }
  // The distance query's wide view of the tree: a node's children, with each child that is a
  // node replaced by its own two children (2 to 4 entries), and the sphere around each entry
  // (query_sphere()) rounded to float. Unused lanes hold zeros. Derived, not serialised.
  struct Quad {
    float x[4], y[4], z[4], radius[4];
    HierarchyRef child[4];
    std::int32_t size;
  };
  const Quad& quad(std::int32_t node) const { return quads_[static_cast<std::size_t>(node)]; }
  // The tightest sphere known around a node or leaf: the bounding sphere for kSphere, the
  // smallest sphere around the node's spheres (padded as Build pads) for kRss, the sphere
  // itself for a leaf. Indexed like slot(). Derived, not serialised.
  const Sphere& query_sphere(HierarchyRef ref) const { return query_spheres_[slot_index(ref)]; }

  // ordered_spheres() in single precision, one array per coordinate and one of radii (each
  // rounded to nearest), padded with kFloatPadding copies of the last sphere so that a query
  // may read whole SIMD packets (up to eight floats) past a range's end. Only ever used to prune
  // with margins that cover float rounding (separation_distance.cpp). Derived, not serialised.
  static constexpr std::size_t kFloatPadding = 8;
  const float* float_x() const { return float_x_.data(); }
  const float* float_y() const { return float_y_.data(); }
  const float* float_z() const { return float_z_.data(); }
  const float* float_radius() const { return float_r_.data(); }
  // Over the spheres and every query_sphere(): the largest |coordinate| of a centre, the
  // largest radius, and the largest distance of a centre from the origin: what bounds the
  // magnitudes a query meets.
  double max_abs_coordinate() const { return max_abs_coordinate_; }
  double max_radius() const { return max_radius_; }
  double max_center_norm() const { return max_center_norm_; }
  // Longest path from the root to a leaf, in edges.
  int depth() const { return depth_; }

  // A self-contained byte string ("inscribe.hierarchy" v1, little-endian), so that a server
  // can cache it and ship it. Deserialize refuses anything Serialize would not write:
  // INVALID_ARGUMENT naming the problem for bad magic, version or kind, truncation or trailing
  // bytes, non-finite or negative numbers, child references out of range or not forming one
  // tree over every sphere exactly once, and any sphere not inside every bounding volume above
  // it (checked, so that a tampered file cannot make queries wrong). Cost O(n depth).
  std::string Serialize() const;
  static absl::StatusOr<SphereHierarchy> Deserialize(absl::string_view bytes);

 private:
  SphereHierarchy() = default;
  // Deserialize's tree and containment checks; sets *depth.
  absl::Status CheckStructure(int* depth) const;
  // Fills the derived arrays: outer_spheres_ from the stored volumes, and the leaf order with
  // each node's range in it.
  void ComputeDerived();

  HierarchyVolume volume_ = HierarchyVolume::kRss;
  std::vector<Sphere> spheres_;
  HierarchyRef root_ = -1;
  std::vector<HierarchyRef> left_, right_;
  std::vector<Rss> rss_;
  std::vector<Sphere> bounding_spheres_;
  std::vector<Sphere> outer_spheres_;
  std::vector<std::int32_t> leaf_order_, leaf_position_, first_, count_;
  std::vector<Sphere> ordered_spheres_;
  std::vector<Slot> slots_;
  std::vector<Quad> quads_;
  std::vector<Sphere> query_spheres_;
  std::vector<float> float_x_, float_y_, float_z_, float_r_;
  double max_abs_coordinate_ = 0.0, max_radius_ = 0.0, max_center_norm_ = 0.0;
  int depth_ = 0;
};

}  // namespace inscribe
