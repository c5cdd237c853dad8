// The corner screen's sheet estimate (voxel_grid.h): exact between planes, on a tube's axis,
// and on real meshes it drops voxels without dropping the plain method's spheres.
#include "medial/voxel_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/voxel_grid_cells.h"
#include "inscribe/solid/boundary_oracle.h"
#include "support/test_meshes.h"

namespace inscribe::internal {
namespace {

using inscribe::testing::LoadTestMesh;

constexpr double kNoReach = std::numeric_limits<double>::infinity();

Vector3 RandomUnit(std::mt19937& random) {
  std::normal_distribution<double> normal;
  Vector3 v;
  do {
    v = Vector3(normal(random), normal(random), normal(random));
  } while (!(v.norm() > 1e-3));
  return v.normalized();
}

// Where the boundary is two planes, the sheet between two points is their bisector; the
// estimate from either foot is the point of its normal on that bisector, found here by
// bisection on the difference of the two plane distances. A box around that point passes; a box
// farther than the reach from both sides' points does not.
TEST(SheetEstimate, IsTheBisectorCrossingBetweenTwoPlanes) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vector3 u_i = RandomUnit(random);
    const Vector3 u_j = RandomUnit(random);
    const double angle = std::acos(std::clamp(u_i.dot(u_j), -1.0, 1.0));
    if (angle < 0.3) continue;
    const Vector3 f_i(unit(random), unit(random), unit(random));
    const Vector3 f_j(unit(random), unit(random), unit(random));
    // Along f_i + t u_i, the distance to i's plane is t and to j's plane u_j . (x - f_j).
    auto difference = [&](double t) { return u_j.dot(f_i + t * u_i - f_j) - t; };
    // difference(t) = d0 - (1 - u_i.u_j) t falls with t: a root at t > 0 iff difference(0) > 0.
    if (!(difference(0.0) > 1e-6)) continue;
    double lo = 0.0, hi = 1.0;
    while (difference(hi) > 0.0) hi *= 2.0;
    for (int step = 0; step < 200; ++step) {
      const double mid = 0.5 * (lo + hi);
      (difference(mid) > 0.0 ? lo : hi) = mid;
    }
    const Vector3 m = f_i + 0.5 * (lo + hi) * u_i;
    const Vector3 half = Vector3::Constant(0.01);
    EXPECT_TRUE(SheetEstimateNearVoxel(f_i, u_i, f_j, u_j, m - half, m + half, 1e-9));
    // A box far from both feet's estimates (j's lies on j's normal, on the same bisector; a
    // side whose t is not positive gives none and keeps the pair).
    const double t_j = u_i.dot(f_j - f_i) / (1.0 - u_i.dot(u_j));
    const Vector3 m_j = f_j + t_j * u_j;
    const Vector3 far = m + 10.0 * (1.0 + (m - m_j).norm()) * RandomUnit(random);
    const double reach = 0.5;
    if ((far - m).norm() - 0.01 * std::sqrt(3.0) > 2.0 * reach && t_j > 0.0 &&
        (far - m_j).norm() - 0.01 * std::sqrt(3.0) > 2.0 * reach) {
      EXPECT_FALSE(SheetEstimateNearVoxel(f_i, u_i, f_j, u_j, far - half, far + half, reach));
      EXPECT_TRUE(SheetEstimateNearVoxel(f_i, u_i, f_j, u_j, far - half, far + half, kNoReach));
    }
    ++checked;
  }
  EXPECT_GT(checked, 500);
}

// Inside a tube, two points at distance rho from the axis see feet on the wall along their
// radial directions; the estimate is the axis. A voxel around those points, away from the axis,
// is ruled out; one holding the axis is not.
TEST(SheetEstimate, PutsATubesSheetOnItsAxis) {
  const double radius = 1.0;
  for (double phi = 0.4; phi < 3.0; phi += 0.3) {
    const Vector3 out_i(1.0, 0.0, 0.0);
    const Vector3 out_j(std::cos(phi), std::sin(phi), 0.0);
    const Vector3 f_i = radius * out_i + Vector3(0, 0, 0.02);
    const Vector3 f_j = radius * out_j + Vector3(0, 0, -0.01);
    const Vector3 axis_point(0.0, 0.0, 0.05);
    const Vector3 half = Vector3::Constant(0.05);
    EXPECT_TRUE(SheetEstimateNearVoxel(f_i, -out_i, f_j, -out_j, axis_point - half,
                                       axis_point + half, 1e-9))
        << phi;
    const Vector3 off_axis = 0.5 * (out_i + out_j).normalized();
    EXPECT_FALSE(
        SheetEstimateNearVoxel(f_i, -out_i, f_j, -out_j, off_axis - half, off_axis + half, 0.1))
        << phi;
  }
}

