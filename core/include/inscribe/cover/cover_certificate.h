// Certified covers: a proof that a solid lies inside a union of spheres, and a sound bound on
// how far the union reaches outside it.
//
// The proof is an octree over the solid's bounding cube. A cell is settled when one sphere
// contains it (a ball is convex, so it contains the cube when it contains the cube's farthest
// corner), or when it provably misses the solid (its centre is outside and farther from the
// boundary than the cell's half-diagonal). Other cells split in 8, down to a finest size; a
// finest cell still unsettled is a failure. Every cell corner is an exact dyadic number (the
// cube's side is a power of two and its origin a multiple of the finest side), so the cells
// tile the cube exactly, and each test carries a relative margin far above the rounding of the
// few operations it makes. Certified means: every point of the solid (boundary included) lies
// in some sphere.
//
// A certificate names what it proved: the solid (its mesh's hash) and the spheres (theirs), so
// that one read back from a file or sent by a client is used only for the spheres it was made
// for (CheckCoverCertificateBinding).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/solid/solid.h"

namespace inscribe {

struct CoverCertifyOptions {
  // Side of the finest cells, as a fraction of the largest side of the mesh's bounding box
  // (rounded down to a power-of-two division of the cube, at most 2^20 cells per side). A
  // sphere set that protrudes less than about this near the boundary cannot be certified.
  double resolution = 1.0 / 2048;
  // Failing cells kept in CoverCertificate::failures (all are counted).
  std::int64_t max_failures_kept = 1 << 20;
  // A cell whose centre is inside the solid and in no sphere already disproves the cover: stop
  // there rather than split it down to the finest cells (a set that misses a large part of
  // the solid is refused in milliseconds). Also: a first pass at 1/256 (when coarser than
  // `resolution`) whose witness, if it finds one, is the answer (its counts and resolution are
  // that pass's), so a set that is not a cover is not split to the finest cells along its
  // tangencies. Off for repairs, which grow a sphere around each failed cell and want them
  // small.
  bool stop_at_witness = true;
};

// One axis-aligned cube of the octree: [min, min + side] on each axis, exact dyadic numbers.
struct CoverCell {
  Vector3 min = Vector3::Zero();
  double side = 0.0;
};

struct CoverCertificate {
  // Every point of the solid lies in some sphere (a proof, see above).
  bool certified = false;
  // What was proved: Solid::sha256 (the validated mesh, "sha256:<64 hex>") and
  // FormatSha256(SpheresSha256(spheres)) of the spheres, in their order.
  std::string mesh_sha256;
  std::string spheres_sha256;
  // No point of any sphere lies farther than this outside the solid: the maximum over spheres
  // of radius - depth(centre) (depth: distance to the boundary, negative outside), at least 0,
  // rounded up. Holds whether or not the set is certified. Mesh units.
  double delta = 0.0;
  // Per sphere, in the set's order: radius - depth(centre) rounded up, a bound on how far
  // that sphere reaches outside the solid (negative for a sphere deep inside); delta is the
  // largest, or 0. Also what CoverCores takes. Mesh units.
  std::vector<double> protrusions;
  // Finest cell side used, mesh units.
  double resolution = 0.0;
  // The octree: cells examined, settled inside one sphere, settled outside the solid, and the
  // failed cells: finest cells left unsettled, and (with stop_at_witness) cells whose centre
  // is a point of the solid in no sphere (0 when certified).
  std::int64_t cells = 0, cells_in_sphere = 0, cells_outside = 0, failed_cells = 0;
  // The failed cells, sorted (coarse first, then x, y, z): the first
  // CoverCertifyOptions::max_failures_kept of them in that order when more failed.
  std::vector<CoverCell> failures;
  // A point of the solid in no sphere, when a failed cell's centre is one (the deepest such
  // centre): the proof that the set is not a cover. Its depth inside the solid
  // (0 on the boundary) and its distance to the nearest sphere.
  std::optional<Vector3> uncovered_point;
  double uncovered_depth = 0.0;
  double uncovered_gap = 0.0;
  double seconds = 0.0;
};

// The one rule for using a certificate that was not just computed (read from a file, sent by a
// client, read back from a cache): it must name `spheres` (their SpheresSha256) and, when
// `mesh_sha256` is not empty, that mesh (empty: the caller does not know the mesh, only the
// spheres are checked), and hold one protrusion per sphere. FAILED_PRECONDITION saying which
// fails and what to do: a certificate that names no spheres or no mesh, other spheres (edited
// after they were certified), another mesh, or too few or too many protrusions. Says nothing
// about `certified`. Cost O(#spheres).
absl::Status CheckCoverCertificateBinding(const CoverCertificate& certificate,
                                          const std::vector<Sphere>& spheres,
                                          absl::string_view mesh_sha256);

// OK, or INVALID_ARGUMENT for a resolution outside (0, 1] or a negative max_failures_kept.
absl::Status CheckCoverCertifyOptions(const CoverCertifyOptions& options);

// Certifies `spheres` (each passing CheckSphere) as a cover of `solid`. INVALID_ARGUMENT for a
// bad sphere or resolution (in (0, 1]); CANCELLED when control.cancel is set. Parallel (TBB)
// and deterministic: the verdict, the counts, the failures and the witness depend only on the
// input. Progress goes to control.on_progress in [0, 1]. The certificate names solid.sha256
// and the spheres.
absl::StatusOr<CoverCertificate> CertifyCover(const Solid& solid,
                                              const std::vector<Sphere>& spheres,
                                              const CoverCertifyOptions& options = {},
                                              const GenerationControl& control = {});

// CoverCertificate::protrusions alone: per sphere, radius - depth(centre) rounded up by a
// margin far above the rounding of the oracle's distance (relative to the mesh's largest
// coordinate). A centre within that margin of the boundary counts as outside. Spheres must
// pass CheckSphere. Parallel, O(N) oracle queries.
absl::StatusOr<std::vector<double>> SphereProtrusions(const Solid& solid,
                                                      const std::vector<Sphere>& spheres);

// CoverCertificate::delta alone: the largest of SphereProtrusions, or 0.
absl::StatusOr<double> SphereProtrusionBound(const Solid& solid,
                                             const std::vector<Sphere>& spheres);

// The cover's cores: for each sphere i of `cover` with radius_i > protrusions[i], the ball at
// its centre of radius radius_i - protrusions[i], at most the centre's depth, so inside the
// solid (a ball around an inside point no larger than its depth). In the cover's order, the
// others left out. INVALID_ARGUMENT unless there is one finite protrusion per sphere. O(N).
absl::StatusOr<std::vector<Sphere>> CoverCores(const std::vector<Sphere>& cover,
                                               const std::vector<double>& protrusions);

}  // namespace inscribe
