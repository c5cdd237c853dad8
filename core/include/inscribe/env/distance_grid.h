// A signed distance voxel grid as an environment, in cuRobo's VoxelGrid terms: dims (the
// grid's extent in metres per axis), voxel_size, pose (the grid frame in the world) and one
// float per voxel, x-major: value (ix * ny + iy) * nz + iz, with n = dims / voxel_size voxels
// per axis. The grid is centred on its pose: voxel i's sample sits at (i + 1/2) v - n v / 2
// on its axis of the grid frame. Values are signed distances, metres, positive outside the
// obstacles (negate a field whose sign is the other way before building).
//
// What is assumed, and so what is certified: the values sample a function f (the signed
// distance to the obstacles) with |value_i - f(sample_i)| <= value_error at every sample, and f
// is Lipschitz with constant L everywhere (|f(x) - f(y)| <= L |x - y|; L = 1 for a true
// distance field, and for its truncation min(f, t)). Then for a ball (c, r), with s the
// sample nearest c (clamped into the grid for balls outside it):
//   clearance in [value_s - value_error - L |c - s| - r,  value_s + value_error + L |c - s| - r]
// moved outward by the environment margin. A value >= truncation says only "at least that
// far": its upper bound is +infinity. The interval is at most 2 value_error + sqrt(3) L v
// wide, whatever tolerance is asked; O(1) per ball.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "inscribe/env/environment.h"
#include "inscribe/geometry/rigid_pose.h"

namespace inscribe {

// Largest number of voxels of a grid.
inline constexpr std::int64_t kMaxGridVoxels = 1LL << 31;

struct DistanceGridLayout {
  Vector3 dims = Vector3::Ones();  // extent per axis, metres, each a whole number of voxels
  double voxel_size = 0.02;        // metres, > 0
  RigidPose pose;                  // the grid frame in the world
};

struct DistanceGridOptions {
  double lipschitz = 1.0;    // L, finite, > 0
  double value_error = 0.0;  // metres, finite, >= 0
  // Values at or above this are truncated ("at least this far"); +infinity: none is.
  double truncation = std::numeric_limits<double>::infinity();
};

// Voxels per axis: dims / voxel_size rounded, which must be within 1e-6 of a whole number >= 1.
// INVALID_ARGUMENT naming the axis otherwise, or for a voxel_size that is not finite and > 0,
// a dims that is not finite, a pose NormalizedPose refuses, more than kMaxGridVoxels voxels.
absl::StatusOr<std::array<int, 3>> DistanceGridVoxels(const DistanceGridLayout& layout);

class SignedDistanceGrid final : public Environment {
 public:
  // `values`: one per voxel (DistanceGridVoxels' product), finite except +infinity for
  // truncated voxels. INVALID_ARGUMENT naming the problem: DistanceGridVoxels', a wrong
  // number of values, a value that is NaN or -infinity (naming its voxel), options out of
  // range (naming the field). O(voxels).
  static absl::StatusOr<SignedDistanceGrid> Create(const DistanceGridLayout& layout,
                                                   std::vector<float> values,
                                                   const DistanceGridOptions& options = {});

  std::array<int, 3> voxels() const;
  // The sample of voxel (ix, iy, iz) in the world frame.
  Vector3 SamplePosition(int ix, int iy, int iz) const;

  int FirstColliding(absl::Span<const Sphere> balls) const override;
  void Clearances(absl::Span<const Sphere> balls, const ClearanceRequest& request,
                  absl::Span<ClearanceInterval> out) const override;
  double Lipschitz() const override;

  struct Grid;
  explicit SignedDistanceGrid(std::shared_ptr<const Grid> grid);

 private:
  std::shared_ptr<const Grid> grid_;
};

}  // namespace inscribe
