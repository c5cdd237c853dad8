// Private: orienting a closed mesh's triangles, consistently across its edges and outward from
// the solid. Validation reports what these change.
#pragma once

#include <cstdint>
#include <vector>

#include "inscribe/mesh.h"
#include "mesh_topology.h"

namespace inscribe::internal {

// Above this many components, nesting (which shells are cavities) costs O(#components * #T)
// and is skipped: every component is then oriented to enclose positive volume.
constexpr std::int64_t kMaxComponentsForNesting = 256;

// Makes orientation consistent across every manifold edge by breadth-first search, keeping the
// majority orientation of each component, and marks the reversed triangles in `flip` (#T).
// `component`: the edge-connected component of each triangle, -1 for triangles without three
// distinct corners. Returns false if a component is not orientable, with one of its triangles
// in `non_orientable_triangle`.
bool MakeOrientationConsistent(Mesh& mesh, const std::vector<EdgeUse>& uses,
                               const EdgeGroups& groups, const std::vector<std::int32_t>& component,
                               std::int64_t num_components, std::vector<char>& flip,
                               std::int64_t* non_orientable_triangle);

// Points every component's normals away from the solid: a shell inside an even number of other
// shells bounds material from outside (positive volume), one inside an odd number is a cavity
// (negative volume). Toggles `flip` for the triangles it reverses. Returns false when there are
// more than kMaxComponentsForNesting components: nesting is then not checked and every
// component encloses positive volume.
bool OrientComponentsOutward(Mesh& mesh, const std::vector<std::int32_t>& component,
                             std::int64_t num_components, std::vector<char>& flip);

}  // namespace inscribe::internal
