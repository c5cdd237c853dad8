// Private: the last rung of the repair ladder (MeshRepair::kWrap), for ValidateMesh: CGAL's 3D
// alpha wrap of a triangle soup, and the checks that make "the wrap encloses the input" a
// proof rather than a promise of the library.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe::internal {

// CGAL::alpha_wrap_3 of every triangle of `soup` with three distinct corners (alpha and offset
// in mesh units, > 0): a closed, outward-oriented 2-manifold. INVALID_ARGUMENT when the soup
// has no such triangle; INTERNAL when CGAL's result is empty. Cost grows with the soup's area
// over offset^2 and alpha's inverse square (see docs/benchmarks/mesh-repair.md).
absl::StatusOr<Mesh> AlphaWrap(const Mesh& soup, double alpha, double offset);

// "" when every triangle of `input` lies in the interior of the solid `wrap` bounds (a closed,
// oriented mesh): no input triangle (or, for a zero-area one, the segment or point it spans)
// meets a triangle of the wrap, by exact predicates, and every input vertex a triangle uses
// has a winding number other than zero with respect to the wrap and lies on none of its
// triangles (exact X-ray test). Otherwise a one-line reason naming the first failure. Cost
// O((#T_input + #T_wrap) log) plus the pairs of overlapping boxes.
std::string CheckWrapEncloses(const Mesh& wrap, const Mesh& input);

// An upper bound on the distance from any point of `wrap`'s triangles to the nearest triangle
// of `input` (mesh units). The distance to one input triangle is convex, so over a wrap
// triangle it is at most its largest value at the corners; the bound of a wrap triangle is the
// least of those over the input triangles nearest to its corners and centroid (closest points
// over a BVH; padded for rounding). A triangle whose bound exceeds 1.25 times the largest
// corner distance (which the wrap attains: a lower bound on the answer) is split in four, four
// levels deep at most. Parallel (TBB).
double WrapReachBound(const Mesh& wrap, const Mesh& input);

}  // namespace inscribe::internal
