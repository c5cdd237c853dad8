// The page `inscribe view` writes: one self-contained HTML file showing a mesh and a sphere set
// with three.js, and the quality report with the paper's Fig. 7 histograms. Everything is
// inline (three.js, OrbitControls, the page's script and style, the data), so the page opens
// from disk with no network.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/view/signed_histogram.h"

namespace inscribe::view {

// What the panel shows besides the geometry. Lengths in mesh units, times in seconds.
struct ViewPageFacts {
  std::string title;         // panel heading and tab title
  std::string mesh_name;     // the mesh file's name
  std::string mesh_sha256;   // "sha256:<hex>" of the validated mesh
  std::string spheres_name;  // the sphere file's name
  QualityReport quality;     // EvaluateSpheres' report
  // Per sphere, in order: max(0, r + signed distance of the centre), how far it reaches
  // outside the mesh (as QualityReport's protrusion).
  std::vector<double> protrusion;
  SignedHistogram boundary_to_envelope;  // Fig. 7, col. 3
  SignedHistogram envelope_to_boundary;  // Fig. 7, col. 4
  double envelope_area = 0.0;            // EnvelopeDistanceResult::envelope_area
  double load_seconds = 0.0, evaluate_seconds = 0.0, envelope_seconds = 0.0;
};

// The data the page's script reads from <script type="application/json" id="inscribe-data">:
//   {title, mesh: {name, sha256, vertices: [x0, y0, z0, x1, ...], triangles: [i0, j0, k0, ...],
//    bbox: {min, max, diagonal}}, spheres: {name, count, xyzr: [x0, y0, z0, r0, ...],
//    protrusion: [...]}, report: QualityReportJson + envelope_area,
//    histograms: {boundary_to_envelope, envelope_to_boundary}: {edges, counts, samples, mean,
//    mean_absolute, min, max}, timing: {load, evaluate, envelope}}
// Coordinates and radii are rounded to 7 significant digits (float precision: what WebGL
// draws), protrusions to 4. `mesh` is the validated mesh (oriented outward). Cost O(#V + #T + n).
nlohmann::json ViewPageData(const Mesh& mesh, const std::vector<Sphere>& spheres,
                            const ViewPageFacts& facts);

// The page around `data` (ViewPageData). INTERNAL when an inlined file would end its element
// early (a script containing "</script", a licence containing "-->"): a build problem.
absl::StatusOr<std::string> ViewPageHtml(const nlohmann::json& data, const std::string& title);

}  // namespace inscribe::view
