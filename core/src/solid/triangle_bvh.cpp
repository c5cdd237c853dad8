#include "solid/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>

#include "base/parallel.h"
#include "solid/closest_point_triangle.h"

namespace inscribe::internal {
namespace {

// Binned SAH: centroid bins per axis, and the cost of visiting a node relative to that of
// testing one triangle. High because leaves cull most of their triangles by their oriented and
// slot boxes. Measured on bunny00, elephant and fandisk: (kMaxLeafSize, kNodeCost) = (16, 8)
// was the fastest of (8, 2), (16, 4), (16, 8), (32, 8); binned SAH beat object-median splits by
// 7% (bunny00) to 19% (fandisk); double-precision node boxes were no faster than float ones
// (within 2%) at twice the size.
constexpr int kBins = 16;
constexpr double kNodeCost = 8.0;
// Below this depth splits follow the SAH; deeper, they halve the triangle count (object
// median), so the depth never exceeds kMaxSahDepth + 31 and kStackSize always suffices.
constexpr int kMaxSahDepth = 48;
constexpr int kStackSize = 96;
static_assert(TriangleBvh::kTraversalStackSize == kStackSize + 2,
              "a traversal pushes at most two children past the depth");

// Culling margins. A box is culled only when its squared distance exceeds
// (d (1 + kCullRelative) + kCullAbsolute * scale)^2, d being the best distance so far and
// scale the largest |coordinate| of the mesh and query: this covers the rounding of box
// distances (relative, a few ulps), of projections into leaf frames and of
// ClosestPointOnTriangle's point (absolute, a few ulps of the coordinates), so no triangle that
// could win, or tie, is ever culled (with zero margins, triangle_bvh_test fails).
constexpr double kCullRelative = 1e-12;
constexpr double kCullAbsolute = 1e-12;
// A caller's upper bound u is honoured when the best squared distance found is at most
// u^2 (1 + kBoundRelative): the rounding of u = sqrt(d^2) itself. Well inside the cull margin.
constexpr double kBoundRelative = 1e-13;

struct Box {
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity());
  Vector3 hi = Vector3::Constant(-std::numeric_limits<double>::infinity());

