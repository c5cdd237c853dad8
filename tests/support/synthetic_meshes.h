// Small meshes built in code, with known volumes, for tests.
#pragma once

#include "inscribe/geometry/mesh.h"

namespace inscribe::testing {

// Axis-aligned box [lo, hi], 8 vertices, 12 triangles, outward orientation.
Mesh Box(const Vector3& lo, const Vector3& hi);
inline Mesh UnitCube() { return Box(Vector3::Zero(), Vector3::Ones()); }

// The unit cube without its last triangle: 11 triangles, 3 border edges.
Mesh OpenUnitCube();

// Icosahedron subdivided `levels` times, vertices projected on the sphere (centre, radius).
// 20 * 4^levels triangles, outward orientation.
Mesh Icosphere(int levels, const Vector3& centre = Vector3::Zero(), double radius = 1.0);

// Tetrahedron with corners a, b, c, d (4 vertices in that order), outward orientation whatever
// their order; all four triangles have zero area when the corners are coplanar.
Mesh Tetrahedron(const Vector3& a, const Vector3& b, const Vector3& c, const Vector3& d);

// Regular octahedron: corners at centre +- radius along each axis (6 vertices, 8 triangles),
// outward orientation.
Mesh Octahedron(const Vector3& centre, double radius);

// Every vertex moved by `offset`.
Mesh Translated(Mesh mesh, const Vector3& offset);

// Vertices and triangles of `b` appended to `a` (indices shifted).
Mesh Concatenate(const Mesh& a, const Mesh& b);

// Every triangle reversed.
Mesh Inverted(Mesh mesh);

// Each triangle with three vertices of its own (3 #T vertices), as MeshLab writes OBJ.
Mesh PerFaceVertices(const Mesh& mesh);

}  // namespace inscribe::testing
