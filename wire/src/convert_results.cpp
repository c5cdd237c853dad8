// The proto <-> core mappings of queries and results: hierarchy volumes, distance tolerances,
// generation parameters and results, deformation results (declared in convert.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/wire/convert.h"

namespace inscribe::wire {

v1::HierarchyVolume VolumeToProto(HierarchyVolume volume) {
  return volume == HierarchyVolume::kRss ? v1::RSS : v1::SPHERE;
}

HierarchyVolume VolumeFromProto(v1::HierarchyVolume volume) {
  return volume == v1::RSS ? HierarchyVolume::kRss : HierarchyVolume::kSphere;
}

void ToleranceToProto(const DistanceRequest& tolerance, v1::DistanceTolerance* out) {
  out->set_abs_err(tolerance.abs_err);
  out->set_rel_err(tolerance.rel_err);
  if (tolerance.closer_than != std::numeric_limits<double>::infinity()) {
    out->set_closer_than(tolerance.closer_than);
  }
}

absl::StatusOr<DistanceRequest> ToleranceFromProto(const v1::DistanceTolerance& t) {
  DistanceRequest request;
  request.abs_err = t.abs_err();
  request.rel_err = t.rel_err();
  if (t.has_closer_than()) request.closer_than = t.closer_than();
  if (!(std::isfinite(request.abs_err) && request.abs_err >= 0.0 &&
        std::isfinite(request.rel_err) && request.rel_err >= 0.0) ||
      std::isnan(request.closer_than)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "tolerance: abs_err and rel_err must be finite and >= 0 and closer_than a number, got ",
        request.abs_err, ", ", request.rel_err, ", ", request.closer_than));
  }
  return request;
}

void GenerateRequestToProto(const std::string& mesh_sha256, const SphereSetParameters& p,
                            MeshRepair repair, v1::GenerateRequest* out) {
  const SphereSetParameters defaults;
  out->set_mesh_sha256(mesh_sha256);
  v1::GenerateParameters* wire = out->mutable_parameters();
  wire->Clear();
  // The wire has no "neither": core's default budget goes as a budget.
  if (p.voxel_size) {
    wire->set_voxel_size(*p.voxel_size);
  } else if (const std::optional<std::int64_t> budget = EffectiveMaxSpheres(p)) {
    wire->set_max_spheres(*budget);
    if (p.kind != SphereSetKind::kCover && p.selection != defaults.selection) {
      wire->set_selection(SphereSelectionName(p.selection));
    }
  }
  const MedialSphereOptions& m = p.medial;
  const MedialSphereOptions& d = defaults.medial;
  if (m.object_angle != d.object_angle) wire->set_object_angle(m.object_angle);
  wire->set_epsilon(m.epsilon);
  if (m.samples != d.samples) wire->set_samples(m.samples);
  wire->set_subdivide_boundary(m.subdivide_boundary);
  if (m.screen_samples != d.screen_samples) wire->set_screen_samples(m.screen_samples);
  if (m.corner_screen != d.corner_screen) wire->set_corner_screen(m.corner_screen);
  if (m.pair_angle_margin != d.pair_angle_margin) wire->set_pair_angle_margin(m.pair_angle_margin);
  wire->set_max_voxels(m.max_voxels);  // the caller's limit, which the server's caps
  wire->set_dilate(p.kind == SphereSetKind::kDilated);
  if (p.kind == SphereSetKind::kDilated && p.dilation.growth != defaults.dilation.growth) {
    wire->set_dilation_growth(p.dilation.growth);
  }
  wire->set_cover(p.kind == SphereSetKind::kCover);
  if (p.max_protrusion) wire->set_max_protrusion(*p.max_protrusion);
  if (p.kind == SphereSetKind::kCover && p.cover_resolution != defaults.cover_resolution) {
    wire->set_cover_resolution(p.cover_resolution);
  }
  if (p.evaluate && p.quality.surface_samples != defaults.quality.surface_samples) {
    wire->set_quality_samples(p.quality.surface_samples);
  }
  if (repair != RepairOptions().level) wire->set_repair(MeshRepairToProto(repair));
  out->set_skip_quality(!p.evaluate);
}