// Feet whose tangent planes meet behind them (t <= 0 from both sides) give no estimate: the pair
// is not ruled out, however far the box.
TEST(SheetEstimate, WithoutAnEstimateThePairStays) {
  // Two walls facing away from each other: x = 0 with inward -x, x = 1 with inward +x.
  const Vector3 f_i(0.0, 0.0, 0.0), u_i(-1.0, 0.0, 0.0);
  const Vector3 f_j(1.0, 0.0, 0.0), u_j(1.0, 0.0, 0.0);
  const Vector3 far(50.0, 50.0, 50.0);
  EXPECT_TRUE(SheetEstimateNearVoxel(f_i, u_i, f_j, u_j, far, far + Vector3::Constant(1.0), 0.1));
}

// A demo mesh's oracle, a grid of cubes of side `fraction` of its diagonal, and the voxels the
// culling keeps; nullopt (with a test failure) if any step fails.
struct Culled {
  BoundaryOracle oracle;
  Grid grid;
  std::vector<VisitedVoxel> voxels;
};
std::optional<Culled> Cull(const char* name, double fraction) {
  const Mesh mesh = LoadTestMesh(name);
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  if (!oracle.ok()) {
    ADD_FAILURE() << oracle.status();
    return std::nullopt;
  }
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const absl::StatusOr<Grid> grid = MakeGrid(box, fraction * box.diagonal(), 20'000'000);
  if (!grid.ok()) {
    ADD_FAILURE() << grid.status();
    return std::nullopt;
  }
  std::int64_t queries = 0;
  std::vector<VisitedVoxel> voxels = CullVoxels(*oracle, *grid, queries);
  return Culled{*std::move(oracle), *grid, std::move(voxels)};
}

// The slow obvious list: every corner of every voxel into a std::set.
void ExpectCornersAsASetFindsThem(const Grid& grid, const std::vector<VisitedVoxel>& voxels) {
  auto id_of = [&](const VisitedVoxel& voxel, int corner) {
    return grid.vertex_id(voxel.index[0] + (corner & 1), voxel.index[1] + ((corner >> 1) & 1),
                          voxel.index[2] + (corner >> 2));
  };
  std::set<std::int64_t> all;
  for (const VisitedVoxel& voxel : voxels) {
    for (int corner = 0; corner < 8; ++corner) all.insert(id_of(voxel, corner));
  }
  const CornerVertices listed = ListCornerVertices(grid, voxels);
  EXPECT_EQ(listed.ids, std::vector<std::int64_t>(all.begin(), all.end()));
  ASSERT_EQ(listed.of_voxel.size(), 8 * voxels.size());
  for (std::size_t v = 0; v < voxels.size(); ++v) {
    for (int corner = 0; corner < 8; ++corner) {
      const std::int64_t at = listed.of_voxel[8 * v + static_cast<std::size_t>(corner)];
      ASSERT_GE(at, 0);
      ASSERT_LT(at, static_cast<std::int64_t>(listed.ids.size()));
      ASSERT_EQ(listed.ids[static_cast<std::size_t>(at)], id_of(voxels[v], corner))
          << "voxel " << v << " corner " << corner;
    }
  }
}

// Both ways of listing: the bit per grid vertex (a real mesh's culled voxels fill a good part
// of their grid) and the sorted corners (a few voxels scattered in a large grid).
TEST(CornerVertices, BothWaysListWhatASetFinds) {
  for (const char* name : {"eight.off", "knot1.off"}) {
    SCOPED_TRACE(name);
    INSCRIBE_REQUIRE_MESH(name);
    const std::optional<Culled> culled = Cull(name, 0.02);
    ASSERT_TRUE(culled);
    ExpectCornersAsASetFindsThem(culled->grid, culled->voxels);
  }
  Grid sparse;
  sparse.size = 1.0;
  sparse.dims = {1000, 700, 900};
  std::mt19937 random(3);
  std::vector<VisitedVoxel> voxels;
  for (int v = 0; v < 300; ++v) {
    // Clusters of neighbours, so that voxels share corners.
    const std::int64_t i = random() % 998, j = random() % 698, k = random() % 898;
    for (int d = 0; d < 3; ++d) {
      VisitedVoxel voxel;
      voxel.index = {i + (d & 1), j + (d >> 1), k};
      voxel.linear = voxel.index[0] + sparse.dims[0] * (voxel.index[1] + sparse.dims[1] * k);
      voxels.push_back(voxel);
    }
  }
  ExpectCornersAsASetFindsThem(sparse, voxels);
  ExpectCornersAsASetFindsThem(sparse, {});
}

using VoxelKey = std::tuple<std::int64_t, std::int64_t, std::int64_t>;

