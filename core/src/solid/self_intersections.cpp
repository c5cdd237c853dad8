#include "solid/self_intersections.h"

#include <CGAL/Bbox_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <iterator>
#include <limits>

#include "base/parallel.h"
#include "mesh/mesh_topology.h"

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

Point VertexPoint(const Mesh& mesh, Eigen::Index v) {
  return Point(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
}

using Point2 = Kernel::Point_2;

// The coordinates of `p` other than `drop`, as a point of the plane.
Point2 Projected(const Vector3& p, int drop) {
  return Point2(p[drop == 0 ? 1 : 0], p[drop == 2 ? 1 : 2]);
}

Vector3 ToVector(const Point& p) { return Vector3(p.x(), p.y(), p.z()); }

// Whether some edge line of the convex polygon `a` (2 or 3 points) has all of `b` strictly on
// one side: for a triangle, the side away from its third corner; a segment has one line, and
// either side will do.
bool SomeEdgeSeparates(const Point2* a, int a_count, const Point2* b, int b_count) {
  const int lines = a_count == 3 ? 3 : 1;
  for (int i = 0; i < lines; ++i) {
    const Point2& p = a[i];
    const Point2& q = a[(i + 1) % a_count];
    const CGAL::Orientation side =
        a_count == 3 ? -CGAL::orientation(p, q, a[(i + 2) % 3]) : CGAL::orientation(p, q, b[0]);
    if (side == CGAL::COLLINEAR) continue;
    bool all = true;
    for (int k = 0; k < b_count && all; ++k) all = CGAL::orientation(p, q, b[k]) == side;
    if (all) return true;
  }
  return false;
}

// CGAL's triangle-triangle and triangle-segment tests with a screen in front: when the shapes'
// shadows on the coordinate plane facing the triangle are strictly apart (a line separates
// them, decided by exact 2D orientations), the shapes share no point, since a common point
// would cast its shadow into both. Neighbouring triangles of a nearly flat surface (midpoint
// subdivision, CAD faces) then skip CGAL's 3D test, whose filters fail on near-coplanar points
// and fall back to exact multi-precision arithmetic. Every other pair gets CGAL's test, so the
// answers are CGAL's.
struct ScreenedTraits : Kernel {
  struct Do_intersect_3 {
    using result_type = bool;
    Kernel::Do_intersect_3 exact;

    bool operator()(const Kernel::Triangle_3& t, const Kernel::Segment_3& s) const {
      const Vector3 triangle[3] = {ToVector(t[0]), ToVector(t[1]), ToVector(t[2])};
      const Vector3 other[2] = {ToVector(s.source()), ToVector(s.target())};
      return !ShadowsApart(triangle, other, 2) && exact(t, s);
    }
    bool operator()(const Kernel::Triangle_3& t, const Kernel::Triangle_3& u) const {
      const Vector3 triangle[3] = {ToVector(t[0]), ToVector(t[1]), ToVector(t[2])};
      const Vector3 other[3] = {ToVector(u[0]), ToVector(u[1]), ToVector(u[2])};
      return !ShadowsApart(triangle, other, 3) && exact(t, u);
    }
  };
  Do_intersect_3 do_intersect_3_object() const { return {}; }
};

}  // namespace

bool ShadowsApart(const Vector3 triangle[3], const Vector3* other, int count) {
  // Any plane gives a sound answer; the one facing the triangle most often separates.
  const Vector3 normal = (triangle[1] - triangle[0]).cross(triangle[2] - triangle[0]);
  int drop = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(normal[k]) > std::abs(normal[drop])) drop = k;
  }
  const Point2 a[3] = {Projected(triangle[0], drop), Projected(triangle[1], drop),
                       Projected(triangle[2], drop)};
  Point2 b[3];
  for (int k = 0; k < count; ++k) b[k] = Projected(other[k], drop);
  return SomeEdgeSeparates(a, 3, b, count) || SomeEdgeSeparates(b, count, a, 3);
}

