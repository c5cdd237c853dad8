// Closed triangulations of URDF's <box> and <cylinder> and of MJCF's capsules and ellipsoids, so
// that they can be spherized like any mesh. Both are centred on the origin of their own frame (the
// collision element's), in metres, outward oriented (counter-clockwise seen from outside) and pass
// ValidateMesh unchanged.
#pragma once

#include "inscribe/geometry/mesh.h"

namespace inscribe::robot {

// URDF's <box size="x y z">: the axis-aligned box [-x/2, x/2] x [-y/2, y/2] x [-z/2, z/2],
// exact. 8 vertices, 12 triangles. `size` > 0 per axis.
Mesh BoxMesh(const Vector3& size);

// Sides of the prism that stands in for a <cylinder>.
inline constexpr int kCylinderSides = 64;

// URDF's <cylinder radius length>: axis z, from -length/2 to length/2. Approximated by the
// prism over the regular `sides`-gon inscribed in the circle (one vertex on +x), capped by fans
// around the axis: 2 * sides + 2 vertices, 4 * sides triangles. The prism lies inside the true
// cylinder, short of it by at most radius * (1 - cos(pi / sides)) (0.12% of the radius for 64
// sides), so spheres inside the prism are inside the cylinder too. radius, length > 0,
// sides >= 3.
Mesh CylinderMesh(double radius, double length, int sides = kCylinderSides);

// Latitude bands of the hemispheres (capsules) and of the whole (ellipsoids) in the surfaces
// of revolution below: one band per pi / (2 * kQuarterBands) of latitude.
inline constexpr int kQuarterBands = 16;

// A capsule (MJCF's <geom type="capsule">): the cylinder of `radius` from z = -length/2 to
// length/2 with a hemisphere on each end. Every vertex lies on the true surface (rings of
// `sides` vertices, one on +x, at latitudes k pi / (2 quarter_bands) on each cap, the poles on
// the axis) and the solid is convex, so the mesh lies inside the capsule, short of it by at most
// radius * (1 - cos(pi / sides)) (0.12% for 64 sides): spheres inside the mesh are inside the
// capsule too. 2 * quarter_bands * sides + 2 vertices (length > 0). radius > 0, length >= 0, sides
// >= 3, quarter_bands >= 1.
Mesh CapsuleMesh(double radius, double length, int sides = kCylinderSides,
                 int quarter_bands = kQuarterBands);

// An ellipsoid with semi-axes `radii` along x, y, z (MJCF's <geom type="ellipsoid">): the
// sphere's triangulation as in CapsuleMesh (2 * quarter_bands latitude bands, `sides` vertices a
// ring) scaled per axis. The vertices lie on the ellipsoid and the solid is convex, so the mesh
// lies inside it. (2 * quarter_bands - 1) * sides + 2 vertices. radii > 0, sides >= 3,
// quarter_bands >= 1.
Mesh EllipsoidMesh(const Vector3& radii, int sides = kCylinderSides,
                   int quarter_bands = kQuarterBands);

}  // namespace inscribe::robot
