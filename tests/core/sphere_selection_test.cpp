// The optimised selection: SelectByCoverage against a slow obvious greedy over its own random
// samples and against exact union volumes; GenerateOptimisedSpheres keeps the paper's
// guarantees (internal, tangent, contacts), never loses to the paper's set at the same budget
// on the demo meshes, is deterministic, reports progress and cancels.
#include "inscribe/medial/sphere_selection.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <vector>

#include "inscribe/balls/union_of_balls.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/solid/solid.h"
#include "medial/coverage_grid.h"
#include "medial/voxel_grid.h"
#include "support/medial_checks.h"
#include "support/sphere_sets.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::ExpectInternalAndTangent;
using testing::LoadTestMesh;
using testing::RandomBalls;

double Volume(const std::vector<Sphere>& balls) {
  absl::StatusOr<double> volume = UnionVolume(balls);
  EXPECT_TRUE(volume.ok()) << volume.status();
  return volume.value_or(0.0);
}

std::vector<Sphere> Chosen(const std::vector<Sphere>& balls, const CoverageSelection& s) {
  std::vector<Sphere> out;
  for (std::int32_t i : s.chosen) out.push_back(balls[static_cast<std::size_t>(i)]);
  return out;
}

// The slow obvious greedy: its own uniform random samples in the balls' bounding box, every
// gain recounted point by point at every step.
std::vector<Sphere> EagerGreedy(const std::vector<Sphere>& balls, std::size_t n, int samples) {
  Vector3 low = Vector3::Constant(std::numeric_limits<double>::infinity()), high = -low;
  for (const Sphere& b : balls) {
    low = low.cwiseMin(b.center - Vector3::Constant(b.radius));
    high = high.cwiseMax(b.center + Vector3::Constant(b.radius));
  }
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vector3> points;
  for (int i = 0; i < samples; ++i) {
    points.push_back(low + (high - low).cwiseProduct(Vector3(unit(rng), unit(rng), unit(rng))));
  }
  std::vector<char> covered(points.size(), 0), taken(balls.size(), 0);
  std::vector<Sphere> out;
  while (out.size() < n) {
    std::size_t best = balls.size();
    std::int64_t best_gain = 0;
    for (std::size_t b = 0; b < balls.size(); ++b) {
      if (taken[b]) continue;
      std::int64_t gain = 0;
      for (std::size_t p = 0; p < points.size(); ++p) {
        gain += !covered[p] && (points[p] - balls[b].center).norm() <= balls[b].radius;
      }
      if (gain > best_gain) best_gain = gain, best = b;
    }
    if (best == balls.size()) break;
    taken[best] = 1;
    out.push_back(balls[best]);
    for (std::size_t p = 0; p < points.size(); ++p) {
      if ((points[p] - balls[best].center).norm() <= balls[best].radius) covered[p] = 1;
    }
  }
  return out;
}

