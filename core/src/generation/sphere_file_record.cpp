#include "inscribe/generation/sphere_file_record.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <variant>

#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

// The value named `name`, or nullptr.
const ScalarValue* Find(const NamedValues& stats, const char* name) {
  for (const auto& [key, value] : stats) {
    if (key == name) return &value;
  }
  return nullptr;
}

// `value`, stat `name`, as a T (an int64 stat also reads as a double), or INVALID_ARGUMENT.
template <typename T>
absl::StatusOr<T> As(const ScalarValue& value, const char* name) {
  if (const T* held = std::get_if<T>(&value)) return *held;
  if constexpr (std::is_same_v<T, double>) {
    if (const std::int64_t* whole = std::get_if<std::int64_t>(&value)) {
      return static_cast<double>(*whole);
    }
  }
  return absl::InvalidArgumentError(absl::StrCat("stats.", name, " has the wrong type"));
}

// The value named `name` as a T, or INVALID_ARGUMENT when it is missing or of another type.
template <typename T>
absl::StatusOr<T> Stat(const NamedValues& stats, const char* name) {
  const ScalarValue* value = Find(stats, name);
  if (value == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat("a cover file needs stats.", name));
  }
  return As<T>(*value, name);
}

// The string named `name`, "" when the file has none (a certificate that names nothing, which
// CheckCoverCertificateBinding refuses), or INVALID_ARGUMENT for another type.
absl::StatusOr<std::string> OptionalString(const NamedValues& stats, const char* name) {
  const ScalarValue* value = Find(stats, name);
  if (value == nullptr) return std::string();
  return As<std::string>(*value, name);
}

}  // namespace

NamedValues CoverCertificateStats(const CoverCertificate& c) {
  return {{"delta", c.delta},
          {"certified", c.certified},
          {"certificate_resolution", c.resolution},
          {"certificate_cells", c.cells},
          {"cells_in_sphere", c.cells_in_sphere},
          {"cells_outside", c.cells_outside},
          {"failed_cells", c.failed_cells},
          {"certify_seconds", c.seconds},
          {"certified_mesh_sha256", c.mesh_sha256},
          {"certified_spheres_sha256", c.spheres_sha256}};
}

std::string RecordedKind(const SphereFile& file) {
  for (const auto& [key, value] : file.params) {
    if (key != kKindParam) continue;
    if (const std::string* kind = std::get_if<std::string>(&value)) return *kind;
  }
  return "";
}

absl::StatusOr<std::optional<CoverCertificate>> RecordedCoverCertificate(const SphereFile& file) {
  if (RecordedKind(file) != SphereSetKindName(SphereSetKind::kCover)) return std::nullopt;
  CoverCertificate c;
  absl::StatusOr<bool> certified = Stat<bool>(file.stats, "certified");
  absl::StatusOr<double> delta = Stat<double>(file.stats, "delta");
  absl::StatusOr<double> resolution = Stat<double>(file.stats, "certificate_resolution");
  absl::StatusOr<std::int64_t> cells = Stat<std::int64_t>(file.stats, "certificate_cells");
  absl::StatusOr<std::int64_t> in_sphere = Stat<std::int64_t>(file.stats, "cells_in_sphere");
  absl::StatusOr<std::int64_t> outside = Stat<std::int64_t>(file.stats, "cells_outside");
  absl::StatusOr<std::int64_t> failed = Stat<std::int64_t>(file.stats, "failed_cells");
  absl::StatusOr<std::string> mesh = OptionalString(file.stats, "certified_mesh_sha256");
  absl::StatusOr<std::string> spheres = OptionalString(file.stats, "certified_spheres_sha256");
  for (const absl::Status& s :
       {certified.status(), delta.status(), resolution.status(), cells.status(), in_sphere.status(),
        outside.status(), failed.status(), mesh.status(), spheres.status()}) {
    if (!s.ok()) return s;
  }
  c.certified = *certified;
  c.delta = *delta;
  c.resolution = *resolution;
  c.cells = *cells;
  c.cells_in_sphere = *in_sphere;
  c.cells_outside = *outside;
  c.failed_cells = *failed;
  c.protrusions = file.protrusions;
  c.mesh_sha256 = *std::move(mesh);
  c.spheres_sha256 = *std::move(spheres);
  return c;
}

absl::StatusOr<std::optional<CoverCertificate>> UsableCoverCertificate(
    const SphereFile& file, const std::string& path, absl::string_view mesh_sha256) {
  absl::StatusOr<std::optional<CoverCertificate>> recorded = RecordedCoverCertificate(file);
  if (!recorded.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", recorded.status().message()));
  }
  if (!recorded->has_value()) return std::nullopt;
  if (absl::Status bound = CheckCoverCertificateBinding(**recorded, file.set.spheres, mesh_sha256);
      !bound.ok()) {
    return absl::FailedPreconditionError(absl::StrCat(path, ": ", bound.message()));
  }
  if (!(*recorded)->certified) {
    return absl::FailedPreconditionError(
        absl::StrCat(path, " records a certificate that does not certify it"));
  }
  return recorded;
}

NamedValues QualityFigures(const QualityReport& quality) {
  return {
      {"volume_mesh", quality.volume_mesh},
      {"volume_union", quality.volume_union},
      {"nerr", quality.nerr},
      {"nerr_is_exact", quality.nerr_is_exact},
      {"protrusion_max", quality.protrusion_max},
      {"coverage", quality.coverage},
      {"boundary_to_union_hausdorff", quality.boundary_to_union_hausdorff},
      {"surface_samples", quality.surface_samples},
      {"fat", quality.fat},
  };
}

