// Private: a flat bounding-volume hierarchy over a mesh's triangles, for closest-point queries in
// double precision and exact ray crossings.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "base/float_rounding.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/solid/boundary_oracle.h"
#include "solid/exact_winding.h"

namespace inscribe::internal {

// A child of an inner node, or the root: either an inner node or a leaf. Trivial (no member
// initialisers), so that traversal stacks of them cost nothing to declare.
struct TriangleBvhRef {
  // count == 0: index of an inner node in TriangleBvh::nodes(). count > 0: index of a leaf in
  // TriangleBvh::leaves(), holding `count` (1 .. kMaxLeafSize) triangles.
  std::int32_t index;
  std::int32_t count;

  constexpr bool is_leaf() const { return count > 0; }
};

// An inner node of a TriangleBvh: its two children and their axis-aligned boxes, 64 bytes (one
// cache line), so one load gives everything needed to order and cull both children. Boxes are
// single precision, rounded outward from the double-precision corners (a box always contains
// its triangles), mesh frame and units; stored axis-major so that both children's bounds on
// one axis are adjacent.
struct alignas(64) TriangleBvhNode {
  float lo[3][2];  // lo[axis][child]
  float hi[3][2];
  TriangleBvhRef child[2];
};

// A leaf: a few triangles and an oriented box around them, 128 bytes. On a curved surface the
// axis-aligned box of a patch is loose where the patch is slanted, and closest-point queries
// then test many triangles that are only nearly as close as the answer; a box aligned with the
// patch's mean normal is thin, and culls most of them for the cost of one 3 x 3 product.
struct alignas(64) TriangleBvhLeaf {
  // Rows: orthonormal axes, the last one along the area-weighted normal (identity when the
  // triangles have no usable normal). Mesh frame, double.
  double axes[3][3];
  // Extent of the corners along each axis: for every corner c, lo[k] <= axes[k] . c <= hi[k].
  double lo[3];
  double hi[3];
  std::int32_t first;  // first slot
  std::int32_t count;  // slots first .. first + count - 1
};

// One slot's triangle in its leaf's frame: the extent of its corners along the leaf's axes,
// rounded outward to float, 24 bytes. Once the query point is in the leaf's frame, it bounds
// the triangle's distance from below in a few operations, sparing most exact tests.
struct TriangleBvhSlotBox {
  float lo[3];
  float hi[3];
};

// Work counters of queries, for benchmarks and tests.
struct TriangleBvhStats {
  std::int64_t nodes = 0;      // inner nodes whose children's boxes were tested
  std::int64_t leaves = 0;     // leaves whose oriented box was tested (closest point only)
  std::int64_t slots = 0;      // triangles whose slot box was tested (closest point only)
  std::int64_t triangles = 0;  // triangles whose closest point (or crossing) was computed
};

// Binary BVH in flat arrays linked by index (Manifold's collider / PQP's node array): root()
// is a leaf or inner node 0, inner nodes come after their parents, every leaf holds 1 to
// kMaxLeafSize "slots", and slot s holds triangle slot_triangles()[s] with its corners copied
// to corners()[3s .. 3s+2] (double, contiguous in leaf order, so a leaf's triangles are read
// from one place) and its box in the leaf's frame in slot_boxes()[s]. Built top-down with binned
// SAH, deterministic.
//
// A closest-point query culls in three stages, each a lower bound on the distance: the
// axis-aligned boxes of inner nodes, the oriented box of a leaf, the slot boxes of its
// triangles; only triangles that pass all three get an exact test.
//
// Every distance and crossing is computed in double precision from the copied corners with
// ClosestPointOnTriangle / XRayCrossing (exact); the boxes only cull, with a margin that keeps
// culling conservative, so queries return exactly what a scan over all triangles would, ties
// going to the lowest triangle index.
//
// Immutable after Build except for Refit. Const methods are safe to call concurrently. A
// default-constructed TriangleBvh holds nothing and must not be queried.
class TriangleBvh {
 public:
  static constexpr int kMaxLeafSize = 16;
  // Depth-first traversal stacks: the tree's depth never exceeds it (see triangle_bvh.cpp).
  static constexpr int kTraversalStackSize = 98;

  TriangleBvh() = default;

  // `mesh` must have at least one triangle, in-range indices and finite coordinates (the
  // caller checks). Cost O(#T log #T) time, about 120 bytes per triangle.
  static TriangleBvh Build(const Mesh& mesh);

