#include "inscribe/medial/medial_spheres.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include "inscribe/balls/union_of_balls.h"
#include "support/medial_checks.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::Box;
using testing::ExpectInternalAndTangent;
using testing::Icosphere;
using testing::LoadTestMesh;

BoundaryOracle MakeOracle(const Mesh& mesh, InsideTest inside = InsideTest::kPseudonormal) {
  BoundaryOracleOptions options;
  options.inside_test = inside;
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh, options);
  EXPECT_TRUE(oracle.ok()) << oracle.status();
  return *std::move(oracle);
}

MedialSphereResult Generate(const BoundaryOracle& oracle, double voxel_size,
                            bool subdivide = false) {
  MedialSphereOptions options;
  options.voxel_size = voxel_size;
  options.subdivide_boundary = subdivide;
  absl::StatusOr<MedialSphereResult> result = GenerateMedialSpheres(oracle, options);
  EXPECT_TRUE(result.ok()) << result.status();
  return result.ok() ? *std::move(result) : MedialSphereResult{};
}

using VoxelKey = std::tuple<std::int64_t, std::int64_t, std::int64_t>;

VoxelKey VoxelOf(const MedialSphereResult& result, const Vector3& x, double size) {
  const Vector3 cell = (x - result.grid_origin) / size;
  return {static_cast<std::int64_t>(std::floor(cell.x())),
          static_cast<std::int64_t>(std::floor(cell.y())),
          static_cast<std::int64_t>(std::floor(cell.z()))};
}

TEST(MedialSpheres, BoxSpheresAreInternalTangentAndMedial) {
  const Mesh box = Box(Vector3(0, 0, 0), Vector3(2.0, 1.0, 0.6));
  const BoundaryOracle oracle = MakeOracle(box);
  const MedialSphereResult result = Generate(oracle, 0.1);
  ASSERT_GT(result.set.size(), 20u);
  ExpectInternalAndTangent(oracle, result.set);
  // A box's medial surface: points whose two smallest face distances are equal.
  for (const Sphere& s : result.set.spheres) {
    std::vector<double> d = {s.center.x(),       2.0 - s.center.x(), s.center.y(),
                             1.0 - s.center.y(), s.center.z(),       0.6 - s.center.z()};
    std::sort(d.begin(), d.end());
    EXPECT_NEAR(d[0], s.radius, 1e-12);
    EXPECT_LE(d[1] - d[0], 2.0 * result.epsilon) << "centre not within epsilon of the medial "
                                                    "surface: "
                                                 << s.center.transpose();
  }
}

