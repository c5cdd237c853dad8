// Private: closing the holes (border loops) of an open triangle mesh with CGAL, for validation.
#pragma once

#include <cstdint>
#include <string>

#include "inscribe/geometry/mesh.h"

namespace inscribe::internal {

// Caps on the work, so that hostile input cannot hang the caller. Every cap is on counts, never
// on time, so that the same mesh always gets the same result. Figures measured on this
// project's 2-core machine (RelWithDebInfo).
struct HoleFillingLimits {
  // A loop with more border edges is left open.
  std::int64_t max_hole_edges = 10'000;
  // Beyond this many border edges in all, no loop is attempted.
  std::int64_t max_total_hole_edges = 100'000;
  // Loops that are not near planar get CGAL's search among the faces of the 3D Delaunay
  // triangulation of their vertices, up to this size only: loops that zigzag cost it O(n^2)
  // time and memory (a 1,000-edge zigzag: 1.2 s, 200 MB; 3,000 edges: 23 s, 1.8 GB).
  std::int64_t max_spatial_hole_edges = 1'000;
  // When that search finds nothing, CGAL's exhaustive search (O(n^3) time, O(n^2) memory;
  // 1.5 s at 400 edges) is tried on loops up to this size.
  std::int64_t max_exhaustive_hole_edges = 400;
  // Both searches together, over all loops, in units of their cost bound: 8 n^2 per 3D
  // search, n^3 / 6 per exhaustive one (about 0.1 us each: spending the whole budget on
  // zigzag loops of 300 to 1,000 edges took 1.7 to 2.9 s).
  std::int64_t max_search_work = 30'000'000;
};

struct HoleFilling {
  // #P by 3 new triangles, indices into the input's vertices (no vertex is added), oriented
  // like the triangles around each hole. Only the loops that were filled contribute.
  Triangles patch;
  std::int64_t holes = 0;                // border loops found
  std::int64_t border_edges = 0;         // edges in all loops
  std::int64_t holes_filled = 0;         // loops closed by `patch`
  std::int64_t filled_border_edges = 0;  // edges of the loops closed by `patch`
  std::int64_t holes_left_open = 0;      // holes - holes_filled
  // True when no loop was tried: `failure` is about the whole border.
  bool refused = false;
  // Why holes were left open, one line (naming the first loop left open unless `refused`);
  // "" when none was.
  std::string failure;
};

// Fills every border loop of `mesh` with triangles between the loop's own vertices (no vertex
// is added), with CGAL's triangulate_hole: a loop that is near planar and projects to a simple
// polygon gets the constrained Delaunay triangulation of that polygon (O(n log n), a patch
// that cannot fold over itself); any other gets Liepa's minimum-weight triangulation (the
// smallest largest dihedral angle, then the smallest area) searched among the faces of the
// loop's 3D Delaunay triangulation and, for short loops, exhaustively. The patch never
// reuses an edge of the mesh nor adds a degenerate triangle; it is not tested against the
// rest of the surface (the caller's self-intersection test sees it).
//
// Requires edge-manifold `mesh` whose triangles are consistently oriented (the caller checks
// both). Nothing is filled (`refused`) when a vertex lies on the border more than once, when
// CGAL cannot build the mesh as a halfedge surface (a vertex joins several fans) or when the
// border is longer than `limits` allow; single loops beyond the limits, or for which CGAL
// finds no triangulation, are left open while others are filled. Triangles with a repeated
// corner are ignored. Cost O(#T log #T) plus the loops' own, bounded by `limits`.
HoleFilling FillHoles(const Mesh& mesh, const HoleFillingLimits& limits = {});

}  // namespace inscribe::internal
