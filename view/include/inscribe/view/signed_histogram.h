// Histograms of signed distances, binned here so that the `inscribe view` page receives
// counts, not every sample.
#pragma once

#include <cstdint>
#include <vector>

namespace inscribe::view {

// `bins` equal bins over [-range, range], symmetric about 0 so that the sign reads at a
// glance: range = max |value|, at least min_range (> 0). Bin k holds the values in
// [edges[k], edges[k+1]) up to rounding; +range goes to the last bin.
struct SignedHistogram {
  std::vector<double> edges;         // bins + 1 ascending edges, edges[0] = -range
  std::vector<std::int64_t> counts;  // bins counts, summing to samples
  std::int64_t samples = 0;
  double mean = 0.0;            // of the values
  double mean_absolute = 0.0;   // of |value|
  double min = 0.0, max = 0.0;  // 0 when there are no values
};

// bins >= 1, min_range > 0 (asserted). Cost O(#values).
SignedHistogram MakeSignedHistogram(const std::vector<double>& values, int bins, double min_range);

}  // namespace inscribe::view