  void Grow(const Box& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  void Grow(const Vector3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Half the surface area; 0 for an empty box.
  double HalfArea() const {
    if (!(lo.array() <= hi.array()).all()) return 0.0;
    const Vector3 e = hi - lo;
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }
};

constexpr double Square(double x) { return x * x; }

// Squared distances from p to the boxes of the node's two children: lower bounds on the
// distance to every triangle in them. Monotone in the bounds under rounding (see
// kCullAbsolute). Two lanes, one per child (SSE2 on x86-64).
inline Eigen::Array2d ChildSquaredDistances(const TriangleBvhNode& n, const Vector3& p) {
  Eigen::Array2d d2 = Eigen::Array2d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Array2d lo = Eigen::Map<const Eigen::Array2f>(n.lo[k]).cast<double>();
    const Eigen::Array2d hi = Eigen::Map<const Eigen::Array2f>(n.hi[k]).cast<double>();
    const Eigen::Array2d pk = Eigen::Array2d::Constant(p[k]);
    const Eigen::Array2d d = (lo - pk).max(pk - hi).max(0.0);
    d2 += d * d;
  }
  return d2;
}

// p in the leaf's frame: (axes[k] . p) for k = 0, 1, 2.
inline Vector3 ToLeafFrame(const TriangleBvhLeaf& leaf, const Vector3& p) {
  Vector3 x;
  for (int k = 0; k < 3; ++k) {
    x[k] = leaf.axes[k][0] * p.x() + leaf.axes[k][1] * p.y() + leaf.axes[k][2] * p.z();
  }
  return x;
}

// Squared distance from x (a point in a leaf's frame) to the box [lo, hi] in that frame.
// Branch-free (vector max), like ChildSquaredDistances.
template <typename Scalar>
inline double FrameBoxSquaredDistance(const Scalar lo[3], const Scalar hi[3], const Vector3& x) {
  using Array3 = Eigen::Array<Scalar, 3, 1>;
  const Eigen::Array3d l = Eigen::Map<const Array3>(lo).template cast<double>();
  const Eigen::Array3d h = Eigen::Map<const Array3>(hi).template cast<double>();
  return (l - x.array()).max(x.array() - h).max(0.0).square().sum();
}

// Frame of an oriented box around `n` corners: normal axis along the
// area-weighted normal, in-plane axes along the corners' principal directions (closed-form 2 x 2
// eigenvectors); identity if the normal vanishes. Axes are unit to within a few ulps, and
// projections round by a few ulps of |corner|, both far inside kCullRelative / kCullAbsolute,
// so the box is a conservative lower bound at the culling margins.
void FitLeafFrame(const Vector3* corners, int n, TriangleBvhLeaf* leaf) {
  Vector3 normal = Vector3::Zero();
  Vector3 centroid = Vector3::Zero();
  for (int i = 0; i < n; i += 3) {
    normal += (corners[i + 1] - corners[i]).cross(corners[i + 2] - corners[i]);
  }
  for (int i = 0; i < n; ++i) centroid += corners[i];
  centroid /= n;
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  const double length = normal.norm();
  if (length > 0.0 && std::isfinite(length)) {
    const Vector3 w = normal / length;
    // Any unit vector perpendicular to w, then the in-plane covariance of the corners.
    const Vector3 e1 =
        (std::abs(w.x()) < 0.9 ? Vector3::UnitX() : Vector3::UnitY()).cross(w).normalized();
    const Vector3 e2 = w.cross(e1);
    double c11 = 0.0, c12 = 0.0, c22 = 0.0;
    for (int i = 0; i < n; ++i) {
      const Vector3 r = corners[i] - centroid;
      const double x = r.dot(e1), y = r.dot(e2);
      c11 += x * x;
      c12 += x * y;
      c22 += y * y;
    }
    const double angle = 0.5 * std::atan2(2.0 * c12, c11 - c22);
    const Vector3 u = (std::cos(angle) * e1 + std::sin(angle) * e2).normalized();
    axes.row(0) = u.transpose();
    axes.row(1) = w.cross(u).normalized().transpose();
    axes.row(2) = w.transpose();
  }
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 3; ++j) leaf->axes[k][j] = axes(k, j);
  }
}

