#include "solid/mesh_wrap.h"

#include <CGAL/Bbox_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>
#include <CGAL/box_intersection_d.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numeric>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "mesh/mesh_topology.h"
#include "solid/closest_point_triangle.h"
#include "solid/triangle_bvh.h"

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::size_t>;

Point ToPoint(const Mesh& mesh, std::int32_t v) {
  return Point(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
}

CGAL::Bbox_3 TriangleBox(const Mesh& mesh, Eigen::Index t) {
  CGAL::Bbox_3 box;
  for (int k = 0; k < 3; ++k) box += ToPoint(mesh, mesh.triangles(t, k)).bbox();
  return box;
}

// Whether input triangle t (possibly of zero area: then the segment between its two farthest
// corners, or its one point) meets the wrap's triangle w; exact predicates.
bool Meets(const Mesh& input, Eigen::Index t, const Mesh& wrap, Eigen::Index w) {
  const Kernel::Triangle_3 wall(ToPoint(wrap, wrap.triangles(w, 0)),
                                ToPoint(wrap, wrap.triangles(w, 1)),
                                ToPoint(wrap, wrap.triangles(w, 2)));
  const std::array<Point, 3> p = {ToPoint(input, input.triangles(t, 0)),
                                  ToPoint(input, input.triangles(t, 1)),
                                  ToPoint(input, input.triangles(t, 2))};
  if (!CGAL::collinear(p[0], p[1], p[2])) {
    return CGAL::do_intersect(Kernel::Triangle_3(p[0], p[1], p[2]), wall);
  }
  // Collinear: the segment between the two extreme corners spans the triangle.
  std::array<Point, 3> sorted = p;
  std::sort(sorted.begin(), sorted.end());  // lexicographic: extremes along the line
  if (sorted.front() == sorted.back()) return CGAL::do_intersect(sorted.front(), wall);
  return CGAL::do_intersect(Kernel::Segment_3(sorted.front(), sorted.back()), wall);
}

}  // namespace

absl::StatusOr<Mesh> AlphaWrap(const Mesh& soup, double alpha, double offset) {
  std::vector<Point> points;
  points.reserve(static_cast<std::size_t>(soup.num_vertices()));
  for (Eigen::Index v = 0; v < soup.vertices.rows(); ++v) {
    points.push_back(ToPoint(soup, static_cast<std::int32_t>(v)));
  }
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(static_cast<std::size_t>(soup.num_triangles()));
  for (Eigen::Index t = 0; t < soup.triangles.rows(); ++t) {
    if (!HasDistinctCorners(soup, t)) continue;
    const std::array<std::int32_t, 3> c = {soup.triangles(t, 0), soup.triangles(t, 1),
                                           soup.triangles(t, 2)};
    // CGAL's wrap oracle builds an AABB tree of the faces; zero-area ones are skipped there
    // too, so they are left out here (their points lie on the other triangles' lines, and the
    // enclosure check below tests them).
    if (CGAL::collinear(points[c[0]], points[c[1]], points[c[2]])) continue;
    faces.push_back({static_cast<std::size_t>(c[0]), static_cast<std::size_t>(c[1]),
                     static_cast<std::size_t>(c[2])});
  }
  if (faces.empty()) {
    return absl::InvalidArgumentError("the mesh has no triangle of non-zero area to wrap");
  }
  CGAL::Surface_mesh<Point> wrap;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
  if (wrap.number_of_faces() == 0) {
    return absl::InternalError(
        absl::StrFormat("the alpha wrap (alpha %g, offset %g) came out empty", alpha, offset));
  }
  Mesh out;
  out.vertices.resize(static_cast<Eigen::Index>(wrap.number_of_vertices()), 3);
  std::vector<std::int32_t> index(wrap.num_vertices(), -1);
  std::int32_t next = 0;
  for (const auto v : wrap.vertices()) {
    const Point& p = wrap.point(v);
    out.vertices.row(next) = Vector3(p.x(), p.y(), p.z()).transpose();
    index[static_cast<std::size_t>(v)] = next++;
  }
  out.vertices.conservativeResize(next, 3);
  out.triangles.resize(static_cast<Eigen::Index>(wrap.number_of_faces()), 3);
  Eigen::Index row = 0;
  for (const auto f : wrap.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(wrap.halfedge(f), wrap)) {
      if (k < 3) out.triangles(row, k) = index[static_cast<std::size_t>(v)];
      ++k;
    }
    if (k != 3) return absl::InternalError("the alpha wrap has a face that is not a triangle");
    ++row;
  }
  return out;
}

