#include "support/cgal_mesh_writer.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>

#include <array>
#include <vector>

namespace inscribe::testing {

bool WriteMeshWithCgal(const std::string& path, const Mesh& mesh, bool binary) {
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
  std::vector<Point> points;
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    points.emplace_back(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
  }
  std::vector<std::array<std::size_t, 3>> faces;
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    faces.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                     static_cast<std::size_t>(mesh.triangles(t, 1)),
                     static_cast<std::size_t>(mesh.triangles(t, 2))});
  }
  return CGAL::IO::write_polygon_soup(
      path, points, faces, CGAL::parameters::use_binary_mode(binary).stream_precision(17));
}

}  // namespace inscribe::testing