absl::StatusOr<SphereSetParameters> SphereSetParametersFromProto(const v1::GenerateRequest& request,
                                                                 std::int64_t max_voxels_limit) {
  const v1::GenerateParameters& wire = request.parameters();
  const bool by_size = wire.voxel_size() != 0.0, by_budget = wire.max_spheres() != 0;
  if (by_size + by_budget + wire.has_max_protrusion() != 1) {
    return absl::InvalidArgumentError(
        "parameters: set exactly one of voxel_size (> 0), max_spheres (> 0) and, for a cover, "
        "max_protrusion");
  }
  if (wire.dilate() && wire.cover()) {
    return absl::InvalidArgumentError(
        "parameters: dilate and cover exclude each other (a cover grows its own spheres)");
  }
  SphereSetParameters p;
  if (by_size) p.voxel_size = wire.voxel_size();
  if (by_budget) p.max_spheres = wire.max_spheres();
  if (wire.has_max_protrusion()) p.max_protrusion = wire.max_protrusion();
  if (wire.has_selection()) {
    if (!by_budget || wire.cover()) {
      return absl::InvalidArgumentError(
          "parameters: selection spends a sphere budget (max_spheres) of internal or dilated "
          "spheres; it means nothing with a voxel size or a cover");
    }
    absl::StatusOr<SphereSelection> selection = ParseSphereSelection(wire.selection());
    if (!selection.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameters.selection: ", selection.status().message()));
    }
    p.selection = *selection;
  }
  MedialSphereOptions& m = p.medial;
  // 0 means core's default for these three (proto3 scalars without presence).
  if (wire.object_angle() != 0.0) m.object_angle = wire.object_angle();
  m.epsilon = wire.epsilon();
  if (wire.samples() != 0) m.samples = wire.samples();
  m.subdivide_boundary = wire.subdivide_boundary();
  if (wire.has_screen_samples()) m.screen_samples = wire.screen_samples();
  if (wire.has_corner_screen()) m.corner_screen = wire.corner_screen();
  if (wire.has_pair_angle_margin()) m.pair_angle_margin = wire.pair_angle_margin();
  m.max_voxels =
      wire.max_voxels() > 0 ? std::min(wire.max_voxels(), max_voxels_limit) : max_voxels_limit;
  if (wire.max_voxels() < 0) m.max_voxels = wire.max_voxels();  // refused below
  p.kind = wire.cover()    ? SphereSetKind::kCover
           : wire.dilate() ? SphereSetKind::kDilated
                           : SphereSetKind::kInternal;
  if (wire.dilate() && wire.has_dilation_growth()) p.dilation.growth = wire.dilation_growth();
  if (wire.cover() && wire.has_cover_resolution()) p.cover_resolution = wire.cover_resolution();
  p.evaluate = !request.skip_quality();
  if (wire.has_quality_samples()) p.quality.surface_samples = wire.quality_samples();
  if (absl::Status s = CheckSphereSetParameters(p); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("parameters: ", s.message()));
  }
  return p;
}

void QualityOptionsToProto(const QualityOptions& options, v1::EvaluateRequest* out) {
  const QualityOptions defaults;
  out->clear_samples();
  if (options.surface_samples != defaults.surface_samples) {
    out->set_samples(options.surface_samples);
  }
  out->set_voxel_size(options.voxel_size);
  out->clear_coverage_tolerance();
  if (options.coverage_tolerance >= 0.0) out->set_coverage_tolerance(options.coverage_tolerance);
}

absl::StatusOr<QualityOptions> QualityOptionsFromProto(const v1::EvaluateRequest& request) {
  QualityOptions options;
  if (request.has_samples()) options.surface_samples = std::max<std::int64_t>(request.samples(), 0);
  options.voxel_size = request.voxel_size();
  if (request.has_coverage_tolerance()) {
    options.coverage_tolerance = request.coverage_tolerance();
    if (!(std::isfinite(options.coverage_tolerance) && options.coverage_tolerance >= 0.0)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "coverage_tolerance must be finite and >= 0, got ", options.coverage_tolerance));
    }
  }
  if (absl::Status s = CheckQualityOptions(options); !s.ok()) return s;
  return options;
}

