#include "inscribe/view/view_report_html.h"

#include "inscribe/view/report_json.h"
#include "page_html.h"
#include "viewer_assets.h"

namespace inscribe::view {
namespace {

nlohmann::json HistogramJson(const SignedHistogram& h) {
  nlohmann::json edges = nlohmann::json::array();
  for (double e : h.edges) edges.push_back(RoundSignificant(e, 6));
  return {{"edges", std::move(edges)},
          {"counts", h.counts},
          {"samples", h.samples},
          {"mean", h.mean},
          {"mean_absolute", h.mean_absolute},
          {"min", h.min},
          {"max", h.max}};
}

}  // namespace

nlohmann::json ViewPageData(const Mesh& mesh, const std::vector<Sphere>& spheres,
                            const ViewPageFacts& facts) {
  std::vector<double> vertices;
  vertices.reserve(static_cast<std::size_t>(mesh.num_vertices()) * 3);
  for (std::int64_t v = 0; v < mesh.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) vertices.push_back(RoundSignificant(mesh.vertices(v, k), 7));
  }
  std::vector<std::int32_t> triangles(mesh.triangles.data(),
                                      mesh.triangles.data() + mesh.triangles.size());
  std::vector<double> xyzr, protrusion;
  xyzr.reserve(spheres.size() * 4);
  for (const Sphere& s : spheres) {
    for (int k = 0; k < 3; ++k) xyzr.push_back(RoundSignificant(s.center[k], 7));
    xyzr.push_back(RoundSignificant(s.radius, 7));
  }
  for (double p : facts.protrusion) protrusion.push_back(RoundSignificant(p, 4));
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);

  nlohmann::json report = QualityReportJson(facts.quality);
  report["envelope_area"] = facts.envelope_area;
  nlohmann::json data;
  data["title"] = facts.title;
  data["mesh"] = {{"name", facts.mesh_name},
                  {"sha256", facts.mesh_sha256},
                  {"vertices", std::move(vertices)},
                  {"triangles", std::move(triangles)},
                  {"bbox",
                   {{"min", {box.min.x(), box.min.y(), box.min.z()}},
                    {"max", {box.max.x(), box.max.y(), box.max.z()}},
                    {"diagonal", box.diagonal()}}}};
  data["spheres"] = {{"name", facts.spheres_name},
                     {"count", spheres.size()},
                     {"xyzr", std::move(xyzr)},
                     {"protrusion", std::move(protrusion)}};
  data["report"] = std::move(report);
  data["histograms"] = {{"boundary_to_envelope", HistogramJson(facts.boundary_to_envelope)},
                        {"envelope_to_boundary", HistogramJson(facts.envelope_to_boundary)}};
  data["timing"] = {{"load", facts.load_seconds},
                    {"evaluate", facts.evaluate_seconds},
                    {"envelope", facts.envelope_seconds}};
  return data;
}

absl::StatusOr<std::string> ViewPageHtml(const nlohmann::json& data, const std::string& title) {
  return SelfContainedPage(data, title, "view_page.js", ViewPageJs());
}

}  // namespace inscribe::view
