// Cutting a closed solid by a plane.
#pragma once

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe {

// The part of the solid bounded by `mesh` (closed, outward oriented, not self-intersecting:
// a mesh ValidateMesh made usable) on the side {x : normal . x <= offset} of the plane, as a
// closed mesh: the cut is capped. Through CGAL's Polygon_mesh_processing::clip, whose
// corefinement computes exactly and rounds the new vertices to doubles. A mesh wholly on the
// kept side comes back unchanged; one wholly beyond it gives a mesh without triangles. Errors:
// INVALID_ARGUMENT for a zero or non-finite normal or offset; FAILED_PRECONDITION when CGAL
// cannot clip the mesh (it is not a closed 2-manifold). O(#T log #T).
absl::StatusOr<Mesh> ClipMeshByPlane(const Mesh& mesh, const Vector3& normal, double offset);

}  // namespace inscribe
