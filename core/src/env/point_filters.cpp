#include "inscribe/env/point_filters.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "absl/strings/str_cat.h"

namespace inscribe {

absl::Status CheckPointFilterOptions(const PointFilterOptions& options) {
  if (options.workspace) {
    const BoundingBox& box = *options.workspace;
    if (!box.min.allFinite() || !box.max.allFinite()) {
      return absl::InvalidArgumentError("workspace has a corner that is not finite");
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (box.min[axis] > box.max[axis]) {
        return absl::InvalidArgumentError(absl::StrCat("workspace min ", box.min[axis], " > max ",
                                                       box.max[axis], " on axis ",
                                                       std::string(1, "xyz"[axis])));
      }
    }
  }
  if (!options.sensor.allFinite()) {
    return absl::InvalidArgumentError("sensor has a coordinate that is not finite");
  }
  if (!(options.min_range >= 0.0) || !(options.max_range >= options.min_range)) {
    return absl::InvalidArgumentError(absl::StrCat("min_range ", options.min_range,
                                                   " and max_range ", options.max_range,
                                                   " must satisfy 0 <= min_range <= max_range"));
  }
  return absl::OkStatus();
}

absl::StatusOr<FilteredPoints> FilterPoints(absl::Span<const Vector3> points,
                                            const PointFilterOptions& options) {
  if (absl::Status status = CheckPointFilterOptions(options); !status.ok()) return status;
  FilteredPoints out;
  const double min2 = options.min_range * options.min_range;
  const double max2 = options.max_range * options.max_range;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vector3& p = points[i];
    if (!p.allFinite()) {
      ++out.dropped_non_finite;
      continue;
    }
    if (options.workspace && ((p.array() < options.workspace->min.array()).any() ||
                              (p.array() > options.workspace->max.array()).any())) {
      ++out.dropped_outside_workspace;
      continue;
    }
    const double d2 = (p - options.sensor).squaredNorm();
    if (d2 < min2 || d2 > max2) {
      ++out.dropped_out_of_range;
      continue;
    }
    out.points.push_back(p);
    out.kept.push_back(static_cast<std::int64_t>(i));
  }
  return out;
}

absl::StatusOr<DownsampledPoints> VoxelDownsample(absl::Span<const Vector3> points,
                                                  double voxel_size) {
  if (!std::isfinite(voxel_size) || !(voxel_size > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("voxel_size ", voxel_size, " must be finite and > 0 (metres)"));
  }
  constexpr double kLimit = 1 << 20;
  std::vector<std::uint64_t> keys(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "point ", i, " has a coordinate that is not finite (FilterPoints drops such points)"));
    }
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const double v = std::floor(points[i][axis] / voxel_size);
      if (!(std::abs(v) < kLimit)) {
        return absl::InvalidArgumentError(
            absl::StrCat("point ", i, " is ", std::abs(v), " voxels from the origin on axis ",
                         std::string(1, "xyz"[axis]),
                         "; at most 2^20 (a larger voxel_size or a workspace filter fixes it)"));
      }
      key = (key << 21) | static_cast<std::uint64_t>(static_cast<std::int64_t>(v) + (1 << 20));
    }
    keys[i] = key;
  }
  std::vector<std::int64_t> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::int64_t a, std::int64_t b) { return keys[a] < keys[b]; });
  DownsampledPoints out;
  for (std::size_t j = 0; j < order.size();) {
    const std::int64_t first = order[j];
    std::size_t end = j + 1;
    while (end < order.size() && keys[order[end]] == keys[first]) {
      out.max_shift = std::max(out.max_shift, (points[order[end]] - points[first]).norm());
      ++out.dropped;
      ++end;
    }
    out.kept.push_back(first);
    j = end;
  }
  std::sort(out.kept.begin(), out.kept.end());
  out.points.reserve(out.kept.size());
  for (std::int64_t i : out.kept) out.points.push_back(points[i]);
  // Rounding of the norms above: one part in 2^50 up, which keeps the stated bound sound.
  out.max_shift *= 1.0 + 1e-15 * 8;
  return out;
}

absl::StatusOr<SelfFilteredPoints> SelfFilterPoints(absl::Span<const Vector3> points,
                                                    absl::Span<const Sphere> balls) {
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (absl::Status status = CheckSphere(balls[i], i); !status.ok()) return status;
  }
  SelfFilteredPoints out;
  if (balls.empty()) {
    out.points.assign(points.begin(), points.end());
    out.kept.resize(points.size());
    std::iota(out.kept.begin(), out.kept.end(), 0);
    return out;
  }
  // A grid over the balls' bounding box, cells of about the largest radius (at most 64 per
  // axis); each cell lists the balls that reach into it.
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  double largest = 0.0;
  for (const Sphere& ball : balls) {
    lo = lo.cwiseMin(ball.center - Vector3::Constant(ball.radius));
    hi = hi.cwiseMax(ball.center + Vector3::Constant(ball.radius));
    largest = std::max(largest, ball.radius);
  }
  int n[3];
  double h[3];
  for (int axis = 0; axis < 3; ++axis) {
    const double extent = hi[axis] - lo[axis];
    n[axis] = static_cast<int>(std::clamp(std::ceil(extent / largest), 1.0, 64.0));
    h[axis] = extent / n[axis];
  }
  auto axis_cell = [&](double v, int axis) {
    const double t = h[axis] > 0.0 ? std::floor((v - lo[axis]) / h[axis]) : 0.0;
    return static_cast<int>(std::clamp(t, 0.0, static_cast<double>(n[axis] - 1)));
  };
  const int cells = n[0] * n[1] * n[2];
  std::vector<std::vector<int>> in_cell(cells);
  for (std::size_t b = 0; b < balls.size(); ++b) {
    int c0[3], c1[3];
    for (int axis = 0; axis < 3; ++axis) {
      // One cell of slack each way, for the rounding of the cell of a point on a cell's side.
      c0[axis] = std::max(0, axis_cell(balls[b].center[axis] - balls[b].radius, axis) - 1);
      c1[axis] =
          std::min(n[axis] - 1, axis_cell(balls[b].center[axis] + balls[b].radius, axis) + 1);
    }
    for (int x = c0[0]; x <= c1[0]; ++x) {
      for (int y = c0[1]; y <= c1[1]; ++y) {
        for (int z = c0[2]; z <= c1[2]; ++z) {
          in_cell[(x * n[1] + y) * n[2] + z].push_back(static_cast<int>(b));
        }
      }
    }
  }
  out.points.reserve(points.size());
  out.kept.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vector3& p = points[i];
    if (!p.allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "point ", i, " has a coordinate that is not finite (FilterPoints drops such points)"));
    }
    bool inside = false;
    if (!(p.array() < lo.array()).any() && !(p.array() > hi.array()).any()) {
      const std::vector<int>& list =
          in_cell[(axis_cell(p.x(), 0) * n[1] + axis_cell(p.y(), 1)) * n[2] + axis_cell(p.z(), 2)];
      for (int b : list) {
        if ((p - balls[b].center).squaredNorm() <= balls[b].radius * balls[b].radius) {
          inside = true;
          break;
        }
      }
    }
    if (inside) {
      ++out.dropped;
    } else {
      out.points.push_back(p);
      out.kept.push_back(static_cast<std::int64_t>(i));
    }
  }
  return out;
}

}  // namespace inscribe