// The leaf's extents in its frame and its slots' boxes (rounded outward), projecting each
// corner once.
void FitExtents(TriangleBvhLeaf* leaf, const Vector3* corners, TriangleBvhSlotBox* boxes) {
  Vector3 leaf_lo = Vector3::Constant(std::numeric_limits<double>::infinity());
  Vector3 leaf_hi = -leaf_lo;
  for (int s = 0; s < leaf->count; ++s) {
    Vector3 lo = ToLeafFrame(*leaf, corners[3 * s]), hi = lo;
    for (int k = 1; k < 3; ++k) {
      const Vector3 x = ToLeafFrame(*leaf, corners[3 * s + k]);
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    leaf_lo = leaf_lo.cwiseMin(lo);
    leaf_hi = leaf_hi.cwiseMax(hi);
    for (int k = 0; k < 3; ++k) {
      boxes[s].lo[k] = RoundDown(lo[k]);
      boxes[s].hi[k] = RoundUp(hi[k]);
    }
  }
  for (int k = 0; k < 3; ++k) {
    leaf->lo[k] = leaf_lo[k];
    leaf->hi[k] = leaf_hi[k];
  }
}

// One triangle during the build: its box, the box's centre (what the bins sort by) and index.
// Partitioned in place, so that each level of the build reads a contiguous range.
struct Primitive {
  Box box;
  Vector3 centroid;
  std::int32_t triangle;
};

// Top-down build state: the primitives being partitioned.
class Builder {
 public:
  explicit Builder(const Mesh& mesh) {
    primitives_.resize(static_cast<std::size_t>(mesh.num_triangles()));
    ParallelFor(std::size_t{0}, primitives_.size(), [&](std::size_t t) {
      Primitive& p = primitives_[t];
      for (int k = 0; k < 3; ++k) {
        p.box.Grow(
            mesh.vertices.row(mesh.triangles(static_cast<Eigen::Index>(t), k)).transpose().eval());
      }
      p.centroid = 0.5 * (p.box.lo + p.box.hi);
      p.triangle = static_cast<std::int32_t>(t);
    });
  }

  // Fills `nodes` and `leaves` (topology only: bounds are left for
  // TriangleBvh::Fit), `order` with the triangle of each slot, and returns the root.
  TriangleBvhRef Run(std::vector<TriangleBvhNode>* nodes, std::vector<TriangleBvhLeaf>* leaves,
                     std::vector<std::int32_t>* order) {
    struct Work {
      std::int32_t parent;  // -1: the root
      int side;             // which child of parent
      std::int32_t begin, end;
      int depth;
    };
    TriangleBvhRef root;
    nodes->clear();
    nodes->reserve(primitives_.size());
    leaves->clear();
    const auto count = static_cast<std::int32_t>(primitives_.size());
    std::vector<std::int32_t> splits;
    Splits(0, count, 0, splits);
    auto next_split = splits.begin();
    std::vector<Work> work = {{-1, 0, 0, count, 0}};
    while (!work.empty()) {
      const Work w = work.back();
      work.pop_back();
      const std::int32_t mid = *next_split++;
      TriangleBvhRef ref{static_cast<std::int32_t>(leaves->size()), w.end - w.begin};
      if (mid < 0) {
        TriangleBvhLeaf leaf{};
        leaf.first = w.begin;
        leaf.count = ref.count;
        leaves->push_back(leaf);
      } else {
        ref = TriangleBvhRef{static_cast<std::int32_t>(nodes->size()), 0};
        nodes->push_back(TriangleBvhNode{});
        // Left child last in, so first out: subtrees are laid out depth first.
        work.push_back({ref.index, 1, mid, w.end, w.depth + 1});
        work.push_back({ref.index, 0, w.begin, mid, w.depth + 1});
      }
      (w.parent < 0 ? root : (*nodes)[static_cast<std::size_t>(w.parent)].child[w.side]) = ref;
    }
    order->resize(primitives_.size());
    for (std::size_t s = 0; s < primitives_.size(); ++s) (*order)[s] = primitives_[s].triangle;
    return root;
  }

 private:
  // Ranges of at least this many primitives split their two parts in parallel.
  static constexpr std::int32_t kParallelSplit = 16384;

  // Appends the split of primitives_[begin, end) and of every range below it (Split's results)
  // in the order Run lays the tree out: a range, then its first part's ranges, then its
  // second's. The two parts of a large range are split in parallel; each touches only its own
  // primitives and Split depends on nothing else, so the tree does not depend on the schedule.
  // Recursion depth: the tree's, at most kMaxSahDepth + 31.
  void Splits(std::int32_t begin, std::int32_t end, int depth, std::vector<std::int32_t>& out) {
    const std::int32_t mid = Split(begin, end, depth);
    out.push_back(mid);
    if (mid < 0) return;
    if (end - begin < kParallelSplit) {
      Splits(begin, mid, depth + 1, out);
      Splits(mid, end, depth + 1, out);
      return;
    }
    std::vector<std::int32_t> second;
    ParallelFor(0, 2, [&](int part) {
      if (part == 0) {
        Splits(begin, mid, depth + 1, out);
      } else {
        Splits(mid, end, depth + 1, second);
      }
    });
    out.insert(out.end(), second.begin(), second.end());
  }

  // Partitions primitives_[begin, end) and returns the first index of the second part, or -1
  // for a leaf.
  std::int32_t Split(std::int32_t begin, std::int32_t end, int depth) {
    const std::int32_t count = end - begin;
    if (count <= 1) return -1;
    Primitive* const first = primitives_.data() + begin;
    Primitive* const last = primitives_.data() + end;
    Box bounds, centroid_bounds;
    for (const Primitive* p = first; p != last; ++p) {
      bounds.Grow(p->box);
      centroid_bounds.Grow(p->centroid);
    }
    const Vector3 extent = centroid_bounds.hi - centroid_bounds.lo;
    // Bin of centroid coordinate c on axis a: (c - lo[a]) * scale[a], clamped.
    const Vector3 scale = Vector3::Constant(kBins).cwiseQuotient(extent);
    int axis = 0;
    if (extent.y() > extent[axis]) axis = 1;
    if (extent.z() > extent[axis]) axis = 2;
    if (!(extent[axis] > 0.0)) {  // all centroids coincide: any split is as good
      return count <= TriangleBvh::kMaxLeafSize ? -1 : begin + count / 2;
    }
    if (depth >= kMaxSahDepth) return MedianSplit(begin, end, axis);

    // Bins on all three axes in one pass (axes without extent stay empty and are skipped).
    std::array<std::array<Box, kBins>, 3> bin_boxes;
    std::array<std::array<std::int32_t, kBins>, 3> bin_counts{};
    for (const Primitive* p = first; p != last; ++p) {
      for (int a = 0; a < 3; ++a) {
        if (!(extent[a] > 0.0)) continue;
        const auto b =
            static_cast<std::size_t>(Bin(p->centroid[a], centroid_bounds.lo[a], scale[a]));
        ++bin_counts[a][b];
        bin_boxes[a][b].Grow(p->box);
      }
    }
    // Best bin boundary over the three axes: cost in units of triangle tests, relative to the
    // parent's area.
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_boundary = -1;
    for (int a = 0; a < 3; ++a) {
      if (!(extent[a] > 0.0)) continue;
      // right_cost[b]: area * count of bins b .. kBins - 1.
      std::array<double, kBins> right_cost{};
      Box right;
      std::int32_t right_count = 0;
      for (int b = kBins - 1; b > 0; --b) {
        right.Grow(bin_boxes[a][static_cast<std::size_t>(b)]);
        right_count += bin_counts[a][static_cast<std::size_t>(b)];
        right_cost[static_cast<std::size_t>(b)] = right.HalfArea() * right_count;
      }
      Box left;
      std::int32_t left_count = 0;
      for (int b = 1; b < kBins; ++b) {
        left.Grow(bin_boxes[a][static_cast<std::size_t>(b - 1)]);
        left_count += bin_counts[a][static_cast<std::size_t>(b - 1)];
        if (left_count == 0 || left_count == count) continue;
        const double cost = left.HalfArea() * left_count + right_cost[static_cast<std::size_t>(b)];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_boundary = b;
        }
      }
    }
    const double area = bounds.HalfArea();
    const double split_cost = kNodeCost + (area > 0.0 ? best_cost / area : 0.0);
    if (count <= TriangleBvh::kMaxLeafSize && (best_axis < 0 || split_cost >= count)) return -1;
    if (best_axis < 0) return MedianSplit(begin, end, axis);
    const Primitive* middle = std::partition(first, last, [&](const Primitive& p) {
      return Bin(p.centroid[best_axis], centroid_bounds.lo[best_axis], scale[best_axis]) <
             best_boundary;
    });
    return begin + static_cast<std::int32_t>(middle - first);
  }

  static int Bin(double c, double lo, double scale) {
    // Clamped as a double: with a subnormal extent `scale` overflows and the product is NaN or
    // infinite, whose cast to int is undefined (UBSan under fuzz_requests).
    const double b = (c - lo) * scale;
    if (!(b > 0.0)) return 0;
    return b >= kBins - 1 ? kBins - 1 : static_cast<int>(b);
  }

  // Halves the range at the median centroid along `axis`, ties broken by triangle index.
  std::int32_t MedianSplit(std::int32_t begin, std::int32_t end, int axis) {
    const std::int32_t mid = begin + (end - begin) / 2;
    std::nth_element(primitives_.begin() + begin, primitives_.begin() + mid,
                     primitives_.begin() + end, [axis](const Primitive& a, const Primitive& b) {
                       const double ca = a.centroid[axis], cb = b.centroid[axis];
                       return ca < cb || (ca == cb && a.triangle < b.triangle);
                     });
    return mid;
  }

  std::vector<Primitive> primitives_;  // #T
};

}  // namespace