std::string CheckWrapEncloses(const Mesh& wrap, const Mesh& input) {
  if (wrap.num_triangles() == 0) return "the wrap has no triangles";
  // Every used input vertex strictly inside the wrap.
  const TriangleBvh bvh = TriangleBvh::Build(wrap);
  std::vector<char> used(static_cast<std::size_t>(input.num_vertices()), 0);
  for (Eigen::Index t = 0; t < input.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(input.triangles(t, k))] = 1;
  }
  for (Eigen::Index v = 0; v < input.vertices.rows(); ++v) {
    if (!used[static_cast<std::size_t>(v)]) continue;
    bool on_surface = false;
    const Vector3 p = input.vertices.row(v).transpose();
    if (bvh.XRayWinding(p, &on_surface) == 0 || on_surface) {
      return absl::StrFormat("input vertex %d (%g, %g, %g) is %s the wrap", v, p.x(), p.y(), p.z(),
                             on_surface ? "on the surface of" : "outside");
    }
  }
  // No input triangle meets the wrap's surface.
  std::vector<Box> input_boxes, wrap_boxes;
  input_boxes.reserve(static_cast<std::size_t>(input.num_triangles()));
  for (Eigen::Index t = 0; t < input.triangles.rows(); ++t) {
    input_boxes.emplace_back(TriangleBox(input, t), static_cast<std::size_t>(t));
  }
  wrap_boxes.reserve(static_cast<std::size_t>(wrap.num_triangles()));
  for (Eigen::Index w = 0; w < wrap.triangles.rows(); ++w) {
    wrap_boxes.emplace_back(TriangleBox(wrap, w), static_cast<std::size_t>(w));
  }
  Eigen::Index first_input = -1, first_wrap = -1;
  CGAL::box_intersection_d(input_boxes.begin(), input_boxes.end(), wrap_boxes.begin(),
                           wrap_boxes.end(), [&](const Box& a, const Box& b) {
                             if (first_input >= 0) return;
                             const auto t = static_cast<Eigen::Index>(a.info());
                             const auto w = static_cast<Eigen::Index>(b.info());
                             if (Meets(input, t, wrap, w)) {
                               first_input = t;
                               first_wrap = w;
                             }
                           });
  if (first_input >= 0) {
    return absl::StrCat("input triangle ", first_input, " meets the wrap's triangle ", first_wrap);
  }
  return "";
}

