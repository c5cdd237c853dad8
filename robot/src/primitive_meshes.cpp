#include "inscribe/robot/primitive_meshes.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>
#include <vector>

namespace inscribe::robot {

Mesh BoxMesh(const Vector3& size) {
  assert((size.array() > 0.0).all());
  const Vector3 h = 0.5 * size;
  Mesh mesh;
  mesh.vertices.resize(8, 3);
  // Vertex i has corner (bit 0 ? +x : -x, bit 1 ? +y : -y, bit 2 ? +z : -z).
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.row(i) << ((i & 1) ? h.x() : -h.x()), ((i & 2) ? h.y() : -h.y()),
        ((i & 4) ? h.z() : -h.z());
  }
  // Two triangles per face, counter-clockwise seen from outside.
  mesh.triangles.resize(12, 3);
  mesh.triangles << 0, 2, 1, 1, 2, 3,  // -z
      4, 5, 6, 5, 7, 6,                // +z
      0, 1, 4, 1, 5, 4,                // -y
      2, 6, 3, 3, 6, 7,                // +y
      0, 4, 2, 2, 4, 6,                // -x
      1, 3, 5, 3, 7, 5;                // +x
  return mesh;
}

Mesh CylinderMesh(double radius, double length, int sides, PrimitiveFit fit) {
  assert(radius > 0.0 && length > 0.0 && sides >= 3);
  const double h = 0.5 * length;
  if (fit == PrimitiveFit::kEnclosing) {
    radius *= (1.0 + kEnclosingMargin) / std::cos(M_PI / sides);
  }
  Mesh mesh;
  // Rim vertices: bottom ring 0..n-1, top ring n..2n-1; then the two cap centres.
  mesh.vertices.resize(2 * sides + 2, 3);
  for (int i = 0; i < sides; ++i) {
    const double angle = 2.0 * M_PI * i / sides;
    const double x = radius * std::cos(angle), y = radius * std::sin(angle);
    mesh.vertices.row(i) << x, y, -h;
    mesh.vertices.row(sides + i) << x, y, h;
  }
  const int bottom = 2 * sides, top = 2 * sides + 1;
  mesh.vertices.row(bottom) << 0.0, 0.0, -h;
  mesh.vertices.row(top) << 0.0, 0.0, h;
  mesh.triangles.resize(4 * sides, 3);
  for (int i = 0; i < sides; ++i) {
    const int j = (i + 1) % sides;
    mesh.triangles.row(4 * i + 0) << i, j, sides + j;  // side, outward
    mesh.triangles.row(4 * i + 1) << i, sides + j, sides + i;
    mesh.triangles.row(4 * i + 2) << bottom, j, i;               // bottom cap faces -z
    mesh.triangles.row(4 * i + 3) << top, sides + i, sides + j;  // top cap faces +z
  }
  return mesh;
}

namespace {

// The surface of revolution about z through `rings` (z, radius) from top to bottom, each ring
// `sides` vertices (one on +x), closed by the poles (0, 0, top) and (0, 0, bottom) with fans.
// Outward oriented when the rings run from top to bottom with positive radii.
Mesh RevolutionMesh(const std::vector<std::pair<double, double>>& rings, double top, double bottom,
                    int sides) {
  const int n = static_cast<int>(rings.size());
  Mesh mesh;
  mesh.vertices.resize(n * sides + 2, 3);
  for (int r = 0; r < n; ++r) {
    for (int i = 0; i < sides; ++i) {
      const double angle = 2.0 * M_PI * i / sides;
      mesh.vertices.row(r * sides + i) << rings[r].second * std::cos(angle),
          rings[r].second * std::sin(angle), rings[r].first;
    }
  }
  const int north = n * sides, south = n * sides + 1;
  mesh.vertices.row(north) << 0.0, 0.0, top;
  mesh.vertices.row(south) << 0.0, 0.0, bottom;
  mesh.triangles.resize(2 * sides * n, 3);
  int t = 0;
  for (int i = 0; i < sides; ++i) {
    const int j = (i + 1) % sides;
    mesh.triangles.row(t++) << north, i, j;
    for (int r = 0; r + 1 < n; ++r) {
      const int up = r * sides, down = (r + 1) * sides;
      mesh.triangles.row(t++) << up + i, down + i, down + j;
      mesh.triangles.row(t++) << up + i, down + j, up + j;
    }
    mesh.triangles.row(t++) << south, (n - 1) * sides + j, (n - 1) * sides + i;
  }
  return mesh;
}

}  // namespace