TriangleBvh TriangleBvh::Build(const Mesh& mesh) {
  TriangleBvh bvh;
  bvh.root_ = Builder(mesh).Run(&bvh.nodes_, &bvh.leaves_, &bvh.slot_triangle_);
  bvh.Fit(mesh);
  return bvh;
}

void TriangleBvh::Refit(const Mesh& mesh) { Fit(mesh); }

// Leaves first, in parallel (each depends on its own corners only, so the result does not
// depend on the schedule), then inner nodes: children come after their parents, so one backward
// pass sees every child before its parent. A leaf's axis-aligned box is its corners' box rounded
// outward; an inner node's is the union of its children's (min and max of floats: exact, and
// equal to rounding the union of the corners).
void TriangleBvh::Fit(const Mesh& mesh) {
  corners_.resize(3 * slot_triangle_.size());
  slot_boxes_.resize(slot_triangle_.size());
  magnitude_ = ParallelReduce(
      std::size_t{0}, leaves_.size(), 64, 0.0,
      [&](std::size_t begin, std::size_t end, double magnitude) {
        for (std::size_t i = begin; i != end; ++i) {
          TriangleBvhLeaf& leaf = leaves_[i];
          const auto first = static_cast<std::size_t>(leaf.first);
          for (std::size_t s = first; s < first + static_cast<std::size_t>(leaf.count); ++s) {
            for (int k = 0; k < 3; ++k) {
              const Vector3 c = mesh.vertices.row(mesh.triangles(slot_triangle_[s], k)).transpose();
              corners_[3 * s + static_cast<std::size_t>(k)] = c;
              magnitude = std::max(magnitude, c.cwiseAbs().maxCoeff());
            }
          }
          FitLeafFrame(&corners_[3 * first], 3 * leaf.count, &leaf);
          FitExtents(&leaf, &corners_[3 * first], &slot_boxes_[first]);
        }
        return magnitude;
      },
      [](double a, double b) { return std::max(a, b); });
  for (std::size_t i = nodes_.size(); i-- > 0;) {
    TriangleBvhNode& n = nodes_[i];
    for (int c = 0; c < 2; ++c) {
      const TriangleBvhRef ref = n.child[c];
      if (ref.is_leaf()) {
        const TriangleBvhLeaf& leaf = leaves_[static_cast<std::size_t>(ref.index)];
        const Vector3* corner = &corners_[3 * static_cast<std::size_t>(leaf.first)];
        Vector3 lo = corner[0], hi = lo;
        for (int j = 1; j < 3 * leaf.count; ++j) {
          lo = lo.cwiseMin(corner[j]);
          hi = hi.cwiseMax(corner[j]);
        }
        for (int k = 0; k < 3; ++k) {
          n.lo[k][c] = RoundDown(lo[k]);
          n.hi[k][c] = RoundUp(hi[k]);
        }
      } else {
        const TriangleBvhNode& child = nodes_[static_cast<std::size_t>(ref.index)];
        for (int k = 0; k < 3; ++k) {
          n.lo[k][c] = std::min(child.lo[k][0], child.lo[k][1]);
          n.hi[k][c] = std::max(child.hi[k][0], child.hi[k][1]);
        }
      }
    }
  }
}