namespace {

void StatsToProto(const MedialSphereStats& s, v1::GenerationStats* out) {
  out->set_grid_voxels(s.grid_voxels);
  out->set_visited_voxels(s.visited_voxels);
  out->set_boundary_voxels(s.boundary_voxels);
  out->set_screened_voxels(s.screened_voxels);
  out->set_crossing_pairs(s.crossing_pairs);
  out->set_searched_pairs(s.searched_pairs);
  out->set_candidates(s.candidates);
  out->set_closest_point_queries(s.closest_point_queries);
  out->set_seconds(s.seconds);
}

MedialSphereStats StatsFromProto(const v1::GenerationStats& s) {
  MedialSphereStats out;
  out.grid_voxels = s.grid_voxels();
  out.visited_voxels = s.visited_voxels();
  out.boundary_voxels = s.boundary_voxels();
  out.screened_voxels = s.screened_voxels();
  out.crossing_pairs = s.crossing_pairs();
  out.searched_pairs = s.searched_pairs();
  out.candidates = s.candidates();
  out.closest_point_queries = s.closest_point_queries();
  out.seconds = s.seconds();
  return out;
}

void DilationToProto(const DilationResult& d, v1::DilationStats* out) {
  out->set_v_points(d.v_points);
  out->set_edge_points(d.edge_points);
  out->set_degenerate(d.degenerate);
  out->set_grown(d.grown);
  out->set_max_growth(d.max_growth);
  out->set_seconds(d.seconds);
}

DilationResult DilationFromProto(const v1::DilationStats& d) {
  DilationResult out;
  out.v_points = d.v_points();
  out.edge_points = d.edge_points();
  out.degenerate = d.degenerate();
  out.grown = d.grown();
  out.max_growth = d.max_growth();
  out.seconds = d.seconds();
  return out;
}

v1::SphereSetKind KindToProto(SphereSetKind kind) {
  switch (kind) {
    case SphereSetKind::kDilated:
      return v1::SPHERE_SET_KIND_DILATED;
    case SphereSetKind::kCover:
      return v1::SPHERE_SET_KIND_COVER;
    case SphereSetKind::kInternal:
      break;
  }
  return v1::SPHERE_SET_KIND_INTERNAL;
}

// Results cached before kinds were recorded have none: a dilated one has its DilationStats.
SphereSetKind KindFromProto(const v1::GenerateResult& result) {
  switch (result.kind()) {
    case v1::SPHERE_SET_KIND_COVER:
      return SphereSetKind::kCover;
    case v1::SPHERE_SET_KIND_DILATED:
      return SphereSetKind::kDilated;
    default:
      return result.has_dilation() ? SphereSetKind::kDilated : SphereSetKind::kInternal;
  }
}

}  // namespace

void GeneratedSphereSetToProto(const GeneratedSphereSet& g, v1::GenerateResult* out) {
  SphereSetToProto(g.set, out->mutable_spheres());
  out->set_voxel_size(g.voxel_size);
  out->set_epsilon(g.epsilon);
  out->set_search_runs(g.runs);
  StatsToProto(g.stats, out->mutable_stats());
  if (g.dilation) DilationToProto(*g.dilation, out->mutable_dilation());
  if (g.quality) QualityReportToProto(*g.quality, out->mutable_quality());
  out->set_generation_seconds(g.generation_seconds);
  out->set_seconds(g.seconds);
  out->set_kind(KindToProto(g.kind));
  out->set_selection(SphereSelectionName(g.selection));
  out->set_pool_size(g.pool_size);
  out->set_covered_fraction(g.covered_fraction);
  if (g.cover) {
    v1::CoverStats* cover = out->mutable_cover();
    CoverCertificateToProto(g.cover->certificate, cover->mutable_certificate());
    cover->set_grown_spheres(g.cover->grown_spheres);
    cover->set_candidates(g.cover->candidates);
    cover->set_repair_rounds(g.cover->repair_rounds);
    cover->set_seconds(g.cover->seconds);
    cover->set_unused_reason(g.cover->unused_reason);
  }
}

