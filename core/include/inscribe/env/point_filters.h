// What a depth sensor's points go through before they become a PointCloud (point_cloud.h):
// a workspace box and a range filter, voxel downsampling, and the robot's self-filter. Each
// returns the points it kept, in input order, and counts what it dropped and why.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

struct PointFilterOptions {
  // Keep only points inside this box (closed), world frame, metres; unset: no box.
  std::optional<BoundingBox> workspace;
  // Keep only points whose distance from `sensor` is in [min_range, max_range], metres.
  Vector3 sensor = Vector3::Zero();
  double min_range = 0.0;                                      // >= 0
  double max_range = std::numeric_limits<double>::infinity();  // >= min_range
};

// OK, or INVALID_ARGUMENT naming the field: a workspace with a non-finite corner or min > max
// on an axis, a non-finite sensor, ranges that are NaN, negative or min_range > max_range.
absl::Status CheckPointFilterOptions(const PointFilterOptions& options);

struct FilteredPoints {
  std::vector<Vector3> points;
  // Indices into the input of the kept points (what a caller's per-point data follows).
  std::vector<std::int64_t> kept;
  std::int64_t dropped_non_finite = 0;
  std::int64_t dropped_outside_workspace = 0;
  std::int64_t dropped_out_of_range = 0;
};

// Drops points with a non-finite coordinate, then those outside the workspace, then those out
// of range (each point counted once, under the first reason). Errors:
// CheckPointFilterOptions'. O(n).
absl::StatusOr<FilteredPoints> FilterPoints(absl::Span<const Vector3> points,
                                            const PointFilterOptions& options);

struct DownsampledPoints {
  std::vector<Vector3> points;  // one per occupied voxel: the first input point in it
  std::vector<std::int64_t> kept;
  std::int64_t dropped = 0;
  // The largest distance from a dropped point to the point kept for its voxel, metres
  // (<= sqrt(3) voxel_size). A cloud of the kept points with radius r + max_shift holds every
  // ball of radius r around the input points (triangle inequality), so checks against it
  // stay conservative.
  double max_shift = 0.0;
};

// One point per cubic voxel of side voxel_size (voxels aligned to the world origin), the
// first in input order. INVALID_ARGUMENT for a voxel_size that is not finite and > 0, a point
// that is not finite (FilterPoints drops them), or voxel indices beyond 2^20 per axis (a
// larger voxel_size or a workspace fixes it). O(n log n).
absl::StatusOr<DownsampledPoints> VoxelDownsample(absl::Span<const Vector3> points,
                                                  double voxel_size);

struct SelfFilteredPoints {
  std::vector<Vector3> points;
  std::vector<std::int64_t> kept;
  std::int64_t dropped = 0;  // points inside some ball
};

// Drops the points inside any of `balls` (|p - c| <= r, closed): the robot's spheres, padded,
// at its current state (robot_states.h poses them). Balls must pass CheckSphere and points be
// finite (INVALID_ARGUMENT naming the ball or point). O(n + cells + balls * cells per ball): the
// balls are binned in a grid of cells of about their largest radius over their bounding box.
absl::StatusOr<SelfFilteredPoints> SelfFilterPoints(absl::Span<const Vector3> points,
                                                    absl::Span<const Sphere> balls);

}  // namespace inscribe
