// The generation pipeline, in one place: choose sigma (or search it for a sphere budget), make
// the medial spheres (Section III), optionally dilate them (Section VI-A), then evaluate them
// (Section IV). The CLI, the server's store, robot links and the bindings all call
// GenerateSphereSet; the parameters carry every default and are validated here.
#pragma once

#include <cstdint>
#include <optional>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/medial_spheres.h"
#include "inscribe/solid.h"
#include "inscribe/sphere.h"
#include "inscribe/sphere_dilation.h"
#include "inscribe/sphere_quality.h"

namespace inscribe {

// The sphere budget used when neither a voxel size nor a budget is given.
inline constexpr std::int64_t kDefaultMaxSpheres = 500;

struct SphereSetParameters {
  // At most one of the two: sigma (mesh units, > 0), or the finest grid giving at most N
  // spheres (> 0). Neither: a budget of kDefaultMaxSpheres.
  std::optional<double> voxel_size;
  std::optional<std::int64_t> max_spheres;
  // Everything else about the medial spheres (object angle, epsilon, samples, screens,
  // boundary subdivision, the voxel limit); its voxel_size is ignored (see above).
  MedialSphereOptions medial;
  // Grow the spheres to cover more of the boundary (S_D+): they then protrude, lose their
  // contacts, and nerr becomes a lower bound.
  bool dilate = false;
  DilationOptions dilation;
  // Evaluate the result (exact union volume, surface sampling); `quality.voxel_size` is
  // filled in from the run.
  bool evaluate = true;
  QualityOptions quality;
};

// OK, or INVALID_ARGUMENT naming the first bad field as SphereSetParameters spells it
// ("object_angle must lie in (0, pi) radians, got 4"). O(1).
absl::Status CheckSphereSetParameters(const SphereSetParameters& parameters);

// The budget GenerateSphereSet uses: max_spheres, else kDefaultMaxSpheres when no voxel size
// is given, else none.
std::optional<std::int64_t> EffectiveMaxSpheres(const SphereSetParameters& parameters);

struct GeneratedSphereSet {
  SphereSet set;            // S_D with contacts, or S_D+ (no contacts) when dilated
  double voxel_size = 0.0;  // sigma used (the search's choice for a budget)
  double epsilon = 0.0;     // epsilon used, mesh units (the default resolved)
  int runs = 0;             // medial-sphere runs (1 for a fixed sigma)
  MedialSphereStats stats;  // of the run that made the set
  // When dilated: the dilation's figures (its `set` is left empty: the result is `set`).
  std::optional<DilationResult> dilation;
  std::optional<QualityReport> quality;  // when parameters.evaluate
  double generation_seconds = 0.0;       // the medial spheres (every run of the search)
  double seconds = 0.0;                  // everything: generation, dilation, evaluation
};

// Runs the pipeline on `solid`. Deterministic: the same solid and parameters give the same set
// bit for bit. `control` reports progress of the generation and cancels it (CANCELLED).
// Errors: INVALID_ARGUMENT from CheckSphereSetParameters or for a grid over the voxel limit;
// RESOURCE_EXHAUSTED when no grid fits the budget; the dilation's and evaluation's errors.
absl::StatusOr<GeneratedSphereSet> GenerateSphereSet(const Solid& solid,
                                                     const SphereSetParameters& parameters,
                                                     const GenerationControl& control = {});

}  // namespace inscribe
