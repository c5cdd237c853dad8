// Fast updates of a medial-sphere set when its mesh deforms (paper Section V): every sphere
// rides on its contact point to the deformed boundary and is shrunk until it sticks out less
// than a threshold, at a small fraction of the cost of generating the set again.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

// Which way a moved sphere's centre lies from its moved contact point A'.
enum class ContactDirection {
  // The paper's estimate, c' = A' + r N'(A'), with N' the inner normal interpolated at A' from
  // the deformed mesh's angle-weighted vertex normals, refined by what the reference knows: the
  // reference direction (c - A) / r is stored in a frame at A made of the interpolated normal
  // and the contact triangle's first edge, and read back in the same frame at A'. When the
  // reference direction equals the interpolated normal this is exactly the paper's formula;
  // when it does not (contacts in the middle of a flat triangle, whose direction is the face
  // normal, or on sharp edges) the difference is carried along, so a rigid motion moves every
  // sphere exactly, as it must.
  kCarriedFrame,
  // The paper's formula as printed: c' = A' + r N'(A'), whatever the reference direction was.
  kInterpolatedNormal,
};

struct DeformationOptions {
  // Algorithm 1's threshold xi (mesh units): no updated sphere protrudes xi or more, where a
  // sphere's protrusion is r - d and d the distance from its centre to the boundary, negative
  // when the centre is outside. 0 = 0.25% of the reference mesh's largest bounding-box extent,
  // the paper's choice (Fig. 5).
  double xi = 0.0;
  // Internal and tangent output: each sphere is returned as (c, d) after the shrinking, so its
  // radius is the distance from its centre to the deformed boundary and its contact the
  // nearest boundary point (Algorithm 1's last line as printed). A centre still outside after
  // the shrinking moves on towards the contact until it is inside; spheres whose centre never
  // gets inside are dropped (see DeformedSpheres::reference_index).
  bool strict = false;
  ContactDirection direction = ContactDirection::kCarriedFrame;
  // The BVH of the deforming boundary's oracle. Its inside test is always the exact winding
  // number (InsideTest::kExactWinding), whatever the reference's validation allowed: a deformed
  // frame may intersect itself where the reference did not, the pseudonormal test is wrong
  // there, and proving a frame free of self-intersections costs more than the exact test.
  BoundaryOracleBackend backend = BoundaryOracleBackend::kFlatBvh;
};

// INVALID_ARGUMENT naming the field for options SphereDeformer::Create refuses (xi not finite
// or negative).
absl::Status CheckDeformationOptions(const DeformationOptions& options);

struct DeformedSpheres {
  // The moved spheres, in the reference's order (less any dropped in strict mode). Contacts,
  // one per sphere: the moved contact A' (the reference's triangle and barycentrics), or in
  // strict mode the nearest point of the deformed boundary. Either way |c - contact| = r, so
  // the set can serve as the reference of a later update on the deformed mesh.
  SphereSet set;
  // For each sphere of `set`, its index in the reference set.
  std::vector<std::int32_t> reference_index;
  double xi = 0.0;              // the threshold used, mesh units
  double max_protrusion = 0.0;  // max over spheres of r - d (see xi); < xi, <= 0 when strict
  std::int64_t shrunk = 0;      // spheres Algorithm 1 made smaller
  std::int64_t dropped = 0;     // strict mode only: centre never got inside
  std::int64_t closest_point_queries = 0;
  int max_shrink_steps = 0;  // the most halvings any sphere needed
  double seconds = 0.0;      // wall time of Update: refit, moves, shrinking
};

// Updates a reference sphere set as its mesh deforms. Holds the reference (mesh, spheres and
// each sphere's direction in its contact frame) and one BoundaryOracle that each Update refits
// to the new vertex positions; the BVH is never rebuilt. Every Update starts from the
// reference, so errors do not accumulate over a sequence of frames.
//
// Not thread-safe: Update must not overlap another call. Internally parallel (TBB).
class SphereDeformer {
 public:
  // `reference`: a closed, outward-oriented mesh (as PrepareMesh returns it). `spheres`: one
  // contact per sphere (triangle of `reference` and barycentrics summing to 1), each sphere
  // tangent at its contact: |c - A| = r to within 1e-6 r, as GenerateMedialSpheres makes them.
  // INVALID_ARGUMENT, naming the sphere, otherwise. Cost: an oracle build, O(#T log #T).
  static absl::StatusOr<SphereDeformer> Create(Mesh reference, SphereSet spheres,
                                               const DeformationOptions& options = {});

  SphereDeformer(SphereDeformer&&) noexcept;
  SphereDeformer& operator=(SphereDeformer&&) noexcept;
  ~SphereDeformer();

  // The spheres for the reference's triangles on `deformed_vertices` (#V by 3, the reference's
  // vertex order). INVALID_ARGUMENT for a wrong vertex count, a non-finite coordinate, or
  // vertices on which the triangles enclose no positive volume (an inverted or collapsed
  // mesh); the deformer is then unchanged. Cost O(#V + #T) for the refit, plus per sphere one
  // closest-point query per halving (at most log2(r / xi) + 2).
  absl::StatusOr<DeformedSpheres> Update(const Vertices& deformed_vertices);

  // The boundary as of the last successful Update (the reference before the first).
  const BoundaryOracle& oracle() const;
  // The options, with xi resolved to mesh units.
  const DeformationOptions& options() const;
  const SphereSet& reference_spheres() const;

 private:
  struct Impl;
  explicit SphereDeformer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Bounds on the volumetric error of spheres approximating the solid bounded by `oracle`'s mesh,
// normalised by the solid's volume (paper Section V-B), from exact union volumes.
struct DeformationErrorBounds {
  double volume_mesh = 0.0;   // divergence theorem, mesh units cubed
  double volume_union = 0.0;  // vol(U), exact (UnionVolume)
  // vol(U^xi): the union of the balls (c_i, r_i - xi) with r_i > xi.
  double volume_union_shrunk = 0.0;
  // vol(U_in): the union of the balls (c_i, min(r_i, d_i)) whose centre is inside (d_i > 0
  // the distance to the boundary), each of them inside the solid.
  double volume_union_inner = 0.0;
  // Lemma 1: |vol(U) - vol(mesh)| / vol(mesh) <= nerr.
  double nerr_lower = 0.0;
  // Lemma 2's argument with U_in in place of U^xi: nerr <= (vol(mesh) - vol(U) + 2 (vol(U) -
  // vol(U_in))) / vol(mesh). Valid for any spheres (U_in lies in both U and the solid), and
  // never looser than nerr_upper_uniform_xi since U_in contains U^xi when every protrusion is
  // below xi.
  double nerr_upper = 0.0;
  // Lemma 2 as stated, with U^xi; a bound only when every sphere's protrusion is below xi
  // (uniform_xi_holds), +infinity otherwise.
  double nerr_upper_uniform_xi = 0.0;
  bool uniform_xi_holds = false;
  // Every sphere is inside the solid (d_i >= r_i): then U_in = U, nerr is exact and the two
  // bounds are equal (Lemma 1).
  bool exact = false;
  double seconds = 0.0;  // wall time: the distance queries and the three union volumes
};

// Errors: xi not finite or negative, a non-finite or negative sphere, a mesh enclosing no
// volume. Cost: #S closest-point queries plus three UnionVolume calls.
absl::StatusOr<DeformationErrorBounds> BoundDeformationError(const BoundaryOracle& oracle,
                                                             const std::vector<Sphere>& spheres,
                                                             double xi);

}  // namespace inscribe
