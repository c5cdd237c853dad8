#include "inscribe/view/view_report_html.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "inscribe/view/report_json.h"
#include "viewer_assets.h"

namespace inscribe::view {
namespace {

// x rounded to `digits` significant decimal digits, as the double whose shortest form (which
// nlohmann::json writes) has at most that many digits.
double RoundSignificant(double x, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, x);
  return std::strtod(text, nullptr);
}

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

// `text` as HTML text or attribute value: markup characters escaped, and invalid UTF-8 (a
// file name's bytes) replaced by U+FFFD as in the data element.
std::string EscapeHtml(const std::string& text) {
  const std::string valid =
      nlohmann::json::parse(
          nlohmann::json(text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace))
          .get<std::string>();
  return absl::StrReplaceAll(
      valid, {{"&", "&amp;"}, {"<", "&lt;"}, {">", "&gt;"}, {"\"", "&quot;"}, {"'", "&#39;"}});
}

// Whether `text`, inlined in a raw-text element <tag> (script or style), would end it early:
// the HTML parser closes the element at the first "</tag" whatever the case. In a script,
// "<!--" could also switch the parser into its escaped states, where "</script" is no longer
// the only way out; neither occurs in the files inlined here.
bool EndsElementEarly(absl::string_view text, absl::string_view tag) {
  const std::string lower = absl::AsciiStrToLower(text);
  return absl::StrContains(lower, absl::StrCat("</", tag)) ||
         (tag == "script" && absl::StrContains(lower, "<!--"));
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
  for (const auto& [name, script] :
       {std::pair{"three.min.js", ThreeJs()}, std::pair{"OrbitControls.js", OrbitControlsJs()},
        std::pair{"view_page.js", ViewPageJs()}}) {
    if (EndsElementEarly(script, "script")) {
      return absl::InternalError(
          absl::StrCat(name, " contains </script or <!--: it cannot be inlined in the page"));
    }
  }
  if (EndsElementEarly(ViewPageCss(), "style")) {
    return absl::InternalError("view_page.css contains </style: it cannot be inlined");
  }
  if (absl::StrContains(ThreeJsLicense(), "--")) {
    return absl::InternalError("three's licence contains --: it cannot go in an HTML comment");
  }
  // '<' only occurs inside JSON strings, where \u003c means the same: nothing in the data can
  // close the script element. Invalid UTF-8 (in a file name) becomes U+FFFD.
  const std::string json = absl::StrReplaceAll(
      data.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), {{"<", "\\u003c"}});
  std::string html;
  html.reserve(ThreeJs().size() + OrbitControlsJs().size() + json.size() + 64 * 1024);
  absl::StrAppend(&html,
                  "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                  "<meta name=\"generator\" content=\"inscribe view\">\n<title>",
                  EscapeHtml(title), " - inscribe view</title>\n");
  absl::StrAppend(&html,
                  "<!--\nThis page inlines three.js 0.147.0 (build/three.min.js and "
                  "examples/js/controls/OrbitControls.js of the npm package three), "
                  "distributed under the following licence:\n\n",
                  ThreeJsLicense(), "\n-->\n");
  absl::StrAppend(&html, "<style>\n", ViewPageCss(), "</style>\n</head>\n<body>\n",
                  "<aside id=\"panel\"></aside>\n<main id=\"viewport\"></main>\n",
                  "<pre id=\"error\" hidden></pre>\n");
  absl::StrAppend(&html, "<script type=\"application/json\" id=\"inscribe-data\">", json,
                  "</script>\n");
  absl::StrAppend(&html, "<script>\n", ThreeJs(), "\n</script>\n");
  absl::StrAppend(&html, "<script>\n", OrbitControlsJs(), "\n</script>\n");
  absl::StrAppend(&html, "<script>\n", ViewPageJs(), "\n</script>\n</body>\n</html>\n");
  return html;
}

}  // namespace inscribe::view
