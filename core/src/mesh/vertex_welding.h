// Private: merging coincident vertices of a triangle soup, for ValidateMesh.
#pragma once

#include <cstdint>
#include <vector>

#include "inscribe/geometry/mesh.h"

namespace inscribe::internal {

struct Weld {
  std::int64_t merged_vertices = 0;      // vertices merged into an earlier one
  std::int64_t collapsed_triangles = 0;  // triangles removed: welding repeated a corner
};

// Groups every vertex of `mesh` with the first vertex (in index order) that starts a group
// and lies within `tolerance` (mesh units; 0: identical coordinates only), removes the
// triangles that had three distinct corners and would repeat one, and merges each group's
// vertices where their triangles form one fan (joined through edges in exactly two
// triangles): a merge that would pinch separate sheets or shells together at a point or an
// edge is not made there. Kept vertices keep their order and coordinates; triangles keep
// their order and corner order. Needs finite coordinates and in-range indices. Cost
// O(#V log #V + #T log #T) (CGAL's kd-tree when tolerance > 0).
//
// `only` (tolerance > 0): when given (one entry per vertex), only the vertices it marks are
// grouped, with each other, and never two that an edge joins (which would collapse its
// triangles); every other vertex stays its own.
Weld WeldVertices(Mesh& mesh, double tolerance, const std::vector<char>* only = nullptr);

}  // namespace inscribe::internal
