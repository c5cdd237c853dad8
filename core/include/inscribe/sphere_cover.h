// Cover sets: spheres that provably contain the whole solid (cover_certificate.h), grown from
// the paper's internal medial spheres.
//
// GenerateCover makes the internal set S_D for the budget, then grows spheres, never moves
// them: first each boundary sample and mesh vertex outside the union is given to the sphere
// that needs the least growth to reach it, then each cell the certificate could not settle to
// the sphere that needs the least growth to contain it, and certifies again. A cell the
// repair grew a sphere around is inside it, so the second certificate passes; the result is
// always certified. delta is then about the largest gap between S_D and the boundary, plus at
// most one finest cell's diagonal.
#pragma once

#include <cstdint>
#include <optional>

#include "absl/status/statusor.h"
#include "inscribe/cover_certificate.h"
#include "inscribe/medial_spheres.h"
#include "inscribe/solid.h"
#include "inscribe/sphere.h"

namespace inscribe {

struct CoverParameters {
  // The two modes, at most one set: at most N spheres with the smallest delta reached (> 0),
  // or delta at most D mesh units with the fewest spheres (finite, > 0). Neither: at most
  // kDefaultMaxSpheres spheres.
  std::optional<std::int64_t> max_spheres;
  std::optional<double> max_protrusion;
  // The internal set's medial options (object angle, samples, ...); core's defaults.
  MedialSphereOptions medial;
  // Boundary points drawn (uniformly by area, fixed seed) to grow the spheres before the first
  // certificate; every mesh vertex is used too. 0..100,000,000.
  std::int64_t growth_samples = 200'000;
  // The certificate's settings (its finest cell size bounds how much a repair overshoots).
  CoverCertifyOptions certify;
};

// OK, or INVALID_ARGUMENT naming the first bad field. O(1).
absl::Status CheckCoverParameters(const CoverParameters& parameters);

struct GeneratedCover {
  SphereSet set;                   // the cover (no contacts: its spheres touch nothing)
  CoverCertificate certificate;    // certified; delta is the cover's protrusion bound
  double voxel_size = 0.0;         // of the internal set it grew from, mesh units
  std::int64_t grown_spheres = 0;  // spheres whose radius grew
  int repair_rounds = 0;           // certificates that failed before the one that passed
  double seconds = 0.0;            // all of it, the internal set included
};

// A certified cover of `solid` (see above). INVALID_ARGUMENT for bad parameters, CANCELLED
// when control.cancel is set, FAILED_PRECONDITION when the solid has no volume to cover.
// Deterministic and parallel (TBB); progress goes to control.on_progress in [0, 1].
absl::StatusOr<GeneratedCover> GenerateCover(const Solid& solid, const CoverParameters& parameters,
                                             const GenerationControl& control = {});

}  // namespace inscribe
