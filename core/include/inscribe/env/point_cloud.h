// A point cloud as an environment: points with a radius (a depth sensor's points, or the
// spheres of a mesh's cover), indexed for ball queries. Built once per frame (O(n + cells));
// immutable after.
//
// The index: a uniform grid of cubic cells of side h over the points' bounding box, the
// points sorted by cell (a counting sort), and per cell the exact Euclidean distance
// transform of the occupied cells (Felzenszwalb and Huttenlocher's lower envelopes, in
// integer cell units) with the nearest occupied cell. For a ball (c, r), with A any cell,
// D_A the distance between A's centre and the nearest occupied cell's centre, b the largest
// distance of a point from its cell's centre (measured at build, about sqrt(3) h / 2) and
// rmax the largest point radius:
//   clearance >= D_A - b - |c - centre(A)| - rmax - r      (lower, O(1))
//   clearance <= |c - p| - r_p - r   for p a point of the nearest occupied cell   (upper, O(1))
// since every point lies within b of its cell's centre. The lower bound is taken from a second
// transform on cells of h / 3 (or h / 2, or h, as max_cells allows) over the same box, with its
// own b: that is what makes it tight. Tighter answers search the points of
// the cells within reach (O(cells within the search radius + their points)). Every bound is
// moved outward by the margin of environment.h.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "inscribe/env/environment.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe {

// Largest number of points a cloud holds (cell offsets are 32-bit).
inline constexpr std::int64_t kMaxCloudPoints = 1LL << 30;

struct PointCloudOptions {
  // Every point's radius when no radii are given, metres, >= 0 (finite).
  double point_radius = 0.0;
  // The index's cell side h, metres; 0: query_radius, grown until the grid has at most
  // max_cells cells. Cost trade-off: exact searches visit about (2 (r + rmax) / h + 2)^3 cells;
  // the O(1) bounds are about sqrt(3) h apart.
  double cell_size = 0.0;
  // The largest ball radius expected in queries (robot sphere plus padding), metres, > 0:
  // sizes the cells when cell_size is 0. Any radius may still be asked.
  double query_radius = 0.05;
  // Largest number of cells (cells cost 20 bytes each), and of the lower bounds' finer cells
  // (4 bytes each); 1..2^28.
  std::int64_t max_cells = 1LL << 22;
};

// OK, or INVALID_ARGUMENT naming the field: point_radius negative or not finite, cell_size
// negative or not finite, query_radius not positive or not finite when cell_size is 0,
// max_cells outside 1..2^28. O(1).
absl::Status CheckPointCloudOptions(const PointCloudOptions& options);

class PointCloud final : public Environment {
 public:
  // `points` in the world frame, metres; `radii` empty (every point options.point_radius) or
  // one per point, each finite and >= 0. INVALID_ARGUMENT naming the point and the option or
  // function that fixes it: a non-finite coordinate (FilterPoints drops them), a bad radius,
  // more than kMaxCloudPoints points; CheckPointCloudOptions' errors. An empty cloud is
  // valid: every ball is clear of it. O(n + cells) time, 32 bytes per point, 20 per cell and 4 per
  // finer cell.
  static absl::StatusOr<PointCloud> Create(absl::Span<const Vector3> points,
                                           absl::Span<const double> radii,
                                           const PointCloudOptions& options = {});

  std::int64_t size() const;
  double cell_size() const;
  std::int64_t cells() const;
  // The points and radii in the index's order (sorted by cell).
  std::vector<Vector3> Points() const;

  int FirstColliding(absl::Span<const Sphere> balls) const override;
  void Clearances(absl::Span<const Sphere> balls, const ClearanceRequest& request,
                  absl::Span<ClearanceInterval> out) const override;

  struct Index;
  explicit PointCloud(std::shared_ptr<const Index> index);

 private:
  std::shared_ptr<const Index> index_;
};

}  // namespace inscribe