BoundaryPoint TriangleBvh::ClosestPoint(const Vector3& p, double upper_bound,
                                        TriangleBvhStats* stats) const {
  const double slack = kCullAbsolute * std::max(magnitude_, p.cwiseAbs().maxCoeff());
  const auto cull_for = [slack](double d) { return Square(d * (1.0 + kCullRelative) + slack); };
  // A negative bound is as broken as any other too-small one; NaN means none.
  const bool bounded = upper_bound < std::numeric_limits<double>::infinity();
  if (bounded) upper_bound = std::max(upper_bound, 0.0);
  double cull = bounded ? cull_for(upper_bound) : std::numeric_limits<double>::infinity();

  BoundaryPoint best;
  double best_squared = std::numeric_limits<double>::infinity();
  struct Entry {
    TriangleBvhRef ref;
    double squared_distance;
  };
  Entry stack[kStackSize + 1];  // + 1: the push below writes before it knows whether to keep
  int top = 0;
  std::int64_t node_visits = 0, leaf_visits = 0, slot_visits = 0, triangle_visits = 0;

  TriangleBvhRef ref = root_;
  for (;;) {
    if (ref.is_leaf()) {
      const TriangleBvhLeaf& leaf = leaves_[static_cast<std::size_t>(ref.index)];
      ++leaf_visits;
      const Vector3 x = ToLeafFrame(leaf, p);
      if (FrameBoxSquaredDistance(leaf.lo, leaf.hi, x) <= cull) {
        slot_visits += leaf.count;
        for (std::int32_t s = leaf.first; s < leaf.first + leaf.count; ++s) {
          const TriangleBvhSlotBox& box = slot_boxes_[static_cast<std::size_t>(s)];
          if (FrameBoxSquaredDistance(box.lo, box.hi, x) > cull) continue;
          ++triangle_visits;
          const Vector3* c = &corners_[3 * static_cast<std::size_t>(s)];
          Vector3 bary;
          const Vector3 q = ClosestPointOnTriangle(p, c[0], c[1], c[2], &bary);
          const double d2 = (p - q).squaredNorm();
          const std::int32_t t = slot_triangle_[static_cast<std::size_t>(s)];
          if (d2 < best_squared || (d2 == best_squared && t < best.triangle)) {
            best_squared = d2;
            best.point = q;
            best.triangle = t;
            best.barycentric = bary;
            cull = std::min(cull, cull_for(std::sqrt(d2)));
          }
        }
      }
    } else {
      ++node_visits;
      const TriangleBvhNode& n = nodes_[static_cast<std::size_t>(ref.index)];
      // Start loading both children while their distances are computed: traversal of a large
      // mesh is bound by memory latency.
      for (const TriangleBvhRef& c : n.child) {
        const auto i = static_cast<std::size_t>(c.index);
        if (c.is_leaf()) {
          __builtin_prefetch(&leaves_[i]);
          __builtin_prefetch(reinterpret_cast<const char*>(&leaves_[i]) + 64);
        } else {
          __builtin_prefetch(&nodes_[i]);
        }
      }
      const Eigen::Array2d d2 = ChildSquaredDistances(n, p);
      const int near = d2[1] < d2[0] ? 1 : 0;
      if (d2[near] <= cull) {
        // Defer the farther child if it is within reach too (branch-free: written always,
        // kept only if so).
        assert(top < kStackSize);
        stack[top] = {n.child[1 - near], d2[1 - near]};
        top += d2[1 - near] <= cull ? 1 : 0;
        ref = n.child[near];
        continue;
      }
    }
    // Next: the most recently deferred subtree still within reach.
    while (top > 0 && stack[top - 1].squared_distance > cull) --top;
    if (top == 0) break;
    ref = stack[--top].ref;
  }
  if (stats != nullptr) {
    stats->nodes += node_visits;
    stats->leaves += leaf_visits;
    stats->slots += slot_visits;
    stats->triangles += triangle_visits;
  }
  if (best.triangle < 0 ||
      (bounded && !(best_squared <= Square(upper_bound) * (1.0 + kBoundRelative)))) {
    return BoundaryPoint{};
  }
  best.distance = std::sqrt(best_squared);
  return best;
}

int TriangleBvh::XRayWinding(const Vector3& p, bool* on_surface) const {
  int winding = 0;
  bool on = false;
  ForEachXRayCrossing(p, [&](std::int32_t, int crossing) {
    if (crossing == kOnTriangle) {
      on = true;
    } else {
      winding += crossing;
    }
  });
  *on_surface = on;
  return winding;
}

}  // namespace inscribe::internal
