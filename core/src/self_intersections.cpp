#include "self_intersections.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <iterator>

#include "mesh_topology.h"

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

Point VertexPoint(const Mesh& mesh, Eigen::Index v) {
  return Point(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
}

}  // namespace

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
  namespace PMP = CGAL::Polygon_mesh_processing;
  try {
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) return std::nullopt;
    SurfaceMesh surface;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, surface);
    if (surface.number_of_faces() != polygons.size()) return std::nullopt;
    std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> faces;
    PMP::self_intersections(surface, std::back_inserter(faces));
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
