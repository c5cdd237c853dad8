#include "mesh/hole_filling.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <iterator>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "mesh/mesh_topology.h"

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

// One border loop, as the hole walks it: vertices v0, v1, ... with the hole's side on the
// left, i.e. opposite to the triangles' own direction along each border edge.
using Loop = std::vector<std::int32_t>;

struct BorderLoops {
  std::vector<Loop> loops;
  std::string failure;  // "" when the border splits into simple loops
};

// Walks the border edges (edges in one triangle) into loops. Cost O(#T log #T).
BorderLoops FindBorderLoops(const Mesh& mesh) {
  const std::vector<EdgeUse> uses = SortedEdgeUses(mesh);
  BorderLoops result;
  // next[v] = the vertex after v along the hole, -1 if v is not on the border, -2 if v starts
  // more than one border edge.
  std::vector<std::int32_t> next(static_cast<std::size_t>(mesh.num_vertices()), -1);
  std::vector<std::int32_t> starts;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i == 1) {
      // The triangle walks a -> b, so the hole walks b -> a.
      const std::int32_t a = uses[i].forward ? uses[i].lo : uses[i].hi;
      const std::int32_t b = uses[i].forward ? uses[i].hi : uses[i].lo;
      std::int32_t& slot = next[static_cast<std::size_t>(b)];
      if (slot != -1) {
        if (slot >= 0) {
          result.failure = absl::StrCat("the border passes through vertex ", b,
                                        " more than once (two holes or sheets meet there)");
        }
        slot = -2;
      } else {
        slot = a;
        starts.push_back(b);
      }
    }
    i = j;
  }
  if (!result.failure.empty()) return result;
  std::vector<char> visited(next.size(), 0);
  for (std::int32_t start : starts) {
    if (visited[static_cast<std::size_t>(start)]) continue;
    Loop loop;
    std::int32_t v = start;
    while (v >= 0 && !visited[static_cast<std::size_t>(v)]) {
      visited[static_cast<std::size_t>(v)] = 1;
      loop.push_back(v);
      v = next[static_cast<std::size_t>(v)];
    }
    // With consistent orientation every border vertex ends one border edge and starts one,
    // so each walk returns to its start; anything else is a border CGAL cannot fill.
    if (v != start) {
      result.failure = absl::StrCat("the border through vertex ", start,
                                    " does not close up (inconsistent orientation?)");
      return result;
    }
    result.loops.push_back(std::move(loop));
  }
  return result;
}

// Vertex i of the result is vertex i of `mesh`, face k the k-th triangle with distinct
// corners. Returns false when the triangles do not form a manifold, consistently oriented
// surface (CGAL's own test), the only kind a halfedge mesh can hold.
bool BuildSurfaceMesh(const Mesh& mesh, SurfaceMesh& surface) {
  std::vector<std::array<std::size_t, 3>> polygons;
  polygons.reserve(static_cast<std::size_t>(mesh.num_triangles()));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    polygons.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                        static_cast<std::size_t>(mesh.triangles(t, 1)),
                        static_cast<std::size_t>(mesh.triangles(t, 2))});
  }
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) return false;
  surface.reserve(static_cast<SurfaceMesh::size_type>(mesh.num_vertices()),
                  static_cast<SurfaceMesh::size_type>(3 * polygons.size()),
                  static_cast<SurfaceMesh::size_type>(polygons.size()));
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    surface.add_vertex(Point(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2)));
  }
  for (const auto& p : polygons) {
    const auto f = surface.add_face(SurfaceMesh::Vertex_index(static_cast<std::uint32_t>(p[0])),
                                    SurfaceMesh::Vertex_index(static_cast<std::uint32_t>(p[1])),
                                    SurfaceMesh::Vertex_index(static_cast<std::uint32_t>(p[2])));
    if (f == SurfaceMesh::null_face()) return false;
  }
  return true;
}

// Largest RMS distance of a loop's vertices to their fitted plane, as a fraction of the
// diagonal of the loop's bounding box, for the loop to be filled as a plane polygon. CGAL's
// default (a quarter of the loop's extent along z) depends on the mesh's frame.
constexpr double kPlanarTolerance = 0.1;