// On real meshes: every voxel the estimate lets through, the directions alone let through too;
// on knot1 (a thin tube) it drops most of them; and of the plain method's spheres (every voxel,
// every sample), those in voxels the estimate keeps are nearly all those in voxels the
// directions keep.
TEST(CornerScreen, SheetEstimatesDropVoxelsButNotThePlainMethodsSpheres) {
  for (const char* name : {"knot1.off", "eight.off", "cow.off", "elephant.off", "fandisk.off"}) {
    SCOPED_TRACE(name);
    INSCRIBE_REQUIRE_MESH(name);
    const std::optional<Culled> culled = Cull(name, 0.012);
    ASSERT_TRUE(culled);
    const BoundaryOracle& oracle = culled->oracle;
    const Grid& grid = culled->grid;
    const std::vector<VisitedVoxel>& voxels = culled->voxels;
    const double sigma = grid.size;
    std::int64_t queries = 0;
    const double min_angle = MedialSphereOptions{}.object_angle - kCornerScreenMargin;
    const std::vector<char> by_directions =
        ScreenByCorners(oracle, grid, voxels, min_angle, kNoReach, queries);
    const std::vector<char> by_estimates =
        ScreenByCorners(oracle, grid, voxels, min_angle, kCornerScreenReach * sigma, queries);
    ASSERT_EQ(by_directions.size(), voxels.size());
    ASSERT_EQ(by_estimates.size(), voxels.size());
    std::map<VoxelKey, std::pair<bool, bool>> passes;
    std::int64_t directions_pass = 0, estimates_pass = 0;
    for (std::size_t v = 0; v < voxels.size(); ++v) {
      EXPECT_TRUE(by_directions[v] || !by_estimates[v]) << "voxel " << v;
      directions_pass += by_directions[v];
      estimates_pass += by_estimates[v];
      passes[{voxels[v].index[0], voxels[v].index[1], voxels[v].index[2]}] = {by_directions[v] != 0,
                                                                              by_estimates[v] != 0};
    }
    if (std::string(name) == "knot1.off") {
      EXPECT_LT(2 * estimates_pass, directions_pass) << estimates_pass << " of " << directions_pass;
    }

    MedialSphereOptions plain;
    plain.voxel_size = sigma;
    plain.corner_screen = false;
    plain.screen_samples = 0;
    const absl::StatusOr<MedialSphereResult> all = GenerateMedialSpheres(oracle, plain);
    ASSERT_TRUE(all.ok()) << all.status();
    ASSERT_GT(all->set.size(), 50u);
    int kept_by_directions = 0, kept_by_estimates = 0;
    for (const Sphere& s : all->set.spheres) {
      const Vector3 cell = (s.center - grid.origin) / sigma;
      const auto it = passes.find({static_cast<std::int64_t>(std::floor(cell.x())),
                                   static_cast<std::int64_t>(std::floor(cell.y())),
                                   static_cast<std::int64_t>(std::floor(cell.z()))});
      ASSERT_NE(it, passes.end()) << "a sphere in a voxel the culling dropped";
      kept_by_directions += it->second.first;
      kept_by_estimates += it->second.second;
    }
    EXPECT_GE(kept_by_estimates, kept_by_directions - static_cast<int>(all->set.size()) / 100)
        << kept_by_estimates << " and " << kept_by_directions << " of " << all->set.size();
  }
}

// The public count (VoxelGridCells, which the service's estimates use) is the grid MakeGrid
// builds, and both are the smallest whole number of cells (at least one) whose sides reach the
// extent, counted here by stepping. Extents and sizes are multiples of 1/64 and 1/16, so that
// every product and quotient is exact or far from a whole number. A grid over max_voxels is
// refused, one at it is not.
TEST(VoxelGridCells, AreTheCellsMakeGridLaysAndCountedByStepping) {
  std::mt19937 random(11);
  std::uniform_int_distribution<int> sixty_fourths(0, 192);
  std::uniform_int_distribution<int> sixteenths(1, 16);
  auto extent_of = [&] { return sixty_fourths(random) / 64.0; };
  for (int trial = 0; trial < 500; ++trial) {
    BoundingBox box;
    box.min = Vector3(extent_of(), extent_of(), extent_of()) - Vector3::Ones();
    box.max = box.min + Vector3(extent_of(), trial % 7 == 0 ? 0.0 : extent_of(), extent_of());
    const double size = sixteenths(random) / 16.0;
    const Vector3 cells = VoxelGridCells(box.extent(), size);
    for (int axis = 0; axis < 3; ++axis) {
      std::int64_t stepped = 1;
      while (static_cast<double>(stepped) * size < box.extent()[axis]) ++stepped;
      EXPECT_EQ(cells[axis], static_cast<double>(stepped)) << "trial " << trial << " axis " << axis;
    }
    const auto voxels = static_cast<std::int64_t>(cells.prod());
    const absl::StatusOr<Grid> grid = MakeGrid(box, size, voxels);
    ASSERT_TRUE(grid.ok()) << grid.status();
    EXPECT_EQ(grid->count(), voxels);
    for (int axis = 0; axis < 3; ++axis) EXPECT_EQ(grid->dims[axis], cells[axis]);
    if (voxels > 1) EXPECT_FALSE(MakeGrid(box, size, voxels - 1).ok());
  }
  // A voxel size far below the extent: a huge count or +infinity, never an overflow.
  EXPECT_GT(VoxelGridCells(Vector3::Ones(), 1e-300).prod(), 1e18);
}

}  // namespace
}  // namespace inscribe::internal
