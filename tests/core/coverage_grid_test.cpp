// The selection's bit field: its block-wise count of a ball's set points against the plain
// row-by-row count (SampleGrid::ForEachRun and BitField::Count) on random and adversarial balls
// and fields, its block totals against a full recount, its parallel fill against ball-by-ball
// sets, and the cleared points of a choice against what each ball's count loses.
#include "medial/coverage_grid.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "support/sphere_sets.h"

namespace inscribe::internal {
namespace {

using testing::RandomBalls;

// The slow obvious count: every run of the ball, popcounted.
std::int64_t RowByRowCount(const SampleGrid& grid, const BitField& field, const Sphere& ball) {
  std::int64_t count = 0;
  grid.ForEachRun(ball, [&](std::int64_t row, std::int64_t first, std::int64_t last) {
    count += field.Count(row, first, last);
  });
  return count;
}

std::int64_t FullRecount(const SampleGrid& grid, const BitField& field) {
  std::int64_t count = 0;
  for (std::int64_t row = 0; row < grid.rows(); ++row) {
    count += field.Count(row, 0, grid.row_length() - 1);
  }
  return count;
}

// Balls from tiny to wider than the grid, some centred outside it.
std::vector<Sphere> Probes(const SampleGrid& grid, std::mt19937_64& rng, int n) {
  const double side = grid.spacing() * static_cast<double>(grid.dim(0));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Sphere> probes;
  for (int p = 0; p < n; ++p) {
    const Vector3 at =
        grid.PointAt(0, 0, 0) +
        side * Vector3(1.4 * unit(rng) - 0.2, 1.4 * unit(rng) - 0.2, 1.4 * unit(rng) - 0.2);
    probes.push_back({at, side * std::pow(unit(rng), 2.0) * 0.8 + 1e-3 * grid.spacing()});
  }
  return probes;
}

TEST(CoverageGrid, BlockCountsEqualTheRowByRowCount) {
  for (std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(seed);
    const std::vector<Sphere> balls = RandomBalls(60, 4.0, 0.2, 1.6, seed);
    const SampleGrid grid(balls, std::int64_t{1} << 20);
    BitField field(grid);
    for (const Sphere& ball : balls) {
      grid.ForEachRun(ball, [&](std::int64_t row, std::int64_t first, std::int64_t last) {
        field.Set(row, first, last);
      });
    }
    const std::vector<Sphere> probes = Probes(grid, rng, 200);
    std::uniform_int_distribution<std::int64_t> row_of(0, grid.rows() - 1);
    std::uniform_int_distribution<std::int64_t> point_of(0, grid.row_length() - 1);
    // Clear ball after ball (as the greedy does) and single points, checking as it goes.
    for (std::size_t step = 0; step < balls.size(); ++step) {
      for (std::size_t p = step % 4; p < probes.size(); p += 4) {
        ASSERT_EQ(field.CountIn(probes[p]), RowByRowCount(grid, field, probes[p]))
            << "step " << step << " probe " << p;
      }
      ASSERT_EQ(field.CountAll(), FullRecount(grid, field));
      grid.ForEachRun(balls[step], [&](std::int64_t row, std::int64_t first, std::int64_t last) {
        field.Clear(row, first, last);
      });
      for (int i = 0; i < 50; ++i) field.Clear(row_of(rng), point_of(rng));
      for (int i = 0; i < 10; ++i) field.Set(row_of(rng), point_of(rng));
    }
    EXPECT_EQ(field.CountAll(), FullRecount(grid, field));
  }
}

// Sample points lying on the sphere: centres on grid points and radii of whole spacings (and a
// hair either side), where the row rule's rounding decides.
TEST(CoverageGrid, BallsThroughSamplePointsCountAsTheRowsSay) {
  const std::vector<Sphere> balls = RandomBalls(40, 4.0, 0.3, 1.2, 9);
  const SampleGrid grid(balls, std::int64_t{1} << 19);
  BitField field(grid);
  for (std::int64_t row = 0; row < grid.rows(); ++row) field.Set(row, 0, grid.row_length() - 1);
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<std::int64_t> x(0, grid.dim(0) - 1), y(0, grid.dim(1) - 1),
      z(0, grid.dim(2) - 1);
  for (int p = 0; p < 300; ++p) {
    const Vector3 centre = grid.PointAt(x(rng), y(rng), z(rng));
    const double units = static_cast<double>(1 + p % 60);
    for (double scale : {1.0, 1.0 - 1e-15, 1.0 + 1e-15, 1.0 - 1e-7, 1.0 + 1e-7}) {
      const Sphere ball{centre, units * grid.spacing() * scale};
      ASSERT_EQ(field.CountIn(ball), RowByRowCount(grid, field, ball)) << p << " " << scale;
    }
    // Knock out points now and then so blocks differ.
    field.Clear(std::uniform_int_distribution<std::int64_t>(0, grid.rows() - 1)(rng),
                std::uniform_int_distribution<std::int64_t>(0, grid.row_length() - 1)(rng));
  }
}

TEST(CoverageGrid, SetAllAndCountPointsMatchBallByBall) {
  for (std::uint64_t seed : {4, 5}) {
    SCOPED_TRACE(seed);
    const std::vector<Sphere> balls = RandomBalls(80, 4.0, 0.1, 1.4, seed);
    // An odd grid so that slabs of four slices end short at the top.
    const SampleGrid grid(balls, (std::int64_t{1} << 19) + 4099);
    BitField serial(grid), parallel(grid);
    for (const Sphere& ball : balls) {
      grid.ForEachRun(ball, [&](std::int64_t row, std::int64_t first, std::int64_t last) {
        serial.Set(row, first, last);
      });
    }
    parallel.SetAll(balls);
    for (std::int64_t row = 0; row < grid.rows(); ++row) {
      ASSERT_EQ(parallel.Count(row, 0, grid.row_length() - 1),
                serial.Count(row, 0, grid.row_length() - 1));
    }
    ASSERT_EQ(parallel.CountAll(), serial.CountAll());
    for (const Sphere& ball : balls) {
      ASSERT_EQ(grid.CountPoints(ball), RowByRowCount(grid, parallel, ball));
    }
  }
}

// Choosing ball after ball as the greedy does: what a choice takes is exactly what every other
// ball's count loses, and Take clears exactly the ball's points.
TEST(CoverageGrid, ClearedPointsAreWhatEachBallsCountLoses) {
  for (std::uint64_t seed : {6, 7}) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(seed);
    const std::vector<Sphere> balls = RandomBalls(50, 4.0, 0.1, 1.6, seed);
    const SampleGrid grid(balls, std::int64_t{1} << 20);
    BitField field(grid);
    field.SetAll(balls);
    std::vector<Sphere> probes = Probes(grid, rng, 150);
    probes.insert(probes.end(), balls.begin(), balls.end());
    std::uniform_int_distribution<std::int64_t> row_of(0, grid.rows() - 1);
    std::uniform_int_distribution<std::int64_t> point_of(0, grid.row_length() - 1);
    ClearedPoints cleared(grid);
    std::vector<std::int64_t> before(probes.size());
    for (std::size_t step = 0; step < balls.size(); ++step) {
      for (std::size_t p = 0; p < probes.size(); ++p) before[p] = field.CountIn(probes[p]);
      const std::int64_t total = field.CountAll();
      cleared.Take(field, balls[step]);
      ASSERT_EQ(field.CountAll(), FullRecount(grid, field));
      EXPECT_EQ(field.CountIn(balls[step]), 0);
      ASSERT_EQ(total - field.CountAll(), before[probes.size() - balls.size() + step]);
      for (std::size_t p = 0; p < probes.size(); ++p) {
        ASSERT_EQ(cleared.CountIn(probes[p]), before[p] - field.CountIn(probes[p]))
            << "step " << step << " probe " << p;
      }
      // Stray points set and cleared between choices, as a swap or a caller might.
      for (int i = 0; i < 20; ++i) field.Set(row_of(rng), point_of(rng));
    }
  }
}

}  // namespace
}  // namespace inscribe::internal
