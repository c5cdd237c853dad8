#include "self_intersections.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <iterator>
#include <limits>
#include <type_traits>

#include "mesh_topology.h"
#include "parallel.h"

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

Point VertexPoint(const Mesh& mesh, Eigen::Index v) {
  return Point(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
}

}  // namespace

bool IsOrientedManifold(const Mesh& mesh) {
  const std::vector<EdgeUse> uses = SortedEdgeUses(mesh);
  // Corner k of triangle t is 3t + k; the corners of one vertex that share an edge are joined.
  DisjointSets fans(static_cast<std::size_t>(mesh.num_triangles()) * 3);
  auto corner = [&mesh](const EdgeUse& use, std::int32_t vertex) {
    const int k = mesh.triangles(use.triangle, use.side) == vertex ? use.side : (use.side + 1) % 3;
    return static_cast<std::size_t>(use.triangle) * 3 + static_cast<std::size_t>(k);
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i > 2) return false;
    if (j - i == 2) {
      if (uses[i].forward == uses[i + 1].forward) return false;
      for (std::int32_t vertex : {uses[i].lo, uses[i].hi}) {
        fans.Union(corner(uses[i], vertex), corner(uses[i + 1], vertex));
      }
    }
    i = j;
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
    const Mesh& mesh) {
  std::vector<Point> points;
  points.reserve(static_cast<std::size_t>(mesh.num_vertices()));
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) points.push_back(VertexPoint(mesh, v));
  std::vector<std::array<std::size_t, 3>> polygons;
  std::vector<std::int32_t> original;  // polygon index -> triangle index in `mesh`
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    polygons.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                        static_cast<std::size_t>(mesh.triangles(t, 1)),
                        static_cast<std::size_t>(mesh.triangles(t, 2))});
    original.push_back(static_cast<std::int32_t>(t));
  }
  if (!IsOrientedManifold(mesh)) return std::nullopt;
  namespace PMP = CGAL::Polygon_mesh_processing;
  try {
    SurfaceMesh surface;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, surface);
    if (surface.number_of_faces() != polygons.size()) return std::nullopt;
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> faces;
    // Parallel over the box pairs (TBB), except under ThreadSanitizer, which cannot see the
    // start and join of CGAL's own loops (parallel.h); the pairs are sorted below, so the
    // order they come in does not matter.
    using Concurrency =
        std::conditional_t<kThreadSanitizer, CGAL::Sequential_tag, CGAL::Parallel_if_available_tag>;
    PMP::self_intersections<Concurrency>(surface, std::back_inserter(faces));
    // polygon_soup_to_polygon_mesh adds faces in input order, so face i is polygon i.
    std::vector<std::pair<std::int32_t, std::int32_t>> pairs;
    pairs.reserve(faces.size());
    for (const auto& [f, g] : faces) {
      std::int32_t a = original[static_cast<std::size_t>(f.idx())];
      std::int32_t b = original[static_cast<std::size_t>(g.idx())];
      pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
    std::sort(pairs.begin(), pairs.end());
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
