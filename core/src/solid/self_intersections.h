// Private: exact self-intersection test of a closed triangle mesh (CGAL).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "mesh/mesh_topology.h"

namespace inscribe::internal {

// Pairs (t1 < t2) of triangles of `mesh` that intersect other than along their shared
// vertices or edge, using exact predicates. Triangles with repeated corners are ignored.
// Returns nullopt when the mesh is not a polygon mesh CGAL can build (e.g. non-manifold
// vertices); the caller then reports the check as not done. Cost O(#T log #T) typically.
// The search runs in `slab_count` parallel parts (0: by the mesh's size and the thread count);
// the pairs do not depend on it.
std::optional<std::vector<std::pair<std::int32_t, std::int32_t>>> SelfIntersectingPairs(
    const Mesh& mesh, std::size_t slab_count = 0);

// Whether the shadows of `triangle` and of the convex hull of `other` (count 2: a segment, 3: a
// triangle) on the coordinate plane facing the triangle are strictly apart, with exact 2D
// orientations: when true, the two share no point. Used before CGAL's 3D test in
// SelfIntersectingPairs, where it decides most neighbouring pairs of nearly flat surfaces
// without CGAL's exact fallback.
bool ShadowsApart(const Vector3 triangle[3], const Vector3* other, int count);

// Whether the triangles with distinct corners form an oriented 2-manifold with boundary, the
// soup CGAL's polygon_soup_to_polygon_mesh needs: every edge in at most two of them, walked in
// opposite directions when in two, and the triangles around each vertex one fan (connected
// through shared edges). CGAL's is_polygon_soup_a_polygon_mesh's verdict, from sorted edge
// uses instead of a tree of edges (13 s against 0.4 s on 1.2 million triangles): O(#T log #T).
bool IsOrientedManifold(const Mesh& mesh);
// The same from the mesh's SortedEdgeUses and their GroupEdges.
bool IsOrientedManifold(const Mesh& mesh, const std::vector<EdgeUse>& uses,
                        const EdgeGroups& groups);

// Number of triangles whose corners are distinct but collinear (zero area), exact predicate;
// `first` receives the first such triangle or -1.
std::int64_t CountCollinearTriangles(const Mesh& mesh, std::int64_t* first);

}  // namespace inscribe::internal