double WrapReachBound(const Mesh& wrap, const Mesh& input) {
  const TriangleBvh bvh = TriangleBvh::Build(input);
  // Rounding: the closest-point computation errs far below a 1e-12 relative and 1e-14 of the
  // coordinates' magnitude absolute pad.
  const double magnitude =
      std::max(input.vertices.cwiseAbs().maxCoeff(), wrap.vertices.cwiseAbs().maxCoeff());
  auto padded = [magnitude](double d) { return d * (1.0 + 1e-12) + 1e-14 * magnitude; };
  auto to_triangle = [&input](const Vector3& p, std::int32_t t) {
    Vector3 weights;
    const Vector3 q =
        ClosestPointOnTriangle(p, input.vertices.row(input.triangles(t, 0)).transpose(),
                               input.vertices.row(input.triangles(t, 1)).transpose(),
                               input.vertices.row(input.triangles(t, 2)).transpose(), &weights);
    return (p - q).norm();
  };
  // The distance to one input triangle is convex, so over a wrap triangle it peaks at a corner:
  // sup over the triangle of the distance to the input is at most, for any input triangle j,
  // the largest corner distance to j. Candidates j: the triangles nearest to the corners and
  // the centroid.
  struct Corner {
    Vector3 p;
    std::int32_t nearest;
    double d;
  };
  auto corner_of = [&](const Vector3& p) {
    const BoundaryPoint closest = bvh.ClosestPoint(p);
    return Corner{p, closest.triangle, (p - closest.point).norm()};
  };
  std::vector<Corner> corners(static_cast<std::size_t>(wrap.num_vertices()));
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, wrap.vertices.rows()),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index v = r.begin(); v != r.end(); ++v) {
                        corners[static_cast<std::size_t>(v)] =
                            corner_of(wrap.vertices.row(v).transpose());
                      }
                    });
  // The largest corner distance is attained: a lower bound on the answer, and the level below
  // which a triangle's bound needs no refining.
  double floor = 0.0;
  for (const Corner& c : corners) floor = std::max(floor, c.d);
  auto bound = [&](const Corner& a, const Corner& b, const Corner& c) {
    const Corner m = corner_of((a.p + b.p + c.p) / 3);
    double best = std::numeric_limits<double>::infinity();
    for (const std::int32_t j : {a.nearest, b.nearest, c.nearest, m.nearest}) {
      best =
          std::min(best, std::max({to_triangle(a.p, j), to_triangle(b.p, j), to_triangle(c.p, j)}));
    }
    return padded(best);
  };
  // The answer is the largest triangle bound, so a triangle (or a part of one) whose bound is
  // already within the largest bound returned so far needs no refining: it cannot raise the
  // answer. The answer is the same as refining every triangle to the 1.25 * floor rule alone
  // (a part stopped early returns at most what is already in the maximum, and the parts that
  // make the maximum are refined as that rule refines them), whatever the order or threads.
  std::atomic<double> returned{padded(floor)};
  auto refine = [&](auto&& self, const Corner& a, const Corner& b, const Corner& c, double here,
                    int depth) -> double {
    if (depth == 0 || here <= std::max(1.25 * floor, returned.load(std::memory_order_relaxed))) {
      return here;
    }
    const Corner ab = corner_of((a.p + b.p) / 2);
    const Corner bc = corner_of((b.p + c.p) / 2);
    const Corner ca = corner_of((c.p + a.p) / 2);
    return std::max({self(self, a, ab, ca, bound(a, ab, ca), depth - 1),
                     self(self, ab, b, bc, bound(ab, b, bc), depth - 1),
                     self(self, ca, bc, c, bound(ca, bc, c), depth - 1),
                     self(self, ab, bc, ca, bound(ab, bc, ca), depth - 1)});
  };
  // Each triangle's first bound, then the triangles refined from the loosest down, so that the
  // bounds that make the answer come in early and the rest stop at once.
  const Eigen::Index n = wrap.triangles.rows();
  auto corner = [&](Eigen::Index t, int k) -> const Corner& {
    return corners[static_cast<std::size_t>(wrap.triangles(t, k))];
  };
  std::vector<double> first(static_cast<std::size_t>(n));
  tbb::parallel_for(
      tbb::blocked_range<Eigen::Index>(0, n), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index t = r.begin(); t != r.end(); ++t) {
          first[static_cast<std::size_t>(t)] = bound(corner(t, 0), corner(t, 1), corner(t, 2));
        }
      });
  std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  std::stable_sort(order.begin(), order.end(), [&](Eigen::Index x, Eigen::Index y) {
    return first[static_cast<std::size_t>(x)] > first[static_cast<std::size_t>(y)];
  });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, order.size(), 16),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const Eigen::Index t = order[i];
                        const double value =
                            refine(refine, corner(t, 0), corner(t, 1), corner(t, 2),
                                   first[static_cast<std::size_t>(t)], 4);
                        double seen = returned.load(std::memory_order_relaxed);
                        while (value > seen && !returned.compare_exchange_weak(seen, value)) {
                        }
                      }
                    });
  return returned.load();
}

}  // namespace inscribe::internal
