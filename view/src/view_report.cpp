#include "inscribe/view/view_report.h"

#include <algorithm>
#include <chrono>
#include <utility>

#include "inscribe/balls/sphere_quality.h"
#include "inscribe/distance/envelope_distances.h"
#include "inscribe/view/signed_histogram.h"
#include "inscribe/view/view_report_html.h"

namespace inscribe::view {
namespace {

// Bins per histogram: Fig. 7's resolution, fine enough to see both tails.
constexpr int kHistogramBins = 60;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

absl::StatusOr<std::string> MakeViewReportPage(const Solid& solid,
                                               const std::vector<Sphere>& spheres,
                                               const ViewReportOptions& options) {
  const auto evaluate_start = std::chrono::steady_clock::now();
  QualityOptions quality;
  quality.surface_samples = options.samples;
  quality.seed = options.seed;
  quality.voxel_size = options.voxel_size;
  absl::StatusOr<QualityReport> report = EvaluateSpheres(solid.oracle, spheres, quality);
  if (!report.ok()) return report.status();
  std::vector<double> protrusion = SphereProtrusions(solid.oracle, spheres);
  const double evaluate_seconds = SecondsSince(evaluate_start);

  EnvelopeDistanceRequest request;
  request.boundary_samples = options.samples;
  request.envelope_samples = options.samples;
  request.seed = options.seed;
  absl::StatusOr<EnvelopeDistanceResult> envelope =
      ComputeEnvelopeDistances(solid.oracle, spheres, request);
  if (!envelope.ok()) return envelope.status();

  ViewPageFacts facts;
  facts.title = options.title;
  facts.mesh_name = options.mesh_name;
  facts.spheres_name = options.spheres_name;
  facts.mesh_sha256 = solid.sha256;
  facts.quality = *report;
  facts.protrusion = std::move(protrusion);
  // Histograms at least 1e-9 of the diagonal wide: the rounding of exact-distance radii.
  const double min_range = std::max(1e-9 * report->bbox_diagonal, 1e-300);
  facts.boundary_to_envelope =
      MakeSignedHistogram(envelope->boundary_to_envelope, kHistogramBins, min_range);
  facts.envelope_to_boundary =
      MakeSignedHistogram(envelope->envelope_to_boundary, kHistogramBins, min_range);
  facts.envelope_area = envelope->envelope_area;
  facts.load_seconds = options.load_seconds;
  facts.evaluate_seconds = evaluate_seconds;
  facts.envelope_seconds = envelope->seconds;
  return ViewPageHtml(ViewPageData(solid.mesh(), spheres, facts), facts.title);
}

}  // namespace inscribe::view