// The eager greedy on SelectByCoverage's own grid, as written down: at every step, recount
// every ball's gain and take the largest (the lowest index among equals). SelectByCoverage
// keeps the gains by subtracting what each choice takes and must choose exactly these balls.
std::vector<std::int32_t> EagerGreedyOnGrid(const std::vector<Sphere>& balls, std::int64_t n,
                                            std::int64_t grid_points) {
  const internal::SampleGrid grid(balls, grid_points);
  internal::BitField uncovered(grid);
  for (const Sphere& ball : balls) {
    grid.ForEachRun(ball, [&](std::int64_t row, std::int64_t first, std::int64_t last) {
      uncovered.Set(row, first, last);
    });
  }
  std::vector<char> taken(balls.size(), 0);
  std::vector<std::int32_t> chosen;
  while (static_cast<std::int64_t>(chosen.size()) < n) {
    std::int64_t best_gain = 0;
    std::size_t best = balls.size();
    for (std::size_t i = 0; i < balls.size(); ++i) {
      if (taken[i]) continue;
      const std::int64_t gain = uncovered.CountIn(balls[i]);
      if (gain > best_gain) best_gain = gain, best = i;
    }
    if (best == balls.size()) break;
    taken[best] = 1;
    grid.ForEachRun(balls[best], [&](std::int64_t row, std::int64_t first, std::int64_t last) {
      uncovered.Clear(row, first, last);
    });
    chosen.push_back(static_cast<std::int32_t>(best));
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

TEST(SelectByCoverage, ChoosesWhatTheEagerGreedyChooses) {
  // Random balls, and a real pool (medial spheres of cow on a fine grid), whose large
  // overlapping balls share points with dozens of others at every choice.
  std::vector<std::vector<Sphere>> pools = {RandomBalls(600, 5.0, 0.1, 1.0, 5),
                                            RandomBalls(300, 2.0, 0.05, 0.6, 6)};
  absl::StatusOr<Solid> cow = PrepareSolid(LoadTestMesh("cow.off"));
  ASSERT_TRUE(cow.ok()) << cow.status();
  MedialSphereOptions medial;
  medial.voxel_size = 0.015;
  absl::StatusOr<MedialSphereResult> pool = GenerateMedialSpheres(cow->oracle, medial);
  ASSERT_TRUE(pool.ok()) << pool.status();
  ASSERT_GT(pool->set.size(), 1000u);
  pools.push_back(pool->set.spheres);
  for (std::size_t p = 0; p < pools.size(); ++p) {
    for (std::int64_t n : {1, 37, 300}) {
      SCOPED_TRACE(::testing::Message() << "pool " << p << ", " << n << " balls");
      CoverageSelectionOptions options;
      options.max_spheres = n;
      options.grid_points = std::int64_t{1} << 20;
      absl::StatusOr<CoverageSelection> fast = SelectByCoverage(pools[p], options);
      ASSERT_TRUE(fast.ok()) << fast.status();
      EXPECT_EQ(fast->chosen, EagerGreedyOnGrid(pools[p], n, options.grid_points));
    }
  }
}

TEST(SelectByCoverage, SamplesMeasureTheExactUnionVolume) {
  const std::vector<Sphere> balls = RandomBalls(300, 4.0, 0.2, 0.9, 11);
  CoverageSelectionOptions options;
  options.max_spheres = 40;
  absl::StatusOr<CoverageSelection> s = SelectByCoverage(balls, options);
  ASSERT_TRUE(s.ok()) << s.status();
  ASSERT_EQ(s->chosen.size(), 40u);
  EXPECT_TRUE(std::is_sorted(s->chosen.begin(), s->chosen.end()));
  const double cell = std::pow(s->grid_spacing, 3);
  EXPECT_NEAR(static_cast<double>(s->samples) * cell / Volume(balls), 1.0, 0.01);
  EXPECT_NEAR(static_cast<double>(s->covered) * cell / Volume(Chosen(balls, *s)), 1.0, 0.01);
}

TEST(SelectByCoverage, AsGoodAsTheSlowEagerGreedy) {
  for (std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE(seed);
    const std::vector<Sphere> balls = RandomBalls(150, 3.0, 0.1, 0.8, seed);
    for (std::int64_t n : {1, 5, 20}) {
      CoverageSelectionOptions options;
      options.max_spheres = n;
      absl::StatusOr<CoverageSelection> fast = SelectByCoverage(balls, options);
      ASSERT_TRUE(fast.ok()) << fast.status();
      const double fast_volume = Volume(Chosen(balls, *fast));
      const double slow_volume = Volume(EagerGreedy(balls, static_cast<std::size_t>(n), 40000));
      // Both estimate the same objective with different samples: within sampling noise.
      EXPECT_GE(fast_volume, 0.98 * slow_volume) << n;
    }
  }
}

TEST(SelectByCoverage, PicksTheBigBallFirstAndSkipsBallsInsideOthers) {
  std::vector<Sphere> balls = {
      {Vector3(0.1, 0, 0), 0.3},  // inside the big one
      {Vector3(0, 0, 0), 1.0},
      {Vector3(5, 0, 0), 0.5},
      {Vector3(5.1, 0, 0), 0.2},  // inside the third
  };
  CoverageSelectionOptions options;
  options.max_spheres = 1;
  EXPECT_EQ(SelectByCoverage(balls, options)->chosen, std::vector<std::int32_t>({1}));
  options.max_spheres = 4;
  // The nested balls add nothing: the selection stops at two.
  EXPECT_EQ(SelectByCoverage(balls, options)->chosen, std::vector<std::int32_t>({1, 2}));
}

TEST(SelectByCoverage, SwapsNeverCoverLessThanTheGreedy) {
  const std::vector<Sphere> balls = RandomBalls(200, 3.0, 0.1, 0.7, 5);
  CoverageSelectionOptions options;
  options.max_spheres = 25;
  absl::StatusOr<CoverageSelection> greedy = SelectByCoverage(balls, options);
  options.swap_passes = 3;
  absl::StatusOr<CoverageSelection> swapped = SelectByCoverage(balls, options);
  ASSERT_TRUE(greedy.ok() && swapped.ok());
  EXPECT_EQ(swapped->samples, greedy->samples);
  EXPECT_GE(swapped->covered, greedy->covered);
  EXPECT_LE(swapped->chosen.size(), 25u);
  const double cell = std::pow(swapped->grid_spacing, 3);
  EXPECT_NEAR(static_cast<double>(swapped->covered) * cell / Volume(Chosen(balls, *swapped)), 1.0,
              0.01);
}

// The swap passes against the plain sequential scan over explicit point lists: each chosen
// ball in turn (least sole cover, then lowest index, first) gives way to the unchosen ball
// overlapping it that covers the most once it is gone, strictly more than it does itself, the
// lowest index among equals. The selection scans the candidates in parallel and skips balls
// with no more points than the best gain so far; it must swap exactly the same balls.
TEST(SelectByCoverage, SwapsAreThoseOfTheSequentialScan) {
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    const std::vector<Sphere> balls = RandomBalls(400, 3.0, 0.05, 0.8, seed);
    CoverageSelectionOptions options;
    options.max_spheres = 30;
    options.grid_points = 1 << 17;
    absl::StatusOr<CoverageSelection> greedy = SelectByCoverage(balls, options);
    options.swap_passes = 4;
    absl::StatusOr<CoverageSelection> swapped = SelectByCoverage(balls, options);
    ASSERT_TRUE(greedy.ok() && swapped.ok());

    const internal::SampleGrid grid(balls, options.grid_points);
    std::vector<std::vector<std::int64_t>> holds(balls.size());
    for (std::size_t b = 0; b < balls.size(); ++b) {
      grid.ForEachRun(balls[b], [&](std::int64_t row, std::int64_t first, std::int64_t last) {
        for (std::int64_t i = first; i <= last; ++i)
          holds[b].push_back(row * grid.row_length() + i);
      });
    }
    std::vector<int> count(static_cast<std::size_t>(grid.row_length() * grid.rows()), 0);
    std::vector<char> chosen(balls.size(), 0);
    auto change = [&](std::size_t b, int step) {
      for (std::int64_t p : holds[b]) count[static_cast<std::size_t>(p)] += step;
      chosen[b] = step > 0;
    };
    auto points_at = [&](std::size_t b, int covers) {
      std::int64_t n = 0;
      for (std::int64_t p : holds[b]) n += count[static_cast<std::size_t>(p)] == covers;
      return n;
    };
    for (std::int32_t b : greedy->chosen) change(static_cast<std::size_t>(b), +1);
    std::int64_t swaps = 0;
    for (int pass = 0; pass < options.swap_passes; ++pass) {
      std::vector<std::pair<std::int64_t, std::int32_t>> order;  // (sole cover, index)
      for (std::size_t b = 0; b < balls.size(); ++b) {
        if (chosen[b]) order.push_back({points_at(b, 1), static_cast<std::int32_t>(b)});
      }
      std::sort(order.begin(), order.end());
      std::int64_t pass_swaps = 0;
      for (const auto& [sole, leaving] : order) {
        const Sphere& s = balls[static_cast<std::size_t>(leaving)];
        change(static_cast<std::size_t>(leaving), -1);
        std::size_t best = static_cast<std::size_t>(leaving);
        std::int64_t best_gain = points_at(best, 0);
        for (std::size_t c = 0; c < balls.size(); ++c) {
          if (chosen[c] || static_cast<std::int32_t>(c) == leaving) continue;
          const double reach = s.radius + balls[c].radius;
          if ((balls[c].center - s.center).squaredNorm() >= reach * reach) continue;
          const std::int64_t gain = points_at(c, 0);
          if (gain > best_gain) {
            best_gain = gain;
            best = c;
          }
        }
        change(best, +1);
        pass_swaps += best != static_cast<std::size_t>(leaving);
      }
      swaps += pass_swaps;
      if (pass_swaps == 0) break;
    }
    std::vector<std::int32_t> expected;
    for (std::size_t b = 0; b < balls.size(); ++b) {
      if (chosen[b]) expected.push_back(static_cast<std::int32_t>(b));
    }
    std::int64_t uncovered = 0;
    std::vector<char> sample(count.size(), 0);
    for (const auto& list : holds) {
      for (std::int64_t p : list) sample[static_cast<std::size_t>(p)] = 1;
    }
    for (std::size_t p = 0; p < count.size(); ++p) uncovered += sample[p] && count[p] == 0;
    EXPECT_GT(swaps, 0) << "seed " << seed << ": the test should make swaps";
    EXPECT_EQ(swapped->swaps, swaps) << "seed " << seed;
    EXPECT_EQ(swapped->chosen, expected) << "seed " << seed;
    EXPECT_EQ(swapped->covered, swapped->samples - uncovered) << "seed " << seed;
  }
}

TEST(SelectByCoverage, BadInputIsAClearError) {
  const std::vector<Sphere> balls = RandomBalls(10, 1.0, 0.1, 0.2, 1);
  CoverageSelectionOptions options;
  options.max_spheres = 0;
  EXPECT_EQ(SelectByCoverage(balls, options).status().code(), absl::StatusCode::kInvalidArgument);
  options.max_spheres = 3;
  options.grid_points = 10;
  EXPECT_NE(SelectByCoverage(balls, options).status().message().find("grid_points"),
            std::string::npos);
  options.grid_points = 1 << 16;
  std::vector<Sphere> bad = balls;
  bad[4].radius = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(SelectByCoverage(bad, options).status().message().find("sphere 4"), std::string::npos);
  EXPECT_TRUE(SelectByCoverage({}, options)->chosen.empty());
}

Solid SolidOf(const char* name) {
  SolidOptions options;
  options.validate.repair.level = MeshRepair::kFill;
  absl::StatusOr<Solid> solid = PrepareSolid(LoadTestMesh(name), options);
  EXPECT_TRUE(solid.ok()) << solid.status();
  return *std::move(solid);
}

TEST(OptimisedSpheres, InternalTangentWithinBudgetAndNeverWorseThanThePaper) {
  for (const char* name : {"eight.off", "cow.off", "fandisk.off", "elephant.off", "knot1.off"}) {
    SCOPED_TRACE(name);
    const Solid solid = SolidOf(name);
    SphereSetParameters parameters;
    parameters.max_spheres = 150;
    parameters.quality.surface_samples = 0;
    parameters.selection = SphereSelection::kPaper;
    absl::StatusOr<GeneratedSphereSet> paper = GenerateSphereSet(solid, parameters);
    parameters.selection = SphereSelection::kOptimised;
    absl::StatusOr<GeneratedSphereSet> optimised = GenerateSphereSet(solid, parameters);
    ASSERT_TRUE(paper.ok() && optimised.ok());
    EXPECT_EQ(optimised->selection, SphereSelection::kOptimised);
    EXPECT_LE(optimised->set.size(), 150u);
    EXPECT_GT(optimised->pool_size, 150);
    ExpectInternalAndTangent(solid.oracle, optimised->set);
    ASSERT_TRUE(optimised->quality->nerr_is_exact);
    EXPECT_LE(optimised->quality->nerr, paper->quality->nerr)
        << "optimised " << optimised->quality->nerr << ", paper " << paper->quality->nerr;
  }
}

// knot1 is a tube: its first pool run, sized by the count model of a medial sheet, falls short,
// and a finer run follows. The short run's spheres join the pool: the pool is exactly the two
// runs' spheres, the finer run's first, and the chosen spheres come from both.
TEST(OptimisedSpheres, AShortRunsSpheresJoinTheFinerRunsPool) {
  const Solid solid = SolidOf("knot1.off");
  OptimisedSphereOptions options;
  options.max_spheres = 150;
  absl::StatusOr<OptimisedSphereResult> result = GenerateOptimisedSpheres(solid.oracle, options);
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->runs, 2);
  const double diagonal = ComputeBoundingBox(solid.oracle.mesh().vertices).diagonal();
  MedialSphereOptions first;
  first.voxel_size = internal::VoxelSizeForCount(diagonal, options.pool_factor * 150);
  MedialSphereOptions second;
  second.voxel_size = result->best.voxel_size;
  ASSERT_LT(second.voxel_size, first.voxel_size);
  const absl::StatusOr<MedialSphereResult> coarse = GenerateMedialSpheres(solid.oracle, first);
  const absl::StatusOr<MedialSphereResult> fine = GenerateMedialSpheres(solid.oracle, second);
  ASSERT_TRUE(coarse.ok() && fine.ok());
  ASSERT_LT(coarse->set.size(), fine->set.size());
  EXPECT_LT(static_cast<double>(coarse->set.size()), 0.5 * options.pool_factor * 150);
  EXPECT_EQ(result->pool_size, static_cast<std::int64_t>(coarse->set.size() + fine->set.size()));
  const auto fine_count = static_cast<std::int32_t>(fine->set.size());
  const auto& chosen = result->selection.chosen;
  EXPECT_TRUE(
      std::any_of(chosen.begin(), chosen.end(), [&](std::int32_t i) { return i < fine_count; }));
  EXPECT_TRUE(
      std::any_of(chosen.begin(), chosen.end(), [&](std::int32_t i) { return i >= fine_count; }));
  for (std::size_t k = 0; k < chosen.size(); ++k) {
    const auto i = static_cast<std::size_t>(chosen[k]);
    const Sphere& expected =
        i < fine->set.size() ? fine->set.spheres[i] : coarse->set.spheres[i - fine->set.size()];
    EXPECT_EQ(result->best.set.spheres[k].center, expected.center) << k;
    EXPECT_EQ(result->best.set.spheres[k].radius, expected.radius) << k;
  }
}