absl::StatusOr<GeneratedSphereSet> GeneratedSphereSetFromProto(const v1::GenerateResult& result) {
  absl::StatusOr<SphereSet> set = SphereSetFromProto(result.spheres());
  if (!set.ok()) return set.status();
  GeneratedSphereSet g;
  g.set = *std::move(set);
  g.voxel_size = result.voxel_size();
  g.epsilon = result.epsilon();
  g.runs = result.search_runs();
  g.stats = StatsFromProto(result.stats());
  if (result.has_dilation()) g.dilation = DilationFromProto(result.dilation());
  if (result.has_quality()) g.quality = QualityReportFromProto(result.quality());
  g.generation_seconds = result.generation_seconds();
  g.seconds = result.seconds();
  g.kind = KindFromProto(result);
  if (!result.selection().empty()) {
    absl::StatusOr<SphereSelection> selection = ParseSphereSelection(result.selection());
    if (!selection.ok()) return selection.status();
    g.selection = *selection;
  }
  g.pool_size = result.pool_size();
  g.covered_fraction = result.covered_fraction();
  if (result.has_cover()) {
    absl::StatusOr<CoverCertificate> certificate =
        CoverCertificateFromProto(result.cover().certificate());
    if (!certificate.ok()) return certificate.status();
    GeneratedCover cover;
    cover.certificate = *std::move(certificate);
    cover.candidates = result.cover().candidates();
    cover.grown_spheres = result.cover().grown_spheres();
    cover.repair_rounds = result.cover().repair_rounds();
    cover.seconds = result.cover().seconds();
    cover.unused_reason = result.cover().unused_reason();
    g.cover = std::move(cover);
  }
  return g;
}

void DeformedSpheresToProto(const DeformedSpheres& moved, v1::UpdateDeformationResponse* out) {
  SphereSetToProto(moved.set, out->mutable_spheres());
  out->mutable_reference_index()->Assign(moved.reference_index.begin(),
                                         moved.reference_index.end());
  out->set_xi(moved.xi);
  out->set_max_protrusion(moved.max_protrusion);
  out->set_shrunk(moved.shrunk);
  out->set_dropped(moved.dropped);
  out->set_closest_point_queries(moved.closest_point_queries);
  out->set_max_shrink_steps(moved.max_shrink_steps);
  out->set_seconds(moved.seconds);
}

absl::StatusOr<DeformedSpheres> DeformedSpheresFromProto(
    const v1::UpdateDeformationResponse& response) {
  absl::StatusOr<SphereSet> set = SphereSetFromProto(response.spheres());
  if (!set.ok()) return set.status();
  if (static_cast<std::size_t>(response.reference_index_size()) != set->size()) {
    return absl::InvalidArgumentError(absl::StrCat("reference_index has ",
                                                   response.reference_index_size(), " entries for ",
                                                   set->size(), " spheres"));
  }
  DeformedSpheres moved;
  moved.set = *std::move(set);
  moved.reference_index.assign(response.reference_index().begin(),
                               response.reference_index().end());
  moved.xi = response.xi();
  moved.max_protrusion = response.max_protrusion();
  moved.shrunk = response.shrunk();
  moved.dropped = response.dropped();
  moved.closest_point_queries = response.closest_point_queries();
  moved.max_shrink_steps = response.max_shrink_steps();
  moved.seconds = response.seconds();
  return moved;
}

void DeformationBoundsToProto(const DeformationErrorBounds& bounds,
                              v1::UpdateDeformationResponse* out) {
  out->set_nerr_lower(bounds.nerr_lower);
  out->set_nerr_upper(bounds.nerr_upper);
  out->set_nerr_is_exact(bounds.exact);
  out->set_volume_mesh(bounds.volume_mesh);
  out->set_volume_union(bounds.volume_union);
  if (bounds.uniform_xi_holds) out->set_nerr_upper_uniform_xi(bounds.nerr_upper_uniform_xi);
  out->set_bounds_seconds(bounds.seconds);
}

