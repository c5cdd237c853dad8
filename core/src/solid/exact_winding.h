// Private: the winding number of a closed, consistently oriented triangle surface around a
// point, decided with exact predicates (CGAL's filtered orientations on the mesh's own doubles).
#pragma once

#include "inscribe/geometry/mesh.h"

namespace inscribe::internal {

// What XRayCrossing returns when the query point lies on the closed triangle.
inline constexpr int kOnTriangle = 2;

// How the ray from p along +x crosses triangle (a, b, c), with the ray's origin perturbed
// symbolically to p + (0, e, e^2) for an infinitesimal e > 0 (Simulation of Simplicity), so
// that it never meets an edge or vertex, and rays through shared edges or vertices count every
// sheet exactly once: +1 when it crosses where the triangle's normal (b - a) x (c - a) points
// along +x, -1 where it points against, 0 when it misses (triangles parallel to x, or of zero
// area, are never crossed), kOnTriangle when p itself lies on the closed triangle. Summed over
// a closed oriented surface, the crossings give its winding number around the perturbed point,
// which equals the winding number around p whenever p is off the surface. Exact for any finite
// doubles. Cost: a few comparisons for a triangle whose box the ray misses, else up to four
// filtered orientation predicates.
int XRayCrossing(const Vector3& p, const Vector3& a, const Vector3& b, const Vector3& c);

}  // namespace inscribe::internal