double LoopDiagonal(const Mesh& mesh, const Loop& loop) {
  Vector3 lo = mesh.vertices.row(loop.front()).transpose(), hi = lo;
  for (std::int32_t v : loop) {
    lo = lo.cwiseMin(mesh.vertices.row(v).transpose());
    hi = hi.cwiseMax(mesh.vertices.row(v).transpose());
  }
  return (hi - lo).norm();
}

// False when two of the loop's vertices (nearly) coincide once projected along the average
// normal CGAL 5.5's plane-polygon filling computes (triangulate_hole_polyline_with_cdt: the
// fan triangles' normals, each turned to the positive side, averaged). Its simplicity test
// misses such a pair and its constrained triangulation then crashes (found by fuzz_mesh on a
// hole of 4 edges), so such a loop skips that method. Conservative: a tolerance of 1e-9 of
// the loop's diagonal. Cost O(n log n).
bool ProjectsWithoutCoincidences(const Mesh& mesh, const Loop& loop) {
  // CGAL walks the hole from the target of the halfedge loop[0] -> loop[1].
  const auto point = [&](std::size_t i) -> Vector3 {
    return mesh.vertices.row(loop[(i + 1) % loop.size()]).transpose();
  };
  Vector3 normal = Vector3::Zero();
  for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
    Vector3 n = (point(i) - point(0)).cross(point(i + 1) - point(0));
    if (n.x() < 0 || (n.x() == 0 && (n.y() < 0 || (n.y() == 0 && n.z() < 0)))) n = -n;
    normal += n;
  }
  if (!(normal.norm() > 0.0)) return true;  // CGAL gives up on this method by itself
  normal.normalize();
  const Vector3 u = normal.unitOrthogonal();
  const Vector3 v = normal.cross(u);
  std::vector<std::pair<double, double>> projected(loop.size());
  for (std::size_t i = 0; i < loop.size(); ++i) {
    projected[i] = {u.dot(point(i)), v.dot(point(i))};
  }
  std::sort(projected.begin(), projected.end());
  const double tolerance = 1e-9 * LoopDiagonal(mesh, loop);
  for (std::size_t i = 0; i < projected.size(); ++i) {
    for (std::size_t j = i + 1;
         j < projected.size() && projected[j].first - projected[i].first <= tolerance; ++j) {
      if (std::abs(projected[j].second - projected[i].second) <= tolerance) return false;
    }
  }
  return true;
}

std::string DescribeLoop(const Loop& loop) {
  return absl::StrCat("the loop of ", loop.size(), " border edges through vertex ", loop.front());
}

}  // namespace

