// The generation pipeline, in one place: choose sigma (or search it for a sphere budget), make
// the medial spheres (Section III), optionally dilate them (Section VI-A) or grow them into a
// certified cover (sphere_cover.h), then evaluate them (Section IV). The CLI, the server's
// store, robot links and the bindings all call GenerateSphereSet; the parameters carry every
// default and are validated here.
#pragma once

#include <cstdint>
#include <optional>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/cover/sphere_cover.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/sphere_dilation.h"
#include "inscribe/medial/sphere_selection.h"
#include "inscribe/solid/solid.h"

namespace inscribe {

// How a budget is spent when the caller does not say.
inline constexpr SphereSelection kDefaultSphereSelection = SphereSelection::kOptimised;

// What a generated set is, relative to its solid.
enum class SphereSetKind {
  // S_D: medial spheres inside the solid, each tangent to it, with their contacts.
  kInternal,
  // S_D+ (Section VI-A): grown to cover more of the boundary; they protrude, have no contacts,
  // and nerr is a lower bound.
  kDilated,
  // A certified cover (sphere_cover.h): holds the whole solid, reaches at most the
  // certificate's delta outside it; no contacts.
  kCover,
};

// "internal", "dilated", "cover": the name sphere files and the CLI use.
const char* SphereSetKindName(SphereSetKind kind);
// The kind SphereSetKindName names; INVALID_ARGUMENT listing the three names otherwise.
absl::StatusOr<SphereSetKind> ParseSphereSetKind(absl::string_view name);

struct SphereSetParameters {
  SphereSetKind kind = SphereSetKind::kInternal;
  // At most one of the two: sigma (mesh units, > 0), or the finest grid giving at most N
  // spheres (> 0). Neither: a budget of kDefaultMaxSpheres (for a cover without
  // max_protrusion too). A cover takes no voxel size.
  std::optional<double> voxel_size;
  std::optional<std::int64_t> max_spheres;
  // How a budget is spent (internal and dilated sets): the paper's finest grid within it, or
  // the optimised choice from a finer grid's pool (sphere_selection.h). A voxel size always
  // means the paper's one sphere per voxel; covers choose their own balls.
  SphereSelection selection = kDefaultSphereSelection;
  // Everything else about the medial spheres (object angle, epsilon, samples, screens,
  // boundary subdivision, the voxel limit); its voxel_size is ignored (see above). Covers
  // choose from balls of their own (sphere_cover.h) and ignore these.
  MedialSphereOptions medial;
  // kDilated: how much the spheres grow.
  DilationOptions dilation;
  // kCover: delta at most this many mesh units with the fewest spheres (finite, > 0), instead
  // of a sphere budget (CoverParameters::max_protrusion).
  std::optional<double> max_protrusion;
  // kCover: the certificate's finest cell side, as a fraction of the largest side of the
  // mesh's bounding box, in (0, 1] (CoverCertifyOptions::resolution).
  double cover_resolution = CoverCertifyOptions{}.resolution;
  // Evaluate the result (exact union volume, surface sampling); `quality.voxel_size` is
  // filled in from the run.
  bool evaluate = true;
  QualityOptions quality;
};

// OK, or INVALID_ARGUMENT naming the first bad field as SphereSetParameters spells it
// ("object_angle must lie in (0, pi) radians, got 4"). O(1).
absl::Status CheckSphereSetParameters(const SphereSetParameters& parameters);

// The budget GenerateSphereSet uses: max_spheres, else kDefaultMaxSpheres when neither a voxel
// size nor (for a cover) max_protrusion is given, else none.
std::optional<std::int64_t> EffectiveMaxSpheres(const SphereSetParameters& parameters);

// The cover's parameters of `parameters` (max_spheres, max_protrusion, the certificate's
// resolution; core's defaults for the rest). O(1).
CoverParameters CoverParametersOf(const SphereSetParameters& parameters);

struct GeneratedSphereSet {
  SphereSetKind kind = SphereSetKind::kInternal;
  SphereSet set;  // S_D with contacts, else (dilated, cover) without
  // sigma used (the search's choice for a paper budget, the pool's for an optimised one); 0 for
  // a cover.
  double voxel_size = 0.0;
  // The selection that spent the budget; kPaper for a fixed voxel size and for covers.
  SphereSelection selection = SphereSelection::kPaper;
  // Optimised selection: the pool's medial spheres and the sample points covered (of those in
  // the pool's union); 0 otherwise.
  std::int64_t pool_size = 0;
  double covered_fraction = 0.0;
  // The medial-sphere run that made an internal or dilated set: epsilon used (mesh units, the
  // default resolved), runs (1 for a fixed sigma) and the run's figures. A cover's internal
  // set is GenerateCover's own: 0 runs and empty figures.
  double epsilon = 0.0;
  int runs = 0;
  MedialSphereStats stats;
  // When dilated: the dilation's figures (its `set` is left empty: the result is `set`).
  std::optional<DilationResult> dilation;
  // When a cover: its certificate (certified) and figures (its `set` is left empty).
  std::optional<GeneratedCover> cover;
  std::optional<QualityReport> quality;  // when parameters.evaluate
  double generation_seconds = 0.0;  // the medial spheres (every run of the search), or the cover
  double seconds = 0.0;             // everything: generation, dilation, evaluation
};

// Runs the pipeline on `solid`. Deterministic: the same solid and parameters give the same set
// bit for bit. `control` reports progress of the generation and cancels it (CANCELLED).
// Errors: INVALID_ARGUMENT from CheckSphereSetParameters or for a grid over the voxel limit;
// RESOURCE_EXHAUSTED when no grid fits the budget; the dilation's, the cover's
// (GenerateCover) and the evaluation's errors.
absl::StatusOr<GeneratedSphereSet> GenerateSphereSet(const Solid& solid,
                                                     const SphereSetParameters& parameters,
                                                     const GenerationControl& control = {});

}  // namespace inscribe
