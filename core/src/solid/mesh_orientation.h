// Private: orienting a closed mesh's triangles, consistently across its edges and outward from
// the solid. Validation reports what these change.
#pragma once

#include <cstdint>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "mesh/mesh_topology.h"

namespace inscribe::internal {

// Makes orientation consistent across every manifold edge by breadth-first search, keeping the
// majority orientation of each component, and marks the reversed triangles in `flip` (#T).
// `component`: the edge-connected component of each triangle, -1 for triangles without three
// distinct corners. Returns false if a component is not orientable, with one of its triangles
// in `non_orientable_triangle`.
bool MakeOrientationConsistent(Mesh& mesh, const std::vector<EdgeUse>& uses,
                               const EdgeGroups& groups, const std::vector<std::int32_t>& component,
                               std::int64_t num_components, std::vector<char>& flip,
                               std::int64_t* non_orientable_triangle);

// Points every component's normals away from the solid: a shell enclosed by an even number of
// other shells bounds material from outside (positive volume), one enclosed by an odd number is
// a cavity (negative volume), for any number of components, with exact winding numbers, so
// that the solid is where the winding number of the result is not zero (InsideTest). Toggles
// `flip` for the triangles it reverses. Needs consistent orientation within each component.
// Returns how many shells are flat: so little volume for their size that their orientation's
// sign, and the pseudonormal near them, cannot be trusted (the exact test is then needed).
std::int64_t OrientComponentsOutward(Mesh& mesh, const std::vector<std::int32_t>& component,
                                     std::int64_t num_components, std::vector<char>& flip);

}  // namespace inscribe::internal
