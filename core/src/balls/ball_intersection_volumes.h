// Private: closed-form volumes of the intersection of 1, 2, 3 and 4 balls, the terms of the
// inclusion-exclusion over a dual complex (union_volume.cpp). Units: mesh units cubed.
#pragma once

#include "inscribe/geometry/sphere.h"

namespace inscribe::internal {

// vol(b), 4/3 pi r^3.
double BallVolume(const Sphere& b);

// vol(a ∩ b) in every configuration: disjoint or touching (0), overlapping (lens: two caps),
// nested (the smaller ball), equal.
double TwoBallIntersectionVolume(const Sphere& a, const Sphere& b);

// vol(a ∩ b ∩ c) for balls with non-collinear centres whose three spheres share two points
// y ± h n (h >= 0): the configuration of every triangle of a dual complex, where the power
// edge meets the union. Right wherever those two points lie, also when the point y is outside
// the triangle of centres. If the spheres share no point (h^2 < 0, only by rounding for a dual
// complex triangle) h is taken as 0, which is the limit.
//
// `angle_weight` scales the terms that are angles of the three spheres' arrangement (the
// corner angles eps and the half arcs gamma, see the .cpp): 1 gives the volume (clamped at
// 0); the inclusion-exclusion passes 1 - k/2 for a triangle with k tetrahedra of the complex
// on it, because each of those tetrahedra's FourBallVolumeWithoutFaceAngles leaves out the
// same angles with half the weight and the opposite sign. Cost: 6 atan2 plus O(1) arithmetic,
// no atan2 at weight 0.
double ThreeBallIntersectionVolume(const Sphere& a, const Sphere& b, const Sphere& c,
                                   double angle_weight = 1.0);

// vol(a ∩ b ∩ c ∩ d) for balls with non-coplanar centres whose power point (equal power to all
// four) lies in all four balls (the configuration of every tetrahedron of a dual complex),
// less the terms that are angles of its four faces' three-ball arrangements (their corner
// angles and half arcs); ThreeBallIntersectionVolume's angle_weight accounts for them. What
// is left: the balls' full spheres, the dihedral angles, the planar triangles and the sines
// of the arcs. Cost: 6 atan2 plus O(1) arithmetic.
double FourBallVolumeWithoutFaceAngles(const Sphere& a, const Sphere& b, const Sphere& c,
                                       const Sphere& d);

}  // namespace inscribe::internal
