// Private: the voxel grid of medial-sphere generation, the culling of voxels wholly outside the
// mesh, and the corner screen. Used by medial-sphere generation and the searches for a budget.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/solid/boundary_oracle.h"

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
  // Grid vertices (voxel corners) (i, j, k), 0 <= i <= dims[0] etc., numbered
  // i + (dims[0] + 1) (j + (dims[1] + 1) k); vertex_count() of them.
  std::int64_t vertex_count() const { return (dims[0] + 1) * (dims[1] + 1) * (dims[2] + 1); }
  std::int64_t vertex_id(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return i + (dims[0] + 1) * (j + (dims[1] + 1) * k);
  }
  Vector3 vertex(std::int64_t id) const {
    const std::int64_t vx = dims[0] + 1;
    const std::int64_t vy = dims[1] + 1;
    return corner(id % vx, (id / vx) % vy, id / (vx * vy));
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

// The grid vertices that are corners of `voxels` (by Grid::vertex_id), in increasing id order,
// and where each voxel's corners are in
// that list: corner c of voxels[v] (offset (c & 1, c >> 1 & 1, c >> 2 & 1)) is
// ids[of_voxel[8 v + c]].
struct CornerVertices {
  std::vector<std::int64_t> ids;
  std::vector<std::int64_t> of_voxel;
};
// A bit per grid vertex with a count per word when the grid has at most 64 vertices per voxel
// listed (16 bytes per voxel at most; O(grid vertices / 64 + voxels)); otherwise, for a few
// voxels in a large grid, the corners sorted. The same answer either way.
CornerVertices ListCornerVertices(const Grid& grid, const std::vector<VisitedVoxel>& voxels);

// The corner screen of medial-sphere generation passes a voxel whose corner directions differ
// by theta minus this (radians): corners sit up to sqrt(3) sigma from the sheet, where the
// directions have turned a little ...
inline constexpr double kCornerScreenMargin = 0.1;
// ... and whose sheet estimate for such a pair lies within this many voxel sizes of it: the
// estimate is exact between planar faces and drifts where the boundary curves.
inline constexpr double kCornerScreenReach = 0.5;

// One flag per voxel: 1 when some pair of its 8 corners has inward directions at their nearest
// boundary points differing by at least `min_angle` (radians) and a sheet estimate
// (SheetEstimateNearVoxel) within `reach` (mesh units; infinity: the directions alone decide).
// Adds its queries to `queries`.
std::vector<char> ScreenByCorners(const BoundaryOracle& oracle, const Grid& grid,
                                  const std::vector<VisitedVoxel>& voxels, double min_angle,
                                  double reach, std::int64_t& queries,
                                  const std::atomic<bool>* cancel = nullptr);

// Where the medial sheet between two points lies, from their nearest boundary points (feet)
// f_i, f_j and unit inward directions u_i, u_j there: the point m = f_i + t u_i on i's inward
// normal at equal distance from the tangent planes at both feet,
// t = u_j . (f_i - f_j) / (1 - u_i . u_j). Along that normal the distance to the boundary is t
// until the normal meets a sheet, so m is that sheet's crossing when both feet lie on planar
// faces, and near it where the boundary curves. False only when both sides (m from i's normal
// and from j's) give a finite t > 0 and put m farther than `reach` from the box [lo, hi]: a side
// without an estimate does not rule the pair out.
bool SheetEstimateNearVoxel(const Vector3& foot_i, const Vector3& inward_i, const Vector3& foot_j,
                            const Vector3& inward_j, const Vector3& lo, const Vector3& hi,
                            double reach);

}  // namespace inscribe::internal
