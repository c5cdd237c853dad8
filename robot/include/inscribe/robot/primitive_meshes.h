// Closed triangulations of URDF's <box> and <cylinder> and of MJCF's capsules and ellipsoids, so
// that they can be spherized like any mesh. All are centred on the origin of their own frame (the
// collision element's), in metres, outward oriented (counter-clockwise seen from outside) and pass
// ValidateMesh unchanged. The curved ones come in two fits: inside the true shape (for internal
// sets: a sphere inside the mesh is inside the shape) or enclosing it (for covers: a certified
// cover of the mesh holds the whole shape), each within PrimitiveExcess of the shape.
#pragma once

#include "inscribe/geometry/mesh.h"

namespace inscribe::robot {

// Which side of a curved primitive its triangulation lies on.
enum class PrimitiveFit {
  kInside,     // every vertex on the true surface: the (convex) mesh lies inside the shape
  kEnclosing,  // every face plane outside the shape: the mesh holds the shape
};

// The relative margin by which enclosing meshes are grown beyond their exact construction, so
// that the rounding of the vertices and of the element's transform (well under 1e-12 of the
// shape's size for any origin within 1e3 sizes) cannot bring a face inside the true shape.
inline constexpr double kEnclosingMargin = 1e-9;

// URDF's <box size="x y z">: the axis-aligned box [-x/2, x/2] x [-y/2, y/2] x [-z/2, z/2],
// exact. 8 vertices, 12 triangles. `size` > 0 per axis.
Mesh BoxMesh(const Vector3& size);

// Sides of the prism that stands in for a <cylinder>.
inline constexpr int kCylinderSides = 64;

// URDF's <cylinder radius length>: axis z, from -length/2 to length/2. Approximated by the
// prism over a regular `sides`-gon (one vertex on +x), capped by fans around the axis:
// 2 * sides + 2 vertices, 4 * sides triangles. kInside: the polygon is inscribed in the circle,
// so the prism lies inside the cylinder, short of it by at most radius * (1 - cos(pi / sides))
// (0.12% of the radius for 64 sides). kEnclosing: the polygon's sides touch the circle (its
// vertices at radius / cos(pi / sides), grown by kEnclosingMargin), so the prism holds the
// cylinder. radius, length > 0, sides >= 3.
Mesh CylinderMesh(double radius, double length, int sides = kCylinderSides,
                  PrimitiveFit fit = PrimitiveFit::kInside);

// Latitude bands of the hemispheres (capsules) and of the whole (ellipsoids) in the surfaces
// of revolution below: one band per pi / (2 * kQuarterBands) of latitude.
inline constexpr int kQuarterBands = 16;

// A capsule (MJCF's <geom type="capsule">): the cylinder of `radius` from z = -length/2 to
// length/2 with a hemisphere on each end. kInside: every vertex lies on the true surface (rings
// of `sides` vertices, one on +x, at latitudes k pi / (2 quarter_bands) on each cap, the poles on
// the axis) and the solid is convex, so the mesh lies inside the capsule, short of it by at most
// radius * (1 - cos(pi / sides)) (0.12% for 64 sides). kEnclosing: the same mesh for the radius
// grown by EnclosingScale (every face plane of the sphere's triangulation then lies at least
// `radius` from the centre, so it holds the ball; split at the equator and stretched along z it
// holds the capsule, which is the ball swept along the axis). 2 * quarter_bands * sides + 2
// vertices (length > 0). radius > 0, length >= 0, sides >= 3, quarter_bands >= 1.
Mesh CapsuleMesh(double radius, double length, int sides = kCylinderSides,
                 int quarter_bands = kQuarterBands, PrimitiveFit fit = PrimitiveFit::kInside);

// An ellipsoid with semi-axes `radii` along x, y, z (MJCF's <geom type="ellipsoid">): the
// sphere's triangulation as in CapsuleMesh (2 * quarter_bands latitude bands, `sides` vertices a
// ring) scaled per axis. The vertices lie on the ellipsoid and the solid is convex, so the mesh
// lies inside it. kEnclosing: the unit sphere's enclosing mesh scaled per axis (an affine map
// keeps the ball inside it). (2 * quarter_bands - 1) * sides + 2 vertices. radii > 0, sides >= 3,
// quarter_bands >= 1.
Mesh EllipsoidMesh(const Vector3& radii, int sides = kCylinderSides,
                   int quarter_bands = kQuarterBands, PrimitiveFit fit = PrimitiveFit::kInside);

// The factor by which the unit sphere's inside triangulation (CapsuleMesh(1, 0, sides,
// quarter_bands)) is grown so that every face plane lies at least 1 from the centre: 1 / the
// smallest distance from the centre to a face's plane, times 1 + kEnclosingMargin. O(#faces).
double EnclosingScale(int sides = kCylinderSides, int quarter_bands = kQuarterBands);

// How far the mesh of `fit` may lie from the true shape's surface: for kInside, the largest
// distance of the shape's surface from the mesh; for kEnclosing, of the mesh from the shape.
// A cover certified on the enclosing mesh protrudes beyond the true shape by at most its delta
// plus this. 0 for boxes. O(#faces) for the curved shapes.
double CylinderExcess(double radius, PrimitiveFit fit, int sides = kCylinderSides);
double CapsuleExcess(double radius, PrimitiveFit fit, int sides = kCylinderSides,
                     int quarter_bands = kQuarterBands);
double EllipsoidExcess(const Vector3& radii, PrimitiveFit fit, int sides = kCylinderSides,
                       int quarter_bands = kQuarterBands);

}  // namespace inscribe::robot
