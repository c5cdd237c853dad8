// Multi-shell assemblies that stress the definition of a solid: cavities (in either
// orientation), more than 256 components, overlapping bodies, shells touching at one vertex,
// near-coincident shells, far-from-origin coordinates, thin plates and zero-area triangles.
// Each comes as given to PrepareSolid and as intended: the same shells, each oriented as the
// solid's definition orients it (a shell enclosed by an even number of other shells faces
// outward, one enclosed by an odd number is a cavity), so that the winding number of
// `intended` (support/winding_oracle.h) is nonzero exactly inside the solid that is meant.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "inscribe/geometry/mesh.h"

namespace inscribe::testing {

struct Assembly {
  std::string name;
  Mesh input;     // what the test hands to PrepareSolid: some shells face the wrong way
  Mesh intended;  // the same vertices and triangles, each shell oriented as meant
  // Regions where points deserve concentrating: cavities, overlaps, thin walls, touching
  // corners (mesh units, axis-aligned).
  std::vector<BoundingBox> focus;
};

// (a) Outer box [-1, 1]^3 with the cavity [-0.6, 0.6]^3, and 300 small cubes and tetrahedra
// (side 0.1) on a 10 x 10 x 3 grid above it: 302 components. `cavity_inward`: the cavity is
// given facing inward (as meant), else outward (validation must find it enclosed and flip
// it). Every seventh piece of debris is given inside out either way.
Assembly HollowBoxWithDebris(bool cavity_inward);
// (b) Boxes [0, 1]^3 and [0.5, 1.5] x [0.3, 1.3] x [0.2, 1.2] overlapping (the second given
// inside out), and a tetrahedron in the negative octant sharing the first box's corner vertex
// (0, 0, 0), the same vertex index: a non-manifold vertex and a self-intersection.
Assembly OverlapWithTouchingTetrahedron();
// (c) Box [-2, 2]^3, cavity [-1.5, 1.5]^3, box [-1, 1]^3 inside it, cavity [-0.5, 0.5]^3 inside
// that. `given_inverted`: every shell given inside out, else every shell given outward.
Assembly NestedShells(bool given_inverted);
// (d) Two unit boxes, the second moved by 1e-9 along (1, 1, 1): overlapping, parallel faces
// 1e-9 apart.
Assembly OffsetTwinBoxes();
// (d) The unit box with the cavity [1e-9, 1 - 1e-9]^3 (walls 1e-9 thick), given outward.
Assembly HairlineHollowBox();
// (b) The unit box and a tetrahedron poking out of it through its face x = 1: corners
// (0.3, 0.5, 0.5) and (0.5, 0.3, 0.5) inside the box, (1.4, 0.6, 0.4) and (1.4, 0.5, 0.8)
// outside. They overlap, so neither encloses the other: both face outward (their union), the
// tetrahedron given inside out.
Assembly TetrahedronPokingOutOfABox();
// (e) `assembly` with every vertex moved by `offset` (focus regions too).
Assembly TranslatedAssembly(const Assembly& assembly, const Vector3& offset);
// (f) The plate [0, 1] x [0, 1] x [0, 1e-3].
Assembly ThinPlate();
// (g) The unit box with five edges (three face diagonals, two box edges) split at an exactly
// representable point of the edge by a zero-area triangle: closed and edge-manifold, with
// five collinear triangles.
Assembly BoxWithCollinearTriangles();
// (g) The box [0.5, 1.5]^3 and a tetrahedron (sides about 0.6) whose corners are coplanar to
// within rounding (volume -1.8e-17, from fuzz_assembly): exact predicates find no zero-area
// triangle and no self-intersection, yet its two sheets lie closer than rounding apart.
Assembly SliverTetrahedronBesideABox();
// (h) Four overlapping icospheres (level 2, 320 triangles each), the second given inside out.
Assembly OverlappingIcospheres();

// Points in the assembly's bounding box, expanded by a tenth of its diagonal: `uniform` spread
// over it, `focused` spread over the focus regions (round robin), and `near_wall` at
// triangles of `intended` (chosen by area) moved along the normal by +-10^-u times the
// diagonal, u uniform in [1, 9]. #P by 3, P = uniform + focused + near_wall.
Vertices AssemblyPoints(const Assembly& assembly, int uniform, int focused, int near_wall,
                        std::uint64_t seed);

// Points spread through each ball (centre, and `per_ball` - 1 uniform in the ball), #P by 3.
Vertices PointsInBalls(const std::vector<Vector3>& centres, const std::vector<double>& radii,
                       int per_ball, std::uint64_t seed);

// Points on the triangles of `mesh`, chosen by area then uniformly in the triangle, plus every
// vertex: the boundary belongs to the solid. #P by 3, P = samples + #V.
Vertices BoundaryPoints(const Mesh& mesh, int samples, std::uint64_t seed);

}  // namespace inscribe::testing