DeformationErrorBounds DeformationBoundsFromProto(const v1::UpdateDeformationResponse& response) {
  DeformationErrorBounds bounds;
  bounds.nerr_lower = response.nerr_lower();
  bounds.nerr_upper = response.nerr_upper();
  bounds.exact = response.nerr_is_exact();
  bounds.volume_mesh = response.volume_mesh();
  bounds.volume_union = response.volume_union();
  bounds.uniform_xi_holds = response.has_nerr_upper_uniform_xi();
  bounds.nerr_upper_uniform_xi = bounds.uniform_xi_holds ? response.nerr_upper_uniform_xi()
                                                         : std::numeric_limits<double>::infinity();
  bounds.seconds = response.bounds_seconds();
  return bounds;
}

void CoverCertificateToProto(const CoverCertificate& c, v1::CoverCertificate* out) {
  out->set_certified(c.certified);
  out->set_delta(c.delta);
  out->set_resolution(c.resolution);
  out->set_cells(c.cells);
  out->set_cells_in_sphere(c.cells_in_sphere);
  out->set_cells_outside(c.cells_outside);
  out->set_failed_cells(c.failed_cells);
  if (c.uncovered_point) {
    for (int k = 0; k < 3; ++k) out->add_uncovered_point((*c.uncovered_point)[k]);
  }
  out->set_uncovered_depth(c.uncovered_depth);
  out->set_uncovered_gap(c.uncovered_gap);
  out->set_seconds(c.seconds);
  out->mutable_protrusions()->Assign(c.protrusions.begin(), c.protrusions.end());
  out->set_mesh_sha256(c.mesh_sha256);
  out->set_spheres_sha256(c.spheres_sha256);
}

absl::StatusOr<CoverCertificate> CoverCertificateFromProto(const v1::CoverCertificate& c) {
  if (c.uncovered_point_size() != 0 && c.uncovered_point_size() != 3) {
    return absl::InvalidArgumentError(absl::StrCat("certificate: uncovered_point has ",
                                                   c.uncovered_point_size(),
                                                   " numbers; expected 0 or 3"));
  }
  CoverCertificate out;
  out.certified = c.certified();
  out.delta = c.delta();
  out.resolution = c.resolution();
  out.cells = c.cells();
  out.cells_in_sphere = c.cells_in_sphere();
  out.cells_outside = c.cells_outside();
  out.failed_cells = c.failed_cells();
  if (c.uncovered_point_size() == 3) {
    out.uncovered_point = Vector3(c.uncovered_point(0), c.uncovered_point(1), c.uncovered_point(2));
  }
  out.uncovered_depth = c.uncovered_depth();
  out.uncovered_gap = c.uncovered_gap();
  out.seconds = c.seconds();
  for (int i = 0; i < c.protrusions_size(); ++i) {
    if (!std::isfinite(c.protrusions(i))) {
      return absl::InvalidArgumentError(
          absl::StrCat("certificate: protrusions[", i, "] (", c.protrusions(i), ") is not finite"));
    }
  }
  out.protrusions.assign(c.protrusions().begin(), c.protrusions().end());
  out.mesh_sha256 = c.mesh_sha256();
  out.spheres_sha256 = c.spheres_sha256();
  return out;
}

absl::StatusOr<CoverCertifyOptions> CoverCertifyOptionsFromProto(
    const v1::CertifyCoverRequest& request) {
  CoverCertifyOptions options;
  if (request.has_resolution()) {
    options.resolution = request.resolution();
  }
  // The failed cells are not sent: keep none.
  options.max_failures_kept = 0;
  if (absl::Status s = CheckCoverCertifyOptions(options); !s.ok()) return s;
  return options;
}

}  // namespace inscribe::wire
