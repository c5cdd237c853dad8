// Private: the voxel grid of medial-sphere generation, the culling of voxels wholly outside the
// mesh, and the corner screen. Used by medial-sphere generation and the searches for a budget.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/boundary_oracle.h"

namespace inscribe::internal {

// The voxel grid: voxel (i, j, k) covers origin + [i, i+1) x [j, j+1) x [k, k+1) times size. The
// grid is centred on the mesh's bounding box.
struct Grid {
  Vector3 origin = Vector3::Zero();
  double size = 0.0;
  std::array<std::int64_t, 3> dims = {0, 0, 0};

  std::int64_t count() const { return dims[0] * dims[1] * dims[2]; }
  Vector3 corner(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return origin +
           size * Vector3(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
  }
};

// A voxel that survived culling. `boundary` when the boundary may cross it.
struct VisitedVoxel {
  std::int64_t linear = 0;  // i + nx * (j + ny * k)
  std::array<std::int64_t, 3> index = {0, 0, 0};
  bool boundary = false;
};

// A grid of cubes of side `size` centred on `box`. INVALID_ARGUMENT naming both numbers when
// it would have more than max_voxels cells (checked before anything is allocated).
absl::StatusOr<Grid> MakeGrid(const BoundingBox& box, double size, std::int64_t max_voxels);

// The smallest voxel size (to 0.1%) whose grid over `box` MakeGrid accepts. `box` must have a
// positive finite diagonal.
double FinestVoxelSize(const BoundingBox& box, std::int64_t max_voxels);

// A first guess at the voxel size giving about `count` medial spheres: the medial surface of a
// solid with this bounding-box diagonal, met by voxels of side sigma, gives about
// (diagonal / sigma)^2 / 4 of them.
inline double VoxelSizeForCount(double diagonal, double count) {
  return 0.5 * diagonal / std::sqrt(count);
}

// Voxels inside the mesh or possibly crossed by its boundary, sorted by linear index. Adds the
// closest-point queries it made to `queries`. When `*cancel` becomes true the work stops early
// and the result is incomplete: the caller must check the flag and discard it.
std::vector<VisitedVoxel> CullVoxels(const BoundaryOracle& oracle, const Grid& grid,
                                     std::int64_t& queries,
                                     const std::atomic<bool>* cancel = nullptr);

// One flag per voxel: 1 when its 8 corners' inward directions at their nearest boundary
// points differ by at least `min_angle` (radians) for some pair. Adds its queries to `queries`.
std::vector<char> ScreenByCorners(const BoundaryOracle& oracle, const Grid& grid,
                                  const std::vector<VisitedVoxel>& voxels, double min_angle,
                                  std::int64_t& queries, const std::atomic<bool>* cancel = nullptr);

}  // namespace inscribe::internal
