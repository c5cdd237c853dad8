#include "inscribe/env/distance_grid.h"

#include <cassert>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/distance/certified_distance.h"

namespace inscribe {

struct SignedDistanceGrid::Grid {
  std::array<int, 3> n = {1, 1, 1};
  double v = 1.0;
  RigidPose pose;                    // normalised
  RigidPose inverse;                 // world -> grid frame
  Vector3 corner = Vector3::Zero();  // -n v / 2: sample i at corner + (i + 1/2) v
  std::vector<float> values;
  DistanceGridOptions options;
  double scale = 0.0;  // |pose translation| + half the grid's diagonal

  struct Sample {
    double value;
    double offset;  // |c - s| in the grid frame
  };
  Sample Nearest(const Vector3& world) const {
    const Vector3 local = inverse * world;
    int i[3];
    Vector3 s;
    for (int axis = 0; axis < 3; ++axis) {
      const double t = std::round((local[axis] - corner[axis]) / v - 0.5);
      i[axis] = !(t >= 0.0) ? 0 : t >= n[axis] - 1 ? n[axis] - 1 : static_cast<int>(t);
      s[axis] = corner[axis] + (i[axis] + 0.5) * v;
    }
    const std::int64_t k = (static_cast<std::int64_t>(i[0]) * n[1] + i[1]) * n[2] + i[2];
    return {static_cast<double>(values[k]), (local - s).norm()};
  }
  // The interval of f(c) - r, margin included.
  ClearanceInterval Bounds(const Sphere& ball) const {
    const Sample sample = Nearest(ball.center);
    const double L = options.lipschitz;
    const double margin =
        kEnvironmentMargin * (1.0 + L) * (scale + ball.center.cwiseAbs().maxCoeff() + ball.radius) +
        kCertifiedDistanceFloor;
    const double spread = options.value_error + L * sample.offset;
    const double upper = sample.value >= options.truncation
                             ? std::numeric_limits<double>::infinity()
                             : sample.value + spread - ball.radius + margin;
    return {sample.value - spread - ball.radius - margin, upper};
  }
};

absl::StatusOr<std::array<int, 3>> DistanceGridVoxels(const DistanceGridLayout& layout) {
  if (!std::isfinite(layout.voxel_size) || !(layout.voxel_size > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("voxel_size ", layout.voxel_size, " must be finite and > 0 (metres)"));
  }
  if (absl::StatusOr<RigidPose> pose = NormalizedPose(layout.pose); !pose.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("grid pose: ", pose.status().message()));
  }
  std::array<int, 3> n;
  double total = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double ratio = layout.dims[axis] / layout.voxel_size;
    const double whole = std::round(ratio);
    if (!std::isfinite(ratio) || whole < 1.0 || std::abs(ratio - whole) > 1e-6 * whole ||
        whole > 1e9) {
      return absl::InvalidArgumentError(
          absl::StrCat("dims ", std::string(1, "xyz"[axis]), " ", layout.dims[axis],
                       " is not a whole number >= 1 of voxels of ", layout.voxel_size, " m"));
    }
    n[axis] = static_cast<int>(whole);
    total *= whole;
  }
  if (total > static_cast<double>(kMaxGridVoxels)) {
    return absl::InvalidArgumentError(absl::StrCat("the grid has ", total, " voxels; at most ",
                                                   kMaxGridVoxels, " (a larger voxel_size)"));
  }
  return n;
}

SignedDistanceGrid::SignedDistanceGrid(std::shared_ptr<const Grid> grid) : grid_(std::move(grid)) {}

absl::StatusOr<SignedDistanceGrid> SignedDistanceGrid::Create(const DistanceGridLayout& layout,
                                                              std::vector<float> values,
                                                              const DistanceGridOptions& options) {
  absl::StatusOr<std::array<int, 3>> n = DistanceGridVoxels(layout);
  if (!n.ok()) return n.status();
  if (!std::isfinite(options.lipschitz) || !(options.lipschitz > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("lipschitz ", options.lipschitz, " must be finite and > 0"));
  }
  if (!std::isfinite(options.value_error) || options.value_error < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("value_error ", options.value_error, " must be finite and >= 0 (metres)"));
  }
  if (std::isnan(options.truncation)) {
    return absl::InvalidArgumentError("truncation is NaN (+infinity: no truncation)");
  }
  const std::int64_t count = static_cast<std::int64_t>((*n)[0]) * (*n)[1] * (*n)[2];
  if (static_cast<std::int64_t>(values.size()) != count) {
    return absl::InvalidArgumentError(absl::StrCat("the grid has ", count, " voxels (", (*n)[0],
                                                   " x ", (*n)[1], " x ", (*n)[2], ") but ",
                                                   values.size(), " values"));
  }
  for (std::int64_t k = 0; k < count; ++k) {
    if (std::isnan(values[k]) || values[k] == -std::numeric_limits<float>::infinity()) {
      return absl::InvalidArgumentError(
          absl::StrCat("value ", k, " (voxel ", k / (static_cast<std::int64_t>((*n)[1]) * (*n)[2]),
                       ", ", (k / (*n)[2]) % (*n)[1], ", ", k % (*n)[2], ") is ", values[k],
                       "; values are finite, or +infinity for truncated voxels"));
    }
  }
  auto grid = std::make_shared<Grid>();
  grid->n = *n;
  grid->v = layout.voxel_size;
  grid->pose = *NormalizedPose(layout.pose);
  grid->inverse = grid->pose.Inverse();
  for (int axis = 0; axis < 3; ++axis) grid->corner[axis] = -0.5 * (*n)[axis] * layout.voxel_size;
  grid->values = std::move(values);
  grid->options = options;
  grid->scale = grid->pose.translation.norm() + grid->corner.norm();
  return SignedDistanceGrid(std::move(grid));
}

std::array<int, 3> SignedDistanceGrid::voxels() const { return grid_->n; }

Vector3 SignedDistanceGrid::SamplePosition(int ix, int iy, int iz) const {
  const Grid& g = *grid_;
  return g.pose * (g.corner + Vector3(ix + 0.5, iy + 0.5, iz + 0.5) * g.v);
}

int SignedDistanceGrid::FirstColliding(absl::Span<const Sphere> balls) const {
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (!grid_->Bounds(balls[i]).clear()) return static_cast<int>(i);
  }
  return -1;
}

void SignedDistanceGrid::Clearances(absl::Span<const Sphere> balls, const ClearanceRequest&,
                                    absl::Span<ClearanceInterval> out) const {
  assert(out.size() == balls.size());
  for (std::size_t i = 0; i < balls.size(); ++i) out[i] = grid_->Bounds(balls[i]);
}

double SignedDistanceGrid::Lipschitz() const { return grid_->options.lipschitz; }

}  // namespace inscribe