Mesh CapsuleMesh(double radius, double length, int sides, int quarter_bands, PrimitiveFit fit) {
  assert(radius > 0.0 && length >= 0.0 && sides >= 3 && quarter_bands >= 1);
  if (fit == PrimitiveFit::kEnclosing) radius *= EnclosingScale(sides, quarter_bands);
  const double h = 0.5 * length;
  std::vector<std::pair<double, double>> rings;
  // Latitudes from the north pole down to the equator on the top cap, then the bottom cap's
  // from its equator down; one equator ring when there is no cylinder part.
  for (int k = 1; k <= quarter_bands; ++k) {
    const double polar = 0.5 * M_PI * k / quarter_bands;
    const double z = k == quarter_bands ? 0.0 : radius * std::cos(polar);
    const double rho = k == quarter_bands ? radius : radius * std::sin(polar);
    rings.emplace_back(h + z, rho);
  }
  for (int k = length > 0.0 ? quarter_bands : quarter_bands + 1; k < 2 * quarter_bands; ++k) {
    const double polar = 0.5 * M_PI * k / quarter_bands;
    const double z = k == quarter_bands ? 0.0 : radius * std::cos(polar);
    const double rho = k == quarter_bands ? radius : radius * std::sin(polar);
    rings.emplace_back(-h + z, rho);
  }
  return RevolutionMesh(rings, h + radius, -h - radius, sides);
}

Mesh EllipsoidMesh(const Vector3& radii, int sides, int quarter_bands, PrimitiveFit fit) {
  assert((radii.array() > 0.0).all() && sides >= 3 && quarter_bands >= 1);
  Mesh mesh = CapsuleMesh(1.0, 0.0, sides, quarter_bands, fit);
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    mesh.vertices.row(i) = mesh.vertices.row(i).cwiseProduct(radii.transpose());
  }
  return mesh;
}

namespace {

// The smallest distance from the centre to a face plane of the unit sphere's inside
// triangulation. Its faces are isosceles trapezoids split in two and triangles at the poles,
// every vertex on the sphere: the distance is below 1 and close to it.
double SmallestFaceDistance(int sides, int quarter_bands) {
  const Mesh mesh = CapsuleMesh(1.0, 0.0, sides, quarter_bands, PrimitiveFit::kInside);
  double smallest = 1.0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose();
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose();
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose();
    const Vector3 normal = (b - a).cross(c - a).normalized();
    // The plane's distance from the centre, as the least over the three corners (the same
    // number up to rounding; the least is the safe one).
    smallest = std::min({smallest, normal.dot(a), normal.dot(b), normal.dot(c)});
  }
  return smallest;
}

}  // namespace

double EnclosingScale(int sides, int quarter_bands) {
  return (1.0 + kEnclosingMargin) / SmallestFaceDistance(sides, quarter_bands);
}

double CylinderExcess(double radius, PrimitiveFit fit, int sides) {
  const double c = std::cos(M_PI / sides);
  return fit == PrimitiveFit::kInside ? radius * (1.0 - c)
                                      : radius * ((1.0 + kEnclosingMargin) / c - 1.0);
}

double CapsuleExcess(double radius, PrimitiveFit fit, int sides, int quarter_bands) {
  // Inside: the mesh holds the ball of the smallest face distance. Enclosing: the mesh lies in
  // the ball of its vertices' radius. Both swept along the axis for the capsule.
  return fit == PrimitiveFit::kInside ? radius * (1.0 - SmallestFaceDistance(sides, quarter_bands))
                                      : radius * (EnclosingScale(sides, quarter_bands) - 1.0);
}

double EllipsoidExcess(const Vector3& radii, PrimitiveFit fit, int sides, int quarter_bands) {
  // The affine image of the ball's bounds: ellipsoids of radii scaled by the same factors,
  // whose surfaces lie at most (factor difference) * largest radius apart.
  return CapsuleExcess(radii.maxCoeff(), fit, sides, quarter_bands);
}

}  // namespace inscribe::robot