NamedValues DilationFigures(const DilationResult& dilation) {
  return {{"v_points", dilation.v_points},
          {"edge_points", dilation.edge_points},
          {"grown", dilation.grown},
          {"max_growth", dilation.max_growth},
          {"dilation_seconds", dilation.seconds}};
}

NamedValues CoverFigures(const GeneratedCover& cover) {
  NamedValues stats = CoverCertificateStats(cover.certificate);
  stats.emplace_back("grown_spheres", cover.grown_spheres);
  stats.emplace_back("cover_candidates", cover.candidates);
  stats.emplace_back("repair_rounds", static_cast<std::int64_t>(cover.repair_rounds));
  if (!cover.unused_reason.empty()) stats.emplace_back("unused_reason", cover.unused_reason);
  return stats;
}

namespace {

// How far the repair moved the surface from the input triangles, when it has a bound: the
// wrap's reach, or the tolerance vertices were welded within. nullopt when nothing moved or
// holes were filled (a patch has no bound to the input).
std::optional<double> SurfaceMovedByRepair(const MeshReport& mesh) {
  if (mesh.holes_filled > 0) return std::nullopt;
  const double moved = mesh.wrapped ? mesh.wrap_reach : mesh.weld_moved_within;
  if (!(moved > 0.0)) return std::nullopt;
  return moved;
}

}  // namespace

std::optional<double> CoverDeltaOverInput(double delta, const MeshReport& mesh) {
  const std::optional<double> moved = SurfaceMovedByRepair(mesh);
  if (!moved) return std::nullopt;
  return std::nextafter(delta + *moved, std::numeric_limits<double>::infinity());
}

std::optional<double> InternalProtrusionOverInput(const MeshReport& mesh) {
  return SurfaceMovedByRepair(mesh);
}

SphereFile GenerationSphereFile(const SphereSetParameters& p, const GeneratedSphereSet& r,
                                const std::string& mesh_sha256, const MeshReport& mesh) {
  // A cover's internal set is the cover generator's own: no epsilon, runs or voxel counts.
  const bool medial_run = r.kind != SphereSetKind::kCover;
  SphereFile file;
  file.set = r.set;
  file.mesh_sha256 = mesh_sha256;
  file.params = {
      {kKindParam, std::string(SphereSetKindName(r.kind))},
      {"voxel_size", r.voxel_size},
      {"object_angle", p.medial.object_angle},
  };
  if (medial_run) file.params.emplace_back("epsilon", r.epsilon);
  NamedValues medial = {
      {"samples", static_cast<std::int64_t>(p.medial.samples)},
      {"screen_samples", static_cast<std::int64_t>(p.medial.screen_samples)},
      {"pair_angle_margin", p.medial.pair_angle_margin},
      {"corner_screen", p.medial.corner_screen},
      {"subdivide_boundary", p.medial.subdivide_boundary},
  };
  for (auto& param : medial) file.params.push_back(std::move(param));
  if (const std::optional<std::int64_t> budget = EffectiveMaxSpheres(p)) {
    file.params.emplace_back("max_spheres", *budget);
    if (medial_run) {
      file.params.emplace_back("selection", std::string(SphereSelectionName(r.selection)));
    }
  }
  if (r.kind == SphereSetKind::kDilated) {
    file.params.emplace_back("dilation_growth", p.dilation.growth);
  }
  if (r.kind == SphereSetKind::kCover) {
    if (p.max_protrusion) file.params.emplace_back("max_protrusion", *p.max_protrusion);
    file.params.emplace_back("cover_resolution", p.cover_resolution);
  }
  if (mesh.geometry_repaired()) file.params.emplace_back("mesh_repairs", mesh.repairs());
  if (mesh.wrapped) {
    file.params.emplace_back("mesh_wrap_alpha", mesh.wrap_alpha);
    file.params.emplace_back("mesh_wrap_offset", mesh.wrap_offset);
  }

  file.stats = {{"seconds", r.generation_seconds}};
  if (medial_run) file.stats.emplace_back("search_runs", static_cast<std::int64_t>(r.runs));
  if (r.selection == SphereSelection::kOptimised) {
    file.stats.emplace_back("pool_size", r.pool_size);
    file.stats.emplace_back("covered_fraction", r.covered_fraction);
  }
  NamedValues figures = r.quality ? QualityFigures(*r.quality) : NamedValues();
  if (medial_run) {
    figures.emplace_back("visited_voxels", r.stats.visited_voxels);
    figures.emplace_back("closest_point_queries", r.stats.closest_point_queries);
  }
  if (r.dilation) {
    for (auto& figure : DilationFigures(*r.dilation)) figures.push_back(std::move(figure));
  }
  if (r.cover) {
    file.protrusions = r.cover->certificate.protrusions;
    for (auto& figure : CoverFigures(*r.cover)) figures.push_back(std::move(figure));
    if (const std::optional<double> over = CoverDeltaOverInput(r.cover->certificate.delta, mesh)) {
      figures.emplace_back("delta_input", *over);
    }
  }
  if (r.kind == SphereSetKind::kInternal) {
    if (const std::optional<double> over = InternalProtrusionOverInput(mesh)) {
      figures.emplace_back("protrusion_input", *over);
    }
  }
  if (mesh.wrapped) figures.emplace_back("mesh_wrap_reach", mesh.wrap_reach);
  for (auto& figure : figures) file.stats.push_back(std::move(figure));
  return file;
}

}  // namespace inscribe
