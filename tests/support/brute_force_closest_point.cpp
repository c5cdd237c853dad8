#include "support/brute_force_closest_point.h"

#include <cmath>
#include <limits>

#include "solid/closest_point_triangle.h"

namespace inscribe::testing {

BoundaryPoint BruteForceClosest(const Mesh& mesh, const Vector3& p) {
  BoundaryPoint best;
  double best_squared = std::numeric_limits<double>::infinity();
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    Vector3 bary;
    const Vector3 q = internal::ClosestPointOnTriangle(
        p, mesh.vertices.row(mesh.triangles(t, 0)).transpose(),
        mesh.vertices.row(mesh.triangles(t, 1)).transpose(),
        mesh.vertices.row(mesh.triangles(t, 2)).transpose(), &bary);
    const double d2 = (p - q).squaredNorm();
    if (d2 < best_squared) {
      best_squared = d2;
      best.point = q;
      best.triangle = static_cast<std::int32_t>(t);
      best.barycentric = bary;
    }
  }
  best.distance = std::sqrt(best_squared);
  return best;
}

double BruteForceDistance(const Mesh& mesh, const Vector3& p) {
  return BruteForceClosest(mesh, p).distance;
}

}  // namespace inscribe::testing
