// Small meshes built in code, with known volumes, for tests.
#pragma once

#include "inscribe/mesh.h"

namespace inscribe::testing {

// Axis-aligned box [lo, hi], 8 vertices, 12 triangles, outward orientation.
Mesh Box(const Vector3& lo, const Vector3& hi);
inline Mesh UnitCube() { return Box(Vector3::Zero(), Vector3::Ones()); }

// The unit cube without its last triangle: 11 triangles, 3 border edges.
Mesh OpenUnitCube();

// Icosahedron subdivided `levels` times, vertices projected on the sphere (centre, radius).
// 20 * 4^levels triangles, outward orientation.
Mesh Icosphere(int levels, const Vector3& centre = Vector3::Zero(), double radius = 1.0);

// Vertices and triangles of `b` appended to `a` (indices shifted).
Mesh Concatenate(const Mesh& a, const Mesh& b);

// Every triangle reversed.
Mesh Inverted(Mesh mesh);

// Each triangle with three vertices of its own (3 #T vertices), as MeshLab writes OBJ.
Mesh PerFaceVertices(const Mesh& mesh);

}  // namespace inscribe::testing
