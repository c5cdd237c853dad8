#include "inscribe/view/signed_histogram.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace inscribe::view {
namespace {

TEST(SignedHistogram, BinsAreSymmetricAboutZero) {
  const SignedHistogram h = MakeSignedHistogram({-1.0, -0.5, 0.0, 0.25, 1.0}, 4, 1e-9);
  EXPECT_EQ(h.edges, (std::vector<double>{-1.0, -0.5, 0.0, 0.5, 1.0}));
  // -1 opens the first bin, -0.5 the second, 0 and 0.25 the third; +range goes to the last.
  EXPECT_EQ(h.counts, (std::vector<std::int64_t>{1, 1, 2, 1}));
  EXPECT_EQ(h.samples, 5);
  EXPECT_DOUBLE_EQ(h.mean, -0.25 / 5);
  EXPECT_DOUBLE_EQ(h.mean_absolute, 2.75 / 5);
  EXPECT_EQ(h.min, -1.0);
  EXPECT_EQ(h.max, 1.0);
}

TEST(SignedHistogram, RangeIsTheLargestMagnitudeOnEitherSide) {
  // All values negative (internal spheres, Fig. 7's first row): the positive half is empty
  // and the range is set by the most negative value.
  const SignedHistogram h = MakeSignedHistogram({-3.0, -2.0, -0.1}, 6, 1e-9);
  EXPECT_EQ(h.edges.front(), -3.0);
  EXPECT_EQ(h.edges.back(), 3.0);
  EXPECT_EQ(h.counts, (std::vector<std::int64_t>{1, 1, 1, 0, 0, 0}));
  EXPECT_EQ(h.max, -0.1);
}

TEST(SignedHistogram, TinyOrNoValuesUseTheMinimumRange) {
  const SignedHistogram tiny = MakeSignedHistogram({1e-20, -1e-21}, 2, 1e-9);
  EXPECT_EQ(tiny.edges, (std::vector<double>{-1e-9, 0.0, 1e-9}));
  EXPECT_EQ(tiny.counts, (std::vector<std::int64_t>{1, 1}));

  const SignedHistogram empty = MakeSignedHistogram({}, 3, 0.5);
  EXPECT_EQ(empty.samples, 0);
  EXPECT_EQ(empty.counts, (std::vector<std::int64_t>{0, 0, 0}));
  EXPECT_EQ(empty.edges.front(), -0.5);
  EXPECT_EQ(empty.edges.back(), 0.5);
  EXPECT_EQ(empty.mean, 0.0);
  EXPECT_EQ(empty.mean_absolute, 0.0);
  EXPECT_EQ(empty.min, 0.0);
  EXPECT_EQ(empty.max, 0.0);
}

TEST(SignedHistogram, MatchesBruteForceOnRandomValues) {
  std::mt19937_64 random(5);
  std::normal_distribution<double> normal(-0.3, 0.7);
  std::vector<double> values(20'000);
  for (double& v : values) v = normal(random);
  const int bins = 60;
  const SignedHistogram h = MakeSignedHistogram(values, bins, 1e-9);
  ASSERT_EQ(h.counts.size(), static_cast<std::size_t>(bins));
  ASSERT_EQ(h.edges.size(), static_cast<std::size_t>(bins) + 1);
  double lowest = values[0], highest = values[0], sum = 0.0, sum_absolute = 0.0;
  for (double v : values) {
    lowest = std::min(lowest, v);
    highest = std::max(highest, v);
    sum += v;
    sum_absolute += std::abs(v);
  }
  const double range = std::max(-lowest, highest);
  EXPECT_EQ(h.edges.front(), -range);
  EXPECT_EQ(h.edges.back(), range);
  EXPECT_EQ(h.min, lowest);
  EXPECT_EQ(h.max, highest);
  EXPECT_NEAR(h.mean, sum / values.size(), 1e-12);
  EXPECT_NEAR(h.mean_absolute, sum_absolute / values.size(), 1e-12);
  // Each bin holds the values between its edges (the last one closed).
  std::vector<std::int64_t> expected(static_cast<std::size_t>(bins), 0);
  for (double v : values) {
    for (int k = 0; k < bins; ++k) {
      const bool last = k == bins - 1;
      if (v >= h.edges[static_cast<std::size_t>(k)] &&
          (v < h.edges[static_cast<std::size_t>(k) + 1] || last)) {
        ++expected[static_cast<std::size_t>(k)];
        break;
      }
    }
  }
  EXPECT_EQ(h.counts, expected);
  std::int64_t total = 0;
  for (std::int64_t c : h.counts) total += c;
  EXPECT_EQ(total, 20'000);
}

}  // namespace
}  // namespace inscribe::view