namespace {

// Slabs for a search over `faces` faces: one per kFacesPerSlab, at most four per thread.
std::size_t AutomaticSlabCount(std::size_t faces) {
  constexpr std::size_t kFacesPerSlab = 32768;
  const std::size_t threads =
      static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  return std::clamp<std::size_t>(faces / kFacesPerSlab, 1, 4 * threads);
}

// The faces of the surface (face i: triangle original[i] of `mesh`) in `count` slabs across the
// longest side of its bounding box, cut at quantiles of the faces' box centres so the slabs hold
// about as many faces each. A face is in every slab its (closed) box reaches, so two faces
// whose boxes meet are both in a slab that holds a common point of the boxes: searching each
// slab on its own finds every pair the whole search would.
std::vector<std::vector<SurfaceMesh::Face_index>> FacesBySlab(
    const Mesh& mesh, const std::vector<std::int32_t>& original, std::size_t count) {
  std::vector<CGAL::Bbox_3> boxes(original.size());
  ParallelForRange(std::size_t{0}, boxes.size(), 4096, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i != end; ++i) {
      CGAL::Bbox_3 box;
      for (int k = 0; k < 3; ++k) box += VertexPoint(mesh, mesh.triangles(original[i], k)).bbox();
      boxes[i] = box;
    }
  });
  CGAL::Bbox_3 all;
  for (const CGAL::Bbox_3& box : boxes) all += box;
  count = std::clamp<std::size_t>(count, 1, std::max<std::size_t>(boxes.size(), 1));
  int axis = 0;
  for (int a = 1; a < 3; ++a) {
    if (all.max(a) - all.min(a) > all.max(axis) - all.min(axis)) axis = a;
  }
  // cuts[k - 1] <= slab k <= cuts[k], the outer slabs unbounded.
  std::vector<double> centres;
  centres.reserve(boxes.size());
  for (const CGAL::Bbox_3& box : boxes) centres.push_back(0.5 * (box.min(axis) + box.max(axis)));
  std::vector<double> cuts;
  auto from = centres.begin();
  for (std::size_t k = 1; k < count; ++k) {
    const auto at = centres.begin() + static_cast<std::ptrdiff_t>(k * centres.size() / count);
    std::nth_element(from, at, centres.end());
    cuts.push_back(*at);
    from = at;
  }
  std::vector<std::vector<SurfaceMesh::Face_index>> slabs(count);
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const CGAL::Bbox_3& box = boxes[i];
    const SurfaceMesh::Face_index f(static_cast<SurfaceMesh::size_type>(i));
    // The first slab whose upper cut is at or above the box's low end, through the last whose
    // lower cut is at or below its high end.
    const auto first = std::lower_bound(cuts.begin(), cuts.end(), box.min(axis)) - cuts.begin();
    const auto last = std::upper_bound(cuts.begin(), cuts.end(), box.max(axis)) - cuts.begin();
    for (auto k = first; k <= last; ++k) slabs[static_cast<std::size_t>(k)].push_back(f);
  }
  return slabs;
}

// `surface` made from the triangles of `mesh` with distinct corners (`polygon_of`: each
// triangle's polygon index, -1 when left out), face i for polygon i like CGAL's
// polygon_soup_to_polygon_mesh, linked straight from the edge groups: each edge's two uses
// become its two halfedges. O(#T), where CGAL's conversion searches each vertex's fan for every
// face it adds (about 1 s on 1.2 million triangles). Needs an oriented manifold
// (IsOrientedManifold) and returns false, leaving `surface` empty, when some edge is a border:
// a border's links run around its hole, which CGAL's conversion makes.
bool LinkClosedSurface(const Mesh& mesh, const std::vector<std::int32_t>& polygon_of,
                       std::size_t polygons, const std::vector<EdgeUse>& uses,
                       const EdgeGroups& groups, SurfaceMesh& surface) {
  for (const auto& [i, j] : groups.ranges) {
    if (j - i != 2) return false;
  }
  surface.reserve(static_cast<SurfaceMesh::size_type>(mesh.num_vertices()),
                  static_cast<SurfaceMesh::size_type>(groups.ranges.size()),
                  static_cast<SurfaceMesh::size_type>(polygons));
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) surface.add_vertex(VertexPoint(mesh, v));
  // The halfedge along side k of polygon p: corner_halfedge[3p + k].
  std::vector<SurfaceMesh::Halfedge_index> corner_halfedge(3 * polygons);
  auto slot = [&polygon_of](const EdgeUse& use) {
    return 3 * static_cast<std::size_t>(polygon_of[static_cast<std::size_t>(use.triangle)]) +
           static_cast<std::size_t>(use.side);
  };
  for (const auto& [i, j] : groups.ranges) {
    const SurfaceMesh::Halfedge_index h = surface.add_edge();
    corner_halfedge[slot(uses[i])] = h;
    corner_halfedge[slot(uses[i + 1])] = surface.opposite(h);
  }
  std::size_t p = 0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (polygon_of[static_cast<std::size_t>(t)] < 0) continue;
    const SurfaceMesh::Face_index f = surface.add_face();
    const SurfaceMesh::Halfedge_index* h = &corner_halfedge[3 * p++];
    for (int k = 0; k < 3; ++k) {
      // Side k runs from corner k to corner k + 1.
      const SurfaceMesh::Vertex_index to(
          static_cast<SurfaceMesh::size_type>(mesh.triangles(t, (k + 1) % 3)));
      surface.set_target(h[k], to);
      surface.set_halfedge(to, h[k]);
      surface.set_face(h[k], f);
      surface.set_next(h[k], h[(k + 1) % 3]);
    }
    surface.set_halfedge(f, h[0]);
  }
  return true;
}

}  // namespace

bool IsOrientedManifold(const Mesh& mesh) {
  const std::vector<EdgeUse> uses = SortedEdgeUses(mesh);
  return IsOrientedManifold(mesh, uses, GroupEdges(uses));
}

