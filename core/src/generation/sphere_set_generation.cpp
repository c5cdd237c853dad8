#include "inscribe/generation/sphere_set_generation.h"

#include <chrono>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The pipeline's last step, whatever the kind: the quality report when asked, and the time.
absl::StatusOr<GeneratedSphereSet> Evaluated(const Solid& solid,
                                             const SphereSetParameters& parameters,
                                             Clock::time_point start, GeneratedSphereSet out) {
  if (parameters.evaluate) {
    QualityOptions quality = parameters.quality;
    quality.voxel_size = out.voxel_size;
    absl::StatusOr<QualityReport> report = EvaluateSpheres(solid.oracle, out.set.spheres, quality);
    if (!report.ok()) {
      return absl::Status(report.status().code(),
                          absl::StrCat("evaluating the result: ", report.status().message()));
    }
    out.quality = *std::move(report);
  }
  out.seconds = SecondsSince(start);
  return out;
}

}  // namespace

const char* SphereSetKindName(SphereSetKind kind) {
  switch (kind) {
    case SphereSetKind::kDilated:
      return "dilated";
    case SphereSetKind::kCover:
      return "cover";
    case SphereSetKind::kInternal:
      break;
  }
  return "internal";
}

absl::StatusOr<SphereSetKind> ParseSphereSetKind(absl::string_view name) {
  for (const SphereSetKind kind :
       {SphereSetKind::kInternal, SphereSetKind::kDilated, SphereSetKind::kCover}) {
    if (name == SphereSetKindName(kind)) return kind;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("kind must be 'internal', 'dilated' or 'cover', got '", name, "'"));
}

CoverParameters CoverParametersOf(const SphereSetParameters& parameters) {
  CoverParameters cover;
  cover.max_spheres = parameters.max_spheres;
  cover.max_protrusion = parameters.max_protrusion;
  cover.certify.resolution = parameters.cover_resolution;
  return cover;
}

absl::Status CheckSphereSetParameters(const SphereSetParameters& p) {
  if (p.voxel_size && p.max_spheres) {
    return absl::InvalidArgumentError("give a voxel size or a sphere budget, not both");
  }
  const bool cover = p.kind == SphereSetKind::kCover;
  if (cover && p.voxel_size) {
    return absl::InvalidArgumentError(
        "a cover takes a sphere budget or a max_protrusion, not a voxel size");
  }
  if (!cover && p.max_protrusion) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_protrusion bounds a cover's delta; it means nothing for ",
                     SphereSetKindName(p.kind), " spheres"));
  }
  if (p.voxel_size && !(std::isfinite(*p.voxel_size) && *p.voxel_size > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("voxel size must be a positive finite number, got ", *p.voxel_size));
  }
  if (p.max_spheres && *p.max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("the sphere budget must be at least 1, got ", *p.max_spheres));
  }
  // One sphere per voxel (up to 8 per subdivided boundary voxel): a budget the finest grid
  // allowed cannot hold would refine to that grid, minutes of work, and still fall short.
  const double most_spheres =
      static_cast<double>(p.medial.max_voxels) * (p.medial.subdivide_boundary ? 8.0 : 1.0);
  if (!cover && p.max_spheres && static_cast<double>(*p.max_spheres) > most_spheres) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a budget of ", *p.max_spheres, " spheres (max_spheres) is more than a grid of at most ",
        p.medial.max_voxels, " voxels (max_voxels) can hold, one sphere per voxel",
        p.medial.subdivide_boundary ? " (8 in a subdivided boundary voxel)" : "",
        "; lower max_spheres or raise max_voxels"));
  }
  if (p.selection != SphereSelection::kPaper && p.selection != SphereSelection::kOptimised) {
    return absl::InvalidArgumentError(
        absl::StrCat("selection must be paper or optimised, got ", static_cast<int>(p.selection)));
  }
  if (absl::Status s = CheckMedialSphereOptions(p.medial, /*need_voxel_size=*/false); !s.ok()) {
    return s;
  }
  if (p.kind == SphereSetKind::kDilated) {
    if (absl::Status s = CheckDilationOptions(p.dilation); !s.ok()) return s;
  }
  if (cover) {
    if (absl::Status s = CheckCoverParameters(CoverParametersOf(p)); !s.ok()) return s;
  }
  if (p.evaluate) {
    if (absl::Status s = CheckQualityOptions(p.quality); !s.ok()) return s;
  }
  return absl::OkStatus();
}