HoleFilling FillHoles(const Mesh& mesh, const HoleFillingLimits& limits) {
  HoleFilling result;
  result.patch.resize(0, 3);
  BorderLoops border = FindBorderLoops(mesh);
  result.holes = static_cast<std::int64_t>(border.loops.size());
  for (const Loop& loop : border.loops) {
    result.border_edges += static_cast<std::int64_t>(loop.size());
  }
  result.holes_left_open = result.holes;
  auto refuse = [&result](std::string why) {
    result.refused = true;
    result.failure = std::move(why);
    return result;
  };
  if (!border.failure.empty()) return refuse(std::move(border.failure));
  if (result.border_edges > limits.max_total_hole_edges) {
    return refuse(absl::StrCat("the holes have ", result.border_edges,
                               " border edges in all, more than the limit of ",
                               limits.max_total_hole_edges));
  }
  if (border.loops.empty()) return result;

  std::vector<std::array<std::int32_t, 3>> patch;
  std::int64_t work = 0;  // spent of limits.max_search_work
  try {
    SurfaceMesh surface;
    if (!BuildSurfaceMesh(mesh, surface)) {
      return refuse(
          "the triangles do not form a manifold surface (a vertex joins several fans of "
          "triangles)");
    }
    for (const Loop& loop : border.loops) {
      const auto n = static_cast<std::int64_t>(loop.size());
      auto fail = [&](const std::string& why) {
        if (result.failure.empty()) result.failure = absl::StrCat(DescribeLoop(loop), " ", why);
      };
      if (n > limits.max_hole_edges) {
        fail(absl::StrCat("is longer than the limit of ", limits.max_hole_edges, " edges"));
        continue;
      }
      // The border halfedge from v0 to v1 has the hole as its (null) face.
      const SurfaceMesh::Halfedge_index h =
          surface.halfedge(SurfaceMesh::Vertex_index(static_cast<std::uint32_t>(loop[0])),
                           SurfaceMesh::Vertex_index(static_cast<std::uint32_t>(loop[1])));
      if (h == SurfaceMesh::null_halfedge() || !surface.is_border(h)) {
        fail("was not found as a border of the halfedge mesh");
        continue;
      }
      std::vector<SurfaceMesh::Face_index> faces;
      // First as a plane polygon: CGAL fits a plane to the loop and, when the loop's RMS
      // distance to it is within the tolerance and its projection is a simple polygon, fills
      // that polygon's constrained Delaunay triangulation. No other method is tried here.
      if (ProjectsWithoutCoincidences(mesh, loop)) {
        PMP::triangulate_hole(surface, h, std::back_inserter(faces),
                              CGAL::parameters::use_2d_constrained_delaunay_triangulation(true)
                                  .threshold_distance(kPlanarTolerance * LoopDiagonal(mesh, loop))
                                  .use_delaunay_triangulation(false)
                                  .do_not_use_cubic_algorithm(true));
      }
      if (faces.empty()) {
        if (n > limits.max_spatial_hole_edges) {
          fail(absl::StrCat("is not near planar and is longer than ", limits.max_spatial_hole_edges,
                            " edges, the limit for a search in space"));
          continue;
        }
        const std::int64_t spatial_work = 8 * n * n;
        const std::int64_t exhaustive_work = n * n * n / 6;
        if (work + spatial_work > limits.max_search_work) {
          fail(
              "is not near planar, and searching for its triangulation would exceed the work "
              "budget left by other holes");
          continue;
        }
        const bool exhaustive = n <= limits.max_exhaustive_hole_edges &&
                                work + spatial_work + exhaustive_work <= limits.max_search_work;
        work += spatial_work + (exhaustive ? exhaustive_work : 0);
        PMP::triangulate_hole(surface, h, std::back_inserter(faces),
                              CGAL::parameters::use_2d_constrained_delaunay_triangulation(false)
                                  .use_delaunay_triangulation(true)
                                  .do_not_use_cubic_algorithm(!exhaustive));
        if (faces.empty()) {
          fail(exhaustive ? std::string("has no valid triangulation")
                          : std::string("has no valid triangulation among the faces of its "
                                        "Delaunay triangulation, and no exhaustive search was "
                                        "tried (the loop is too long or the work budget spent)"));
          continue;
        }
      }
      for (SurfaceMesh::Face_index f : faces) {
        const SurfaceMesh::Halfedge_index a = surface.halfedge(f);
        const SurfaceMesh::Halfedge_index b = surface.next(a);
        const SurfaceMesh::Halfedge_index c = surface.next(b);
        patch.push_back({static_cast<std::int32_t>(surface.target(a).idx()),
                         static_cast<std::int32_t>(surface.target(b).idx()),
                         static_cast<std::int32_t>(surface.target(c).idx())});
      }
      ++result.holes_filled;
      result.filled_border_edges += n;
    }
  } catch (const std::exception& e) {
    // CGAL signals violated preconditions (and memory exhaustion) by throwing.
    result.patch.resize(0, 3);
    result.holes_filled = 0;
    result.filled_border_edges = 0;
    result.holes_left_open = result.holes;
    return refuse(absl::StrCat("CGAL failed while filling holes: ", e.what()));
  }
  result.holes_left_open = result.holes - result.holes_filled;
  result.patch.resize(static_cast<Eigen::Index>(patch.size()), 3);
  for (std::size_t i = 0; i < patch.size(); ++i) {
    for (int k = 0; k < 3; ++k) result.patch(static_cast<Eigen::Index>(i), k) = patch[i][k];
  }
  return result;
}

}  // namespace inscribe::internal
