// JSON forms of core results, as the CLI prints them.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "inscribe/balls/sphere_quality.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::view {

// The `inscribe info --json` object: mesh_sha256, vertices, triangles, closed, usable,
// volume, bbox {min, max, diagonal}, counts {...}, issues [...].
nlohmann::json MeshReportJson(const MeshReport& report, const std::string& sha256);

// The quality report as a flat object: spheres, volume_mesh, volume_union, nerr,
// nerr_is_exact, nerr_kind ("exact" | "lower_bound"), protrusion_{max,mean,p95} (mesh units)
// and protrusion_max_relative (of the bbox diagonal), protruding_spheres, surface_samples,
// coverage, coverage_tolerance, boundary_to_union_{mean,hausdorff}, radius_{min,max},
// fat_up_to_voxel_size, and when the voxel size is known: voxel_size, fat,
// fraction_radius_over_sqrt3_sigma.
nlohmann::json QualityReportJson(const QualityReport& report);

}  // namespace inscribe::view
