#include "inscribe/mesh/mesh_clip.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/clip.h>
#include <CGAL/Polygon_mesh_processing/polygon_mesh_to_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <cmath>
#include <exception>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

}  // namespace

absl::StatusOr<Mesh> ClipMeshByPlane(const Mesh& mesh, const Vector3& normal, double offset) {
  if (!normal.allFinite() || !(normal.norm() > 0.0) || !std::isfinite(offset)) {
    return absl::InvalidArgumentError(
        absl::StrCat("clip plane: the normal must be a non-zero finite vector and the offset "
                     "finite, got normal (",
                     normal.x(), ", ", normal.y(), ", ", normal.z(), ") offset ", offset));
  }
  // Wholly on one side: nothing to cut (the exact common case of a plane past the mesh).
  const Eigen::VectorXd heights = mesh.vertices * normal;
  if (mesh.vertices.rows() == 0 || heights.maxCoeff() <= offset) return mesh;
  if (heights.minCoeff() >= offset) return Mesh{};

  std::vector<Point> points;
  points.reserve(static_cast<std::size_t>(mesh.vertices.rows()));
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    points.emplace_back(mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2));
  }
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(static_cast<std::size_t>(mesh.triangles.rows()));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    faces.push_back({static_cast<std::size_t>(mesh.triangles(t, 0)),
                     static_cast<std::size_t>(mesh.triangles(t, 1)),
                     static_cast<std::size_t>(mesh.triangles(t, 2))});
  }
  SurfaceMesh surface;
  try {
    if (!PMP::is_polygon_soup_a_polygon_mesh(faces)) {
      return absl::FailedPreconditionError(
          "clip plane: the mesh is not a closed 2-manifold, so it cannot be cut");
    }
    PMP::polygon_soup_to_polygon_mesh(points, faces, surface);
    // CGAL keeps the plane's negative side: a x + b y + c z + d <= 0.
    const Kernel::Plane_3 plane(normal.x(), normal.y(), normal.z(), -offset);
    if (!PMP::clip(surface, plane, CGAL::parameters::clip_volume(true))) {
      return absl::FailedPreconditionError(
          "clip plane: CGAL could not cut the mesh (it is not a closed 2-manifold)");
    }
    PMP::triangulate_faces(surface);  // a no-op unless a cap came out as polygons
  } catch (const std::exception& e) {
    return absl::FailedPreconditionError(absl::StrCat("clip plane: CGAL failed: ", e.what()));
  }
  std::vector<Point> out_points;
  std::vector<std::vector<std::size_t>> out_faces;
  PMP::polygon_mesh_to_polygon_soup(surface, out_points, out_faces);
  Mesh out;
  out.vertices.resize(static_cast<Eigen::Index>(out_points.size()), 3);
  for (std::size_t v = 0; v < out_points.size(); ++v) {
    out.vertices.row(static_cast<Eigen::Index>(v)) << CGAL::to_double(out_points[v].x()),
        CGAL::to_double(out_points[v].y()), CGAL::to_double(out_points[v].z());
  }
  std::vector<std::array<std::int64_t, 3>> triangles;
  for (const std::vector<std::size_t>& face : out_faces) {
    if (face.size() != 3) {
      return absl::InternalError(
          absl::StrCat("clip plane: CGAL left a face with ", face.size(), " corners"));
    }
    triangles.push_back({static_cast<std::int64_t>(face[0]), static_cast<std::int64_t>(face[1]),
                         static_cast<std::int64_t>(face[2])});
  }
  out.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      out.triangles(static_cast<Eigen::Index>(t), k) = static_cast<int>(triangles[t][k]);
    }
  }
  return out;
}

}  // namespace inscribe
