// The whole `inscribe view` report for a sphere set on a solid: the quality report, each
// sphere's protrusion, the paper's Fig. 7 histograms of signed distances between the boundary
// and the union's envelope, and the HTML page showing all of it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/solid.h"

namespace inscribe::view {

struct ViewReportOptions {
  // Points sampled on the boundary and on the envelope (coverage, Hausdorff, histograms).
  std::int64_t samples = 100'000;
  std::uint64_t seed = 1;
  // The voxel size the set was made with, for the fatness test; 0 when unknown.
  double voxel_size = 0.0;
  std::string title, mesh_name, spheres_name;
  double load_seconds = 0.0;  // shown in the panel: reading and validating the mesh
};

// The page (ViewPageHtml) for `spheres` on `solid`. Errors: INVALID_ARGUMENT for spheres or
// options that cannot be evaluated, RESOURCE_EXHAUSTED for an envelope too small to sample
// (thousands of copies of one ball), INTERNAL for a page that cannot be assembled (a build
// problem). Cost: EvaluateSpheres plus ComputeEnvelopeDistances with `samples` each way.
absl::StatusOr<std::string> MakeViewReportPage(const Solid& solid,
                                               const std::vector<Sphere>& spheres,
                                               const ViewReportOptions& options);

}  // namespace inscribe::view