  // New positions of the same mesh (same #V and triangles as at Build): copies the corners
  // again and recomputes every box and leaf frame, keeping the tree's topology. O(#T), leaves
  // in parallel (TBB). The result is bit for bit the tree that Build would give with this
  // topology; queries return exactly what a fresh Build on these vertices returns (both equal
  // the brute-force scan), only their cost grows as the deformation makes the topology stale.
  void Refit(const Mesh& mesh);

  // The boundary point nearest to p over all triangles: the minimum of the squared distance
  // as computed by ClosestPointOnTriangle, lowest triangle index among equal minima.
  //
  // upper_bound (mesh units): the caller asserts that some triangle lies within this distance
  // of p; triangles farther away are culled from the start. If none is found within it (the
  // assertion was wrong, or the bound negative), returns triangle == -1; NaN or infinity mean
  // no bound. Cost O(log #T) typical, more the farther p is from the surface.
  BoundaryPoint ClosestPoint(const Vector3& p,
                             double upper_bound = std::numeric_limits<double>::infinity(),
                             TriangleBvhStats* stats = nullptr) const;

  // Calls visit(triangle, crossing) for every triangle that XRayCrossing (exact_winding.h)
  // says the symbolically perturbed ray from p along +x crosses (crossing +1 or -1) or that
  // holds p (crossing kOnTriangle), in no particular order. Visits every leaf whose box
  // holds p's (y, z) and reaches x >= p_x. Cost O(log #T) plus the triangles the ray passes.
  template <typename Visit>
  void ForEachXRayCrossing(const Vector3& p, Visit&& visit) const;

  // The winding number around p (perturbed as XRayCrossing says) of the mesh's triangles: the
  // sum of their crossings. *on_surface: whether some triangle was found to hold p.
  int XRayWinding(const Vector3& p, bool* on_surface) const;

  TriangleBvhRef root() const { return root_; }
  const std::vector<TriangleBvhNode>& nodes() const { return nodes_; }
  const std::vector<TriangleBvhLeaf>& leaves() const { return leaves_; }
  const std::vector<std::int32_t>& slot_triangles() const { return slot_triangle_; }
  const std::vector<Vector3>& corners() const { return corners_; }
  const std::vector<TriangleBvhSlotBox>& slot_boxes() const { return slot_boxes_; }
  // Largest |coordinate| over the corners: scales the culling margins.
  double magnitude() const { return magnitude_; }

 private:
  // Copies the corners from `mesh` and computes every box and leaf frame. Build and Refit
  // share it, so a refit tree is bit for bit a built one.
  void Fit(const Mesh& mesh);

  TriangleBvhRef root_{0, 0};
  std::vector<TriangleBvhNode> nodes_;  // inner nodes, at most #T - 1
  std::vector<TriangleBvhLeaf> leaves_;
  std::vector<std::int32_t> slot_triangle_;     // #T: triangle index of each slot
  std::vector<Vector3> corners_;                // 3 #T: corners of slot s at 3s, 3s+1, 3s+2
  std::vector<TriangleBvhSlotBox> slot_boxes_;  // #T
  double magnitude_ = 0.0;
};

template <typename Visit>
void TriangleBvh::ForEachXRayCrossing(const Vector3& p, Visit&& visit) const {
  // Boxes are rounded outward from the corners and the tests are closed, so a box that holds
  // a triangle the perturbed ray meets is never culled.
  auto holds_ray = [&p](const TriangleBvhNode& n, int c) {
    return static_cast<double>(n.hi[0][c]) >= p.x() && static_cast<double>(n.lo[1][c]) <= p.y() &&
           static_cast<double>(n.hi[1][c]) >= p.y() && static_cast<double>(n.lo[2][c]) <= p.z() &&
           static_cast<double>(n.hi[2][c]) >= p.z();
  };
  TriangleBvhRef stack[kTraversalStackSize];
  int top = 0;
  stack[top++] = root_;
  while (top > 0) {
    const TriangleBvhRef ref = stack[--top];
    if (ref.is_leaf()) {
      const TriangleBvhLeaf& leaf = leaves_[static_cast<std::size_t>(ref.index)];
      for (std::int32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
        const Vector3* c = &corners_[3 * static_cast<std::size_t>(s)];
        const int crossing = XRayCrossing(p, c[0], c[1], c[2]);
        if (crossing != 0) visit(slot_triangle_[static_cast<std::size_t>(s)], crossing);
      }
      continue;
    }
    const TriangleBvhNode& n = nodes_[static_cast<std::size_t>(ref.index)];
    for (int c = 1; c >= 0; --c) {
      if (holds_ray(n, c)) stack[top++] = n.child[c];
    }
  }
}

}  // namespace inscribe::internal
