#include "report_json.h"

namespace inscribe::cli {

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
  j["issues"] = std::move(issues);
  return j;
}

}  // namespace inscribe::cli
