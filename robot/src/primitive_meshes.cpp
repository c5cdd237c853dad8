#include "inscribe/robot/primitive_meshes.h"

#include <cassert>
#include <cmath>

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

Mesh CylinderMesh(double radius, double length, int sides) {
  assert(radius > 0.0 && length > 0.0 && sides >= 3);
  const double h = 0.5 * length;
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

}  // namespace inscribe::robot
