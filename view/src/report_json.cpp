#include "inscribe/view/report_json.h"

namespace inscribe::view {

nlohmann::json MeshReportJson(const MeshReport& report, const std::string& sha256) {
  nlohmann::json issues = nlohmann::json::array();
  for (const MeshIssue& issue : report.issues) {
    issues.push_back({{"severity", SeverityName(issue.severity)},
                      {"code", issue.code},
                      {"message", issue.message},
                      {"count", issue.count}});
  }
  nlohmann::json j;
  j["mesh_sha256"] = sha256.empty() ? nlohmann::json(nullptr) : nlohmann::json(sha256);
  j["vertices"] = report.vertices;
  j["triangles"] = report.triangles;
  j["closed"] = report.closed();
  j["usable"] = report.usable();
  if (!report.usable()) j["error"] = report.first_error();
  j["volume"] = report.volume;
  j["bbox"] = {{"min", {report.bbox.min.x(), report.bbox.min.y(), report.bbox.min.z()}},
               {"max", {report.bbox.max.x(), report.bbox.max.y(), report.bbox.max.z()}},
               {"diagonal", report.bbox.diagonal()}};
  j["components"] = report.components;
  j["counts"] = {{"non_finite_vertices", report.non_finite_vertices},
                 {"out_of_range_indices", report.out_of_range_indices},
                 {"welded_vertices", report.welded_vertices},
                 {"weld_collapsed_triangles", report.weld_collapsed_triangles},
                 {"degenerate_triangles", report.degenerate_triangles},
                 {"duplicate_triangles", report.duplicate_triangles},
                 {"unreferenced_vertices", report.unreferenced_vertices},
                 {"border_edges", report.border_edges},
                 {"non_manifold_edges", report.non_manifold_edges},
                 {"non_manifold_vertices", report.non_manifold_vertices},
                 {"inconsistent_edges", report.inconsistent_edges},
                 {"flipped_triangles", report.flipped_triangles}};
  j["self_intersections"] = {{"checked", report.self_intersections_checked},
                             {"pairs", report.self_intersecting_pairs}};
  // What the repair changed: the hash, volume, bbox and self-intersections above are the
  // repaired mesh's; `geometry_repaired` says the solid is not the file's as given.
  nlohmann::json repair = {{"geometry_repaired", report.geometry_repaired()},
                           {"repairs", report.repairs()},
                           {"duplicate_triangles_removed", report.duplicate_triangles_removed},
                           {"double_walls_removed", report.double_walls_removed},
                           {"crack_weld_tolerance", report.crack_weld_tolerance},
                           {"crack_vertices_welded", report.crack_vertices_welded},
                           {"weld_moved_within", report.weld_moved_within},
                           {"holes_filled", report.holes_filled},
                           {"hole_triangles_added", report.hole_triangles_added},
                           {"wrapped", report.wrapped}};
  if (report.wrapped) {
    repair["wrap"] = {{"alpha", report.wrap_alpha},
                      {"offset", report.wrap_offset},
                      {"input_triangles", report.wrap_input_triangles},
                      {"triangles", report.wrap_triangles},
                      {"reach", report.wrap_reach}};
  }
  j["repair"] = std::move(repair);
  j["issues"] = std::move(issues);
  return j;
}

}  // namespace inscribe::view

namespace inscribe::view {

nlohmann::json QualityReportJson(const QualityReport& r) {
  nlohmann::json j;
  j["spheres"] = r.spheres;
  j["volume_mesh"] = r.volume_mesh;
  j["volume_union"] = r.volume_union;
  j["nerr"] = r.nerr;
  j["nerr_is_exact"] = r.nerr_is_exact;
  j["nerr_kind"] = r.nerr_is_exact ? "exact" : "lower_bound";
  j["protrusion_max"] = r.protrusion_max;
  j["protrusion_mean"] = r.protrusion_mean;
  j["protrusion_p95"] = r.protrusion_p95;
  j["protrusion_max_relative"] = r.bbox_diagonal > 0 ? r.protrusion_max / r.bbox_diagonal : 0.0;
  j["protruding_spheres"] = r.protruding_spheres;
  j["protrusion_tolerance"] = r.protrusion_tolerance;
  j["bbox_diagonal"] = r.bbox_diagonal;
  j["surface_samples"] = r.surface_samples;
  j["coverage"] = r.coverage;
  j["coverage_tolerance"] = r.coverage_tolerance;
  j["boundary_to_union_mean"] = r.boundary_to_union_mean;
  j["boundary_to_union_hausdorff"] = r.boundary_to_union_hausdorff;
  j["radius_min"] = r.radius_min;
  j["radius_max"] = r.radius_max;
  j["fat_up_to_voxel_size"] = r.fat_up_to_voxel_size;
  if (r.voxel_size > 0.0) {
    j["voxel_size"] = r.voxel_size;
    j["fat"] = r.fat;
    j["fraction_radius_over_sqrt3_sigma"] = r.fraction_radius_over_sqrt3_sigma;
  }
  j["evaluate_seconds"] = r.seconds;
  return j;
}

}  // namespace inscribe::view