TEST(MedialSpheres, AtMostOneSphereInsideEachVoxel) {
  const Mesh mesh = LoadTestMesh("eight.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  const double sigma = 0.04 * ComputeBoundingBox(mesh.vertices).diagonal();
  const MedialSphereResult result = Generate(oracle, sigma);
  ASSERT_GT(result.set.size(), 50u);
  std::set<VoxelKey> seen;
  for (const Sphere& s : result.set.spheres) {
    const VoxelKey key = VoxelOf(result, s.center, sigma);
    EXPECT_TRUE(seen.insert(key).second) << "two spheres in one voxel";
    EXPECT_GE(std::get<0>(key), 0);
    EXPECT_LT(std::get<0>(key), result.grid_dims[0]);
  }
  ExpectInternalAndTangent(oracle, result.set);
}

TEST(MedialSpheres, SubdividedBoundaryVoxelsHoldAtMostEight) {
  const Mesh mesh = LoadTestMesh("eight.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  const double sigma = 0.06 * ComputeBoundingBox(mesh.vertices).diagonal();
  const MedialSphereResult plain = Generate(oracle, sigma);
  const MedialSphereResult split = Generate(oracle, sigma, /*subdivide=*/true);
  EXPECT_GT(split.set.size(), plain.set.size());
  std::map<VoxelKey, int> per_voxel;
  std::set<VoxelKey> per_half;
  for (const Sphere& s : split.set.spheres) {
    ++per_voxel[VoxelOf(split, s.center, sigma)];
    EXPECT_TRUE(per_half.insert(VoxelOf(split, s.center, 0.5 * sigma)).second)
        << "two spheres in one half-size voxel";
  }
  for (const auto& [key, count] : per_voxel) EXPECT_LE(count, 8);
  ExpectInternalAndTangent(oracle, split.set);
}

TEST(MedialSpheres, SameOutputBitForBitWhateverTheThreads) {
  const Mesh mesh = LoadTestMesh("elephant.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  const double sigma = 0.05 * ComputeBoundingBox(mesh.vertices).diagonal();
  MedialSphereResult one_thread;
  {
    tbb::global_control serial(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = Generate(oracle, sigma);
  }
  const MedialSphereResult parallel = Generate(oracle, sigma);
  const MedialSphereResult again = Generate(oracle, sigma);
  ASSERT_GT(one_thread.set.size(), 10u);
  for (const MedialSphereResult* other : {&parallel, &again}) {
    ASSERT_EQ(other->set.size(), one_thread.set.size());
    for (std::size_t i = 0; i < one_thread.set.size(); ++i) {
      // Exact equality on purpose: the output must not depend on scheduling.
      EXPECT_EQ(other->set.spheres[i].center, one_thread.set.spheres[i].center);
      EXPECT_EQ(other->set.spheres[i].radius, one_thread.set.spheres[i].radius);
      EXPECT_EQ(other->set.contacts[i].triangle, one_thread.set.contacts[i].triangle);
      EXPECT_EQ(other->set.contacts[i].barycentric, one_thread.set.contacts[i].barycentric);
    }
  }
}

TEST(MedialSpheres, RealMeshesGiveInternalTangentSpheres) {
  for (const char* name : {"cow.off", "knot1.off", "fandisk.off"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = LoadTestMesh(name);
    // cow self-intersects: the pseudonormal sign is unreliable there (see InsideTest).
    const BoundaryOracle oracle = MakeOracle(mesh, InsideTest::kExactWinding);
    const MedialSphereResult result =
        Generate(oracle, 0.05 * ComputeBoundingBox(mesh.vertices).diagonal());
    ASSERT_GT(result.set.size(), 10u);
    ExpectInternalAndTangent(oracle, result.set);
  }
}

// The screens are accelerations of the paper's per-voxel method: against the plain method
// (every voxel, every sample) they must find nearly the same voxels and the same volume.
TEST(MedialSpheres, ScreensKeepNearlyEverySphereOfThePlainMethod) {
  for (const char* name : {"eight.off", "elephant.off", "fandisk.off"}) {
    SCOPED_TRACE(name);
    const Mesh mesh = LoadTestMesh(name);
    const BoundaryOracle oracle = MakeOracle(mesh);
    MedialSphereOptions fast;
    fast.voxel_size = 0.04 * ComputeBoundingBox(mesh.vertices).diagonal();
    MedialSphereOptions plain = fast;
    plain.corner_screen = false;
    plain.screen_samples = 0;
    plain.pair_angle_margin = M_PI;
    const absl::StatusOr<MedialSphereResult> a = GenerateMedialSpheres(oracle, fast);
    const absl::StatusOr<MedialSphereResult> b = GenerateMedialSpheres(oracle, plain);
    ASSERT_TRUE(a.ok() && b.ok());
    std::set<VoxelKey> fast_voxels;
    for (const Sphere& s : a->set.spheres)
      fast_voxels.insert(VoxelOf(*a, s.center, fast.voxel_size));
    int shared = 0;
    for (const Sphere& s : b->set.spheres)
      shared += fast_voxels.count(VoxelOf(*b, s.center, fast.voxel_size));
    EXPECT_GE(shared, 0.93 * static_cast<double>(b->set.size()))
        << shared << " of the plain method's " << b->set.size() << " voxels";
    const double volume_fast = *UnionVolume(a->set.spheres);
    const double volume_plain = *UnionVolume(b->set.spheres);
    EXPECT_NEAR(volume_fast / SignedVolume(mesh), volume_plain / SignedVolume(mesh), 0.005);
  }
}

// Where the corner screen pays: a thin tube at a fine grid, most of whose voxels see no sheet.
TEST(MedialSpheres, CornerScreenSkipsMostVoxelsOfAThinTube) {
  const Mesh mesh = LoadTestMesh("knot1.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  MedialSphereOptions options;
  options.voxel_size = 0.012 * ComputeBoundingBox(mesh.vertices).diagonal();
  const absl::StatusOr<MedialSphereResult> fast = GenerateMedialSpheres(oracle, options);
  options.corner_screen = false;
  const absl::StatusOr<MedialSphereResult> unscreened = GenerateMedialSpheres(oracle, options);
  ASSERT_TRUE(fast.ok() && unscreened.ok());
  EXPECT_GT(fast->stats.screened_voxels, fast->stats.visited_voxels / 2);
  EXPECT_LT(2 * fast->stats.closest_point_queries, unscreened->stats.closest_point_queries);
  EXPECT_GE(fast->set.size(), unscreened->set.size() * 97 / 100);
}

TEST(MedialSpheres, SphereMeshGivesOneBigSphereNearItsCentre) {
  const Mesh ball = Icosphere(3, Vector3(0.3, -0.2, 0.1), 1.0);
  const BoundaryOracle oracle = MakeOracle(ball);
  const MedialSphereResult result = Generate(oracle, 0.5);
  ASSERT_GE(result.set.size(), 1u);
  double largest = 0.0;
  for (const Sphere& s : result.set.spheres) largest = std::max(largest, s.radius);
  // The level-3 icosphere's inradius is above 0.99.
  EXPECT_GT(largest, 0.98);
  ExpectInternalAndTangent(oracle, result.set);
}

TEST(MedialSpheres, ObjectAngleFilters) {
  const Mesh mesh = LoadTestMesh("elephant.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  MedialSphereOptions options;
  options.voxel_size = 0.05 * ComputeBoundingBox(mesh.vertices).diagonal();
  options.object_angle = 0.3;
  const absl::StatusOr<MedialSphereResult> loose = GenerateMedialSpheres(oracle, options);
  options.object_angle = 1.5;
  const absl::StatusOr<MedialSphereResult> strict = GenerateMedialSpheres(oracle, options);
  ASSERT_TRUE(loose.ok() && strict.ok());
  EXPECT_GT(loose->set.size(), strict->set.size());
}

TEST(MedialSpheres, InvalidOptionsAreClearErrors) {
  const BoundaryOracle oracle = MakeOracle(Box(Vector3::Zero(), Vector3::Ones()));
  auto error_for = [&](MedialSphereOptions options) {
    absl::StatusOr<MedialSphereResult> result = GenerateMedialSpheres(oracle, options);
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(result.status().message());
  };
  MedialSphereOptions good;
  good.voxel_size = 0.25;
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    MedialSphereOptions o = good;
    o.voxel_size = bad;
    EXPECT_NE(error_for(o).find("voxel size"), std::string::npos);
  }
  for (double bad : {0.0, -0.1, M_PI, 4.0, std::nan("")}) {
    MedialSphereOptions o = good;
    o.object_angle = bad;
    EXPECT_NE(error_for(o).find("object angle"), std::string::npos);
  }
  MedialSphereOptions o = good;
  o.samples = 1;
  EXPECT_NE(error_for(o).find("samples"), std::string::npos);
  o = good;
  o.epsilon = -1.0;
  EXPECT_NE(error_for(o).find("epsilon"), std::string::npos);
  // A voxel size that would make 10^18 voxels is refused up front, not allocated.
  o = good;
  o.voxel_size = 1e-6;
  const std::string message = error_for(o);
  EXPECT_NE(message.find("more than 20000000 voxels"), std::string::npos) << message;
  o.max_voxels = 1000;
  o.voxel_size = 0.05;  // 20^3 = 8000 voxels
  EXPECT_NE(error_for(o).find("more than 1000 voxels"), std::string::npos);

  SphereBudgetOptions budget;
  budget.max_spheres = 0;
  EXPECT_EQ(GenerateWithSphereBudget(oracle, budget).status().code(),
            absl::StatusCode::kInvalidArgument);
  budget.max_spheres = -5;
  EXPECT_NE(
      std::string(GenerateWithSphereBudget(oracle, budget).status().message()).find("at least 1"),
      std::string::npos);
}

TEST(MedialSpheres, ProgressIsMonotoneAndCancellationStops) {
  const Mesh mesh = LoadTestMesh("elephant.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  MedialSphereOptions options;
  options.voxel_size = 0.02 * ComputeBoundingBox(mesh.vertices).diagonal();
  std::vector<double> seen;
  GenerationControl control;
  control.on_progress = [&](double f) { seen.push_back(f); };
  ASSERT_TRUE(GenerateMedialSpheres(oracle, options, control).ok());
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), 1.0);

  std::atomic<bool> cancel{false};
  control.cancel = &cancel;
  int calls = 0;
  control.on_progress = [&](double) {
    ++calls;
    cancel = true;  // cancel after the first batch
  };
  const absl::StatusOr<MedialSphereResult> cancelled =
      GenerateMedialSpheres(oracle, options, control);
  EXPECT_EQ(cancelled.status().code(), absl::StatusCode::kCancelled);
  EXPECT_EQ(calls, 1);

  SphereBudgetOptions budget;
  budget.max_spheres = 300;
  cancel = false;
  control.on_progress = [&](double f) {
    if (f > 0.2) cancel = true;
  };
  EXPECT_EQ(GenerateWithSphereBudget(oracle, budget, control).status().code(),
            absl::StatusCode::kCancelled);
}

TEST(SphereBudget, FinestGridWithinTheBudget) {
  const Mesh mesh = LoadTestMesh("fandisk.off");
  const BoundaryOracle oracle = MakeOracle(mesh);
  for (std::int64_t budget : {40, 300}) {
    SCOPED_TRACE(budget);
    SphereBudgetOptions options;
    options.max_spheres = budget;
    const absl::StatusOr<SphereBudgetResult> found = GenerateWithSphereBudget(oracle, options);
    ASSERT_TRUE(found.ok()) << found.status();
    EXPECT_LE(static_cast<std::int64_t>(found->best.set.size()), budget);
    EXPECT_GT(static_cast<std::int64_t>(found->best.set.size()), budget * 8 / 10);
    // The bracket: a slightly finer grid gives too many spheres.
    ASSERT_GT(found->rejected_voxel_size, 0.0);
    EXPECT_LE(found->best.voxel_size / found->rejected_voxel_size - 1.0,
              options.relative_tolerance);
    EXPECT_GT(static_cast<std::int64_t>(Generate(oracle, found->rejected_voxel_size).set.size()),
              budget);
    EXPECT_LE(found->runs, options.max_runs);
    ExpectInternalAndTangent(oracle, found->best.set);
  }
}

// A ball's medial axis is one point: no grid reaches the budget, and the search must stop at
// the finest grid the voxel limit allows (whose sides round up to whole voxels) instead of
// asking for one just past it.
TEST(SphereBudget, AnUnreachableBudgetGivesTheFinestGridsSet) {
  const BoundaryOracle oracle = MakeOracle(testing::Icosphere(3));
  for (const std::int64_t max_voxels : {100'000, 250'047, 1'000'000}) {
    SCOPED_TRACE(max_voxels);
    SphereBudgetOptions options;
    options.max_spheres = 500;
    options.base.max_voxels = max_voxels;
    const absl::StatusOr<SphereBudgetResult> found = GenerateWithSphereBudget(oracle, options);
    ASSERT_TRUE(found.ok()) << found.status();
    EXPECT_LT(static_cast<std::int64_t>(found->best.set.size()), 500);
    EXPECT_GE(found->best.set.size(), 1u);
    EXPECT_LE(found->best.stats.grid_voxels, max_voxels);
    EXPECT_GT(found->best.stats.grid_voxels, max_voxels * 9 / 10);
  }
}

}  // namespace
}  // namespace inscribe
