// The union of a set of balls: its dual complex (Edelsbrunner 1995, "The union of balls and
// its dual shape") and its exact volume (paper Section IV-B).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

// The dual complex of a union of balls: the nerve of the decomposition of the union by the
// power diagram (weights r^2). Simplex (i0, ..., ik) is present when the balls' cells restricted
// to the union, cell(b) ∩ b, have a common point; equivalently, it is the alpha complex at
// alpha = 0 of the regular triangulation of the weighted centres. Every simplex is a simplex of
// that triangulation, so the complex is embedded: no two triangles or tetrahedra overlap.
//
// All entries are indices into the input ball array. Each tuple is sorted ascending and each
// list is sorted lexicographically, so equal input gives an identical value.
struct DualComplex {
  // Balls whose restricted cell is non-empty, i.e. that show on the union's boundary or own
  // part of its interior.
  std::vector<std::int32_t> vertices;
  // Pairs, triples and quadruples of balls whose restricted cells meet. For every edge the two
  // spheres meet in a circle (or touch); for every triangle the three spheres share two points
  // (or touch in one); for every tetrahedron the point of equal power to all four lies in all
  // four balls.
  std::vector<std::array<std::int32_t, 2>> edges;
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<std::array<std::int32_t, 4>> tetrahedra;
  // The other input balls: hidden in the regular triangulation (empty power cell), with an
  // empty restricted cell, or exact duplicates of a ball with a lower index. Each is contained
  // in the union of the others, so dropping all of them leaves the union unchanged. Sorted.
  std::vector<std::int32_t> redundant;

  std::size_t num_simplices() const {
    return vertices.size() + edges.size() + triangles.size() + tetrahedra.size();
  }
};

// Dual complex of `balls` (centres in mesh frame, radii in mesh units). Built from CGAL's
// Regular_triangulation_3 (exact predicates, symbolic perturbation for degenerate input such
// as co-spherical or coplanar centres; from 2,048 balls inserted in parallel on the TBB pool),
// classified at alpha = 0 with Fixed_alpha_shape_3's rules and exact predicates in one pass
// over its cells (in parallel too). The regular triangulation with symbolic perturbation is
// unique, so the result does not depend on the thread count or the insertion order. Empty
// input gives an empty complex.
//
// Errors: INVALID_ARGUMENT naming the first bad ball (non-finite centre or radius, radius <= 0,
// a coordinate or radius above 1e150) or for more than 2^31 - 1 balls; INTERNAL with CGAL's
// message if CGAL throws.
// Cost: O(n log n) expected for well-spread balls (the regular triangulation's size).
absl::StatusOr<DualComplex> ComputeDualComplex(const std::vector<Sphere>& balls);

// Volume of the union of `balls`, in mesh units cubed, by the short inclusion-exclusion
// formula over the dual complex (Edelsbrunner 1995):
//   vol = sum_vertices vol(b_i) - sum_edges vol(b_i ∩ b_j) + sum_triangles vol(b_i ∩ b_j ∩ b_k)
//         - sum_tetrahedra vol(b_i ∩ b_j ∩ b_k ∩ b_l),
// every term in closed form (no sampling, no quadrature). The angle terms that a tetrahedron
// shares with its faces cancel exactly against theirs and are left out of both, so a triangle
// with two tetrahedra of the complex on it costs no trigonometry. Terms are computed relative
// to one of their balls' centres (no loss from a large common offset), in parallel, and
// summed in long double in the complex's order, so the bits do not depend on the thread
// count; the
// tests find agreement with an independent quadrature to about 1e-14 relative, including
// degenerate (co-spherical, coplanar) input. Empty input gives 0.
//
// Errors: as ComputeDualComplex. Cost: ComputeDualComplex plus O(#simplices).
absl::StatusOr<double> UnionVolume(const std::vector<Sphere>& balls);

// The same sum over a complex the caller already has (e.g. from ComputeDualComplex(balls) for
// dilation). `complex` must be the dual complex of these very balls; anything else gives a
// meaningless number. Errors: INVALID_ARGUMENT for an invalid ball, or a simplex with an index
// out of range or indices not strictly increasing. Cost O(#simplices).
absl::StatusOr<double> UnionVolume(const std::vector<Sphere>& balls, const DualComplex& complex);

}  // namespace inscribe