bool IsOrientedManifold(const Mesh& mesh, const std::vector<EdgeUse>& uses,
                        const EdgeGroups& groups) {
  // Corner k of triangle t is 3t + k; the corners of one vertex that share an edge are joined.
  DisjointSets fans(static_cast<std::size_t>(mesh.num_triangles()) * 3);
  auto corner = [&mesh](const EdgeUse& use, std::int32_t vertex) {
    const int k = mesh.triangles(use.triangle, use.side) == vertex ? use.side : (use.side + 1) % 3;
    return static_cast<std::size_t>(use.triangle) * 3 + static_cast<std::size_t>(k);
  };
  for (const auto& [i, j] : groups.ranges) {
    if (j - i > 2) return false;
    if (j - i == 2) {
      if (uses[i].forward == uses[i + 1].forward) return false;
      for (std::int32_t vertex : {uses[i].lo, uses[i].hi}) {
        fans.Union(corner(uses[i], vertex), corner(uses[i + 1], vertex));
      }
    }
  }
  std::vector<std::size_t> fan_of(static_cast<std::size_t>(mesh.num_vertices()),
                                  std::numeric_limits<std::size_t>::max());
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::size_t root = fans.Find(static_cast<std::size_t>(t) * 3 + k);
      std::size_t& fan = fan_of[static_cast<std::size_t>(mesh.triangles(t, k))];
      if (fan == std::numeric_limits<std::size_t>::max()) fan = root;
      if (fan != root) return false;  // two fans meet at this vertex
    }
  }
  return true;
}

std::optional<std::vector<std::pair<std::int32_t, std::int32_t>>> SelfIntersectingPairs(
    const Mesh& mesh, std::size_t slab_count) {
  const std::vector<EdgeUse> uses = SortedEdgeUses(mesh);
  const EdgeGroups groups = GroupEdges(uses);
  if (!IsOrientedManifold(mesh, uses, groups)) return std::nullopt;
  std::vector<std::int32_t> original;  // polygon index -> triangle index in `mesh`
  std::vector<std::int32_t> polygon_of(static_cast<std::size_t>(mesh.num_triangles()), -1);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    polygon_of[static_cast<std::size_t>(t)] = static_cast<std::int32_t>(original.size());
    original.push_back(static_cast<std::int32_t>(t));
  }
  namespace PMP = CGAL::Polygon_mesh_processing;
  try {
    SurfaceMesh surface;
    if (!LinkClosedSurface(mesh, polygon_of, original.size(), uses, groups, surface)) {
      std::vector<Point> points;
      points.reserve(static_cast<std::size_t>(mesh.num_vertices()));
      for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
        points.push_back(VertexPoint(mesh, v));
      }
      std::vector<std::array<std::size_t, 3>> polygons;
      polygons.reserve(original.size());
      for (const std::int32_t t : original) {
        polygons.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                            static_cast<std::size_t>(mesh.triangles(t, 1)),
                            static_cast<std::size_t>(mesh.triangles(t, 2))});
      }
      PMP::polygon_soup_to_polygon_mesh(points, polygons, surface);
    }
    if (surface.number_of_faces() != original.size()) return std::nullopt;
    // Each slab's search is CGAL's own, sequential; the slabs run in parallel. CGAL's parallel
    // search instead runs 16 searches over quarters of four copies of the boxes, much more
    // work in all (reading and validating 1.2 million triangles: 28.8 s of CPU against 18.7 s
    // with its sequential search), and under ThreadSanitizer its TBB loops would be unseen.
    const std::vector<std::vector<SurfaceMesh::Face_index>> slabs = FacesBySlab(
        mesh, original, slab_count > 0 ? slab_count : AutomaticSlabCount(original.size()));
    std::vector<std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>>> found(
        slabs.size());
    ParallelFor(std::size_t{0}, slabs.size(), [&](std::size_t k) {
      PMP::self_intersections<CGAL::Sequential_tag>(
          slabs[k], surface, std::back_inserter(found[k]),
          CGAL::parameters::geom_traits(ScreenedTraits()));
    });
    // Face i is polygon i.
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    for (const auto& in_slab : found) {
      for (const auto& [f, g] : in_slab) {
        std::int32_t a = original[static_cast<std::size_t>(f.idx())];
        std::int32_t b = original[static_cast<std::size_t>(g.idx())];
        pairs.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
    // A pair whose boxes meet in more than one slab is found in each.
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::int64_t CountCollinearTriangles(const Mesh& mesh, std::int64_t* first) {
  std::int64_t count = 0;
  *first = -1;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    if (CGAL::collinear(VertexPoint(mesh, mesh.triangles(t, 0)),
                        VertexPoint(mesh, mesh.triangles(t, 1)),
                        VertexPoint(mesh, mesh.triangles(t, 2)))) {
      if (count == 0) *first = t;
      ++count;
    }
  }
  return count;
}

}  // namespace inscribe::internal
