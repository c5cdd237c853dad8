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
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "mesh/mesh_topology.h"
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
      return absl::StrFormat("input vertex %d (%g, %g, %g) is %s the wrap", v, p.x(), p.y(),
                             p.z(), on_surface ? "on the surface of" : "outside");
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
    return absl::StrCat("input triangle ", first_input, " meets the wrap's triangle ",
                        first_wrap);
  }
  return "";
}

double WrapReachBound(const Mesh& wrap, const Mesh& input) {
  const TriangleBvh bvh = TriangleBvh::Build(input);
  // Distances from the wrap's vertices to the input, padded for the rounding of the closest
  // point's computation (relative 1e-12, far above its error for coordinates below
  // kMaxMeshCoordinate).
  auto distance = [&bvh](const Vector3& p) {
    const BoundaryPoint closest = bvh.ClosestPoint(p);
    return (p - closest.point).norm() * (1.0 + 1e-12) + 1e-300;
  };
  std::vector<double> corner(static_cast<std::size_t>(wrap.num_vertices()), 0.0);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, wrap.vertices.rows()),
                    [&](const tbb::blocked_range<Eigen::Index>& r) {
                      for (Eigen::Index v = r.begin(); v != r.end(); ++v) {
                        corner[static_cast<std::size_t>(v)] =
                            distance(wrap.vertices.row(v).transpose());
                      }
                    });
  // Every corner distance is a distance some point of the wrap has: the largest is a lower
  // bound on the reach, and a triangle's bound needs no refining once it is near that.
  const double floor = corner.empty() ? 0.0 : *std::max_element(corner.begin(), corner.end());
  struct Corner {
    Vector3 p;
    double d;
  };
  const double pad = 1.0 + 1e-12;
  // Over the triangle (a, b, c): each point x is within |x - q| of any point q whose distance
  // to the input is known, and the farthest point of a triangle from q is a corner; q runs over
  // the corners and the centroid.
  auto bound = [&](const Corner& a, const Corner& b, const Corner& c, const Corner& m) {
    const double ab = (a.p - b.p).norm(), bc = (b.p - c.p).norm(), ca = (c.p - a.p).norm();
    const double to_m =
        std::max({(a.p - m.p).norm(), (b.p - m.p).norm(), (c.p - m.p).norm()}) * pad;
    return std::min({a.d + std::max(ab, ca) * pad, b.d + std::max(ab, bc) * pad,
                     c.d + std::max(bc, ca) * pad, m.d + to_m});
  };
  auto centroid = [&](const Corner& a, const Corner& b, const Corner& c) {
    const Vector3 p = (a.p + b.p + c.p) / 3;
    return Corner{p, distance(p)};
  };
  auto refine = [&](auto&& self, const Corner& a, const Corner& b, const Corner& c,
                    int depth) -> double {
    const double here = bound(a, b, c, centroid(a, b, c));
    if (depth == 0 || here <= 1.25 * floor) return here;
    const Corner ab{(a.p + b.p) / 2, distance((a.p + b.p) / 2)};
    const Corner bc{(b.p + c.p) / 2, distance((b.p + c.p) / 2)};
    const Corner ca{(c.p + a.p) / 2, distance((c.p + a.p) / 2)};
    return std::max({self(self, a, ab, ca, depth - 1), self(self, ab, b, bc, depth - 1),
                     self(self, ca, bc, c, depth - 1), self(self, ab, bc, ca, depth - 1)});
  };
  return tbb::parallel_reduce(
      tbb::blocked_range<Eigen::Index>(0, wrap.triangles.rows()), floor,
      [&](const tbb::blocked_range<Eigen::Index>& r, double worst) {
        for (Eigen::Index t = r.begin(); t != r.end(); ++t) {
          Corner c[3];
          for (int k = 0; k < 3; ++k) {
            const std::int32_t v = wrap.triangles(t, k);
            c[k] = Corner{wrap.vertices.row(v).transpose(), corner[static_cast<std::size_t>(v)]};
          }
          worst = std::max(worst, refine(refine, c[0], c[1], c[2], 4));
        }
        return worst;
      },
      [](double a, double b) { return std::max(a, b); });
}

}  // namespace inscribe::internal