TEST(OptimisedSpheres, SameOutputBitForBitWhateverTheThreads) {
  const Solid solid = SolidOf("elephant.off");
  OptimisedSphereOptions options;
  options.max_spheres = 120;
  absl::StatusOr<OptimisedSphereResult> one_thread;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = GenerateOptimisedSpheres(solid.oracle, options);
  }
  absl::StatusOr<OptimisedSphereResult> parallel = GenerateOptimisedSpheres(solid.oracle, options);
  ASSERT_TRUE(one_thread.ok() && parallel.ok());
  ASSERT_EQ(parallel->best.set.size(), one_thread->best.set.size());
  EXPECT_EQ(parallel->selection.chosen, one_thread->selection.chosen);
  for (std::size_t i = 0; i < one_thread->best.set.size(); ++i) {
    EXPECT_EQ(parallel->best.set.spheres[i].center, one_thread->best.set.spheres[i].center);
    EXPECT_EQ(parallel->best.set.spheres[i].radius, one_thread->best.set.spheres[i].radius);
    EXPECT_EQ(parallel->best.set.contacts[i].triangle, one_thread->best.set.contacts[i].triangle);
  }
}

TEST(OptimisedSpheres, ProgressIsMonotoneAndCancellationStops) {
  const Solid solid = SolidOf("elephant.off");
  OptimisedSphereOptions options;
  options.max_spheres = 200;
  std::vector<double> seen;
  GenerationControl control;
  control.on_progress = [&](double f) { seen.push_back(f); };
  ASSERT_TRUE(GenerateOptimisedSpheres(solid.oracle, options, control).ok());
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), 1.0);

  for (double at : {0.1, 0.9}) {  // during the pool, then during the selection
    std::atomic<bool> cancel{false};
    control.cancel = &cancel;
    control.on_progress = [&](double f) {
      if (f >= at) cancel = true;
    };
    EXPECT_EQ(GenerateOptimisedSpheres(solid.oracle, options, control).status().code(),
              absl::StatusCode::kCancelled)
        << at;
  }
}

TEST(OptimisedSpheres, BadOptionsNameTheField) {
  const Solid solid = SolidOf("eight.off");
  OptimisedSphereOptions options;
  options.max_spheres = 100;
  options.pool_factor = 1.0;
  EXPECT_NE(GenerateOptimisedSpheres(solid.oracle, options).status().message().find("pool_factor"),
            std::string::npos);
  options.pool_factor = 3.0;
  options.base.object_angle = 4.0;
  EXPECT_NE(GenerateOptimisedSpheres(solid.oracle, options).status().message().find("object angle"),
            std::string::npos);
  EXPECT_EQ(ParseSphereSelection("greedy").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(*ParseSphereSelection(SphereSelectionName(SphereSelection::kOptimised)),
            SphereSelection::kOptimised);
}

}  // namespace
}  // namespace inscribe