std::optional<std::int64_t> EffectiveMaxSpheres(const SphereSetParameters& parameters) {
  if (parameters.max_spheres) return parameters.max_spheres;
  if (parameters.voxel_size || parameters.max_protrusion) return std::nullopt;
  return kDefaultMaxSpheres;
}

absl::StatusOr<GeneratedSphereSet> GenerateSphereSet(const Solid& solid,
                                                     const SphereSetParameters& parameters,
                                                     const GenerationControl& control) {
  const Clock::time_point start = Clock::now();
  if (absl::Status s = CheckSphereSetParameters(parameters); !s.ok()) return s;
  GeneratedSphereSet out;
  out.kind = parameters.kind;
  if (parameters.kind == SphereSetKind::kCover) {
    absl::StatusOr<GeneratedCover> cover =
        GenerateCover(solid, CoverParametersOf(parameters), control);
    if (!cover.ok()) return cover.status();
    out.set = std::move(cover->set);
    cover->set = {};
    out.cover = *std::move(cover);
    out.generation_seconds = SecondsSince(start);
    return Evaluated(solid, parameters, start, std::move(out));
  }
  MedialSphereResult medial;
  const std::optional<std::int64_t> budget = EffectiveMaxSpheres(parameters);
  if (budget && parameters.selection == SphereSelection::kOptimised) {
    OptimisedSphereOptions optimised;
    optimised.max_spheres = *budget;
    optimised.base = parameters.medial;
    absl::StatusOr<OptimisedSphereResult> chosen =
        GenerateOptimisedSpheres(solid.oracle, optimised, control);
    if (!chosen.ok()) return chosen.status();
    out.runs = chosen->runs;
    out.selection = SphereSelection::kOptimised;
    out.pool_size = chosen->pool_size;
    out.covered_fraction = chosen->selection.covered_fraction();
    medial = std::move(chosen->best);
  } else if (budget) {
    SphereBudgetOptions search;
    search.max_spheres = *budget;
    search.base = parameters.medial;
    absl::StatusOr<SphereBudgetResult> found =
        GenerateWithSphereBudget(solid.oracle, search, control);
    if (!found.ok()) return found.status();
    out.runs = found->runs;
    medial = std::move(found->best);
  } else {
    MedialSphereOptions options = parameters.medial;
    options.voxel_size = *parameters.voxel_size;
    absl::StatusOr<MedialSphereResult> run = GenerateMedialSpheres(solid.oracle, options, control);
    if (!run.ok()) return run.status();
    out.runs = 1;
    medial = *std::move(run);
  }
  out.generation_seconds = SecondsSince(start);
  out.voxel_size = medial.voxel_size;
  out.epsilon = medial.epsilon;
  out.stats = medial.stats;
  out.set = std::move(medial.set);

  // S_D+ (Section VI-A) replaces S_D from here on: it is what gets evaluated and returned.
  if (parameters.kind == SphereSetKind::kDilated) {
    absl::StatusOr<DilationResult> dilated =
        DilateSpheres(solid.oracle, out.set, parameters.dilation);
    if (!dilated.ok()) {
      return absl::Status(dilated.status().code(),
                          absl::StrCat("dilating the spheres: ", dilated.status().message()));
    }
    out.set = std::move(dilated->set);
    dilated->set = {};
    out.dilation = *std::move(dilated);
  }
  return Evaluated(solid, parameters, start, std::move(out));
}

}  // namespace inscribe
