#include "inscribe/view/signed_histogram.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace inscribe::view {

SignedHistogram MakeSignedHistogram(const std::vector<double>& values, int bins, double min_range) {
  assert(bins >= 1 && min_range > 0.0);
  SignedHistogram h;
  h.samples = static_cast<std::int64_t>(values.size());
  double range = min_range, sum = 0.0, sum_absolute = 0.0;
  if (!values.empty()) {
    h.min = *std::min_element(values.begin(), values.end());
    h.max = *std::max_element(values.begin(), values.end());
    range = std::max({range, -h.min, h.max});
  }
  h.edges.resize(static_cast<std::size_t>(bins) + 1);
  for (int i = 0; i <= bins; ++i) {
    h.edges[static_cast<std::size_t>(i)] = range * (2.0 * i / bins - 1.0);
  }
  h.counts.assign(static_cast<std::size_t>(bins), 0);
  for (double v : values) {
    sum += v;
    sum_absolute += std::abs(v);
    const double position = std::floor((v + range) / (2.0 * range) * bins);
    const int bin = static_cast<int>(std::clamp(position, 0.0, bins - 1.0));
    ++h.counts[static_cast<std::size_t>(bin)];
  }
  if (!values.empty()) {
    h.mean = sum / static_cast<double>(values.size());
    h.mean_absolute = sum_absolute / static_cast<double>(values.size());
  }
  return h;
}

}  // namespace inscribe::view
