// Unit-cube meshes built in code for the service tests: known volume, known defects.
#pragma once

#include "inscribe/mesh.h"

namespace inscribe::testing {

// [0, 1]^3: 8 vertices, 12 triangles, counter-clockwise seen from outside, volume 1.
inline Mesh CubeMesh() {
  Mesh mesh;
  mesh.vertices.resize(8, 3);
  // Vertex i has x = bit 0, y = bit 1, z = bit 2 of i.
  for (int i = 0; i < 8; ++i) mesh.vertices.row(i) << (i & 1), (i >> 1) & 1, (i >> 2) & 1;
  mesh.triangles.resize(12, 3);
  mesh.triangles << 0, 2, 1, 1, 2, 3,  // z = 0, normal -z
      4, 5, 6, 5, 7, 6,                // z = 1, normal +z
      0, 1, 4, 1, 5, 4,                // y = 0, normal -y
      2, 6, 3, 3, 6, 7,                // y = 1, normal +y
      0, 4, 2, 2, 4, 6,                // x = 0, normal -x
      1, 3, 5, 3, 7, 5;                // x = 1, normal +x
  return mesh;
}

// The unit cube with every triangle reversed: normals point in.
inline Mesh InvertedCubeMesh() {
  Mesh mesh = CubeMesh();
  mesh.triangles.col(1).swap(mesh.triangles.col(2));
  return mesh;
}

// The unit cube without its last triangle: 11 triangles, 3 border edges.
inline Mesh OpenCubeMesh() {
  Mesh mesh = CubeMesh();
  mesh.triangles.conservativeResize(11, 3);
  return mesh;
}

}  // namespace inscribe::testing
