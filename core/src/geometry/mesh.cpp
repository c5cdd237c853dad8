#include "inscribe/geometry/mesh.h"

namespace inscribe {

BoundingBox ComputeBoundingBox(const Vertices& vertices) {
  BoundingBox box;
  if (vertices.rows() == 0) return box;
  box.min = vertices.colwise().minCoeff().transpose();
  box.max = vertices.colwise().maxCoeff().transpose();
  return box;
}

double SignedVolume(const Mesh& mesh) {
  // Summing det(v0 - o, v1 - o, v2 - o) about the bbox centre o instead of the origin keeps the
  // terms small for meshes far from the origin (less cancellation); the sum is the same.
  const Vector3 origin =
      mesh.num_vertices() > 0
          ? Vector3(0.5 * (mesh.vertices.colwise().minCoeff() + mesh.vertices.colwise().maxCoeff())
                              .transpose())
          : Vector3::Zero();
  double six_volume = 0.0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose() - origin;
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose() - origin;
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose() - origin;
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

}  // namespace inscribe
