// Closed triangulations of URDF's <box> and <cylinder>, so that they can be spherized like any
// mesh. Both are centred on the origin of their own frame (the collision element's), in metres,
// outward oriented (counter-clockwise seen from outside) and pass ValidateMesh unchanged.
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

}  // namespace inscribe::robot
