#include "inscribe/env/point_cloud.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "env/distance_transform.h"
#include "inscribe/distance/certified_distance.h"

namespace inscribe {

// Cells are numbered (ix * ny + iy) * nz + iz; cell (ix, iy, iz) covers
// [origin + i h, origin + (i + 1) h) per axis and its centre is origin + (i + 1/2) h.
struct PointCloud::Index {
  struct Point {
    double x, y, z, r;
  };
  std::vector<Point> points;  // sorted by cell
  Vector3 origin = Vector3::Zero();
  double h = 1.0;
  int n[3] = {1, 1, 1};
  std::vector<std::uint32_t> start;  // cells + 1: the points of cell k are [start[k], start[k+1])
  std::vector<float> nearest;        // per cell, D (metres) rounded down; +inf for no points
  std::vector<std::int64_t> nearest_d2;  // per cell, D^2 in cell units^2 (exact)
  std::vector<std::uint32_t> rep;        // per cell, a point of the nearest occupied cell
  double bin_radius = 0.0;               // largest |point - its cell's centre|
  // The finer transform behind the O(1) lower bounds: cells of side h / fine over the same box
  // (fine 3, 2 or 1, as max_cells allows).
  int fine = 1;
  int fine_n[3] = {1, 1, 1};
  std::vector<float> fine_nearest;  // per fine cell, as `nearest`
  double fine_bin_radius = 0.0;
  double max_radius = 0.0;
  double scale = 0.0;  // largest |coordinate| of the grid and points, plus max_radius

  std::int64_t Cell(int ix, int iy, int iz) const {
    return (static_cast<std::int64_t>(ix) * n[1] + iy) * n[2] + iz;
  }
  int AxisCell(double v, int axis) const {
    const double t = std::floor((v - origin[axis]) / h);
    if (!(t >= 0.0)) return 0;  // also NaN
    return t >= n[axis] - 1 ? n[axis] - 1 : static_cast<int>(t);
  }
  double Centre(int i, int axis) const { return origin[axis] + (i + 0.5) * h; }
  double Margin(const Sphere& ball) const {
    return kEnvironmentMargin * (scale + ball.center.cwiseAbs().maxCoeff() + ball.radius) +
           kCertifiedDistanceFloor;
  }
};

namespace {

using Index = PointCloud::Index;

double Distance(const Vector3& c, const Index::Point& p) {
  const double dx = c.x() - p.x, dy = c.y() - p.y, dz = c.z() - p.z;
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Calls visit(point) for every point that may lie within `reach` of c (every one that does,
// and some that do not), cell column by column; stops when visit returns true. Cells whose
// centre lies within inner_d2 (exclusive, cell units squared) of cell `inner` hold no point
// and are skipped. Returns whether visit stopped it.
template <typename Visit>
bool VisitNear(const Index& index, const Vector3& c, double reach, std::int64_t inner_d2,
               const int inner[3], Visit visit) {
  const double h = index.h;
  // A point within reach of c has its cell's centre within box of c.
  const double box = reach + index.bin_radius;
  int lo[2], hi[2];
  for (int axis = 0; axis < 2; ++axis) {
    const double first = std::floor((c[axis] - box - index.origin[axis]) / h - 0.5);
    const double last = std::ceil((c[axis] + box - index.origin[axis]) / h - 0.5);
    if (last < 0.0 || first > index.n[axis] - 1) return false;
    lo[axis] = first < 0.0 ? 0 : static_cast<int>(first);
    hi[axis] = static_cast<int>(std::min<double>(last, index.n[axis] - 1));
  }
  const double box2 = box * box;
  for (int ix = lo[0]; ix <= hi[0]; ++ix) {
    const double ex = c.x() - index.Centre(ix, 0);
    for (int iy = lo[1]; iy <= hi[1]; ++iy) {
      const double ey = c.y() - index.Centre(iy, 1);
      const double left = box2 - ex * ex - ey * ey;
      if (left < 0.0) continue;
      const double zr = std::sqrt(left);
      const double zlo = std::floor((c.z() - zr - index.origin.z()) / h - 0.5);
      const double zhi = std::ceil((c.z() + zr - index.origin.z()) / h - 0.5);
      if (zhi < 0.0 || zlo > index.n[2] - 1) continue;
      const int z0 = zlo < 0.0 ? 0 : static_cast<int>(zlo);
      const int z1 = static_cast<int>(std::min<double>(zhi, index.n[2] - 1));
      // The empty cells around `inner`: |dz| <= skip.
      const std::int64_t dx = ix - inner[0], dy = iy - inner[1];
      const std::int64_t left_inner = inner_d2 - dx * dx - dy * dy;
      std::int64_t skip = -1;
      if (left_inner > 0) {
        skip = static_cast<std::int64_t>(std::sqrt(static_cast<double>(left_inner - 1)));
        while (skip * skip > left_inner - 1) --skip;
        while ((skip + 1) * (skip + 1) <= left_inner - 1) ++skip;
      }
      const std::int64_t row = index.Cell(ix, iy, 0);
      for (int iz = z0; iz <= z1; ++iz) {
        if (skip >= 0 && std::abs(static_cast<std::int64_t>(iz) - inner[2]) <= skip) {
          iz = static_cast<int>(inner[2] + skip);  // jump over the empty run
          continue;
        }
        const std::uint32_t begin = index.start[row + iz], end = index.start[row + iz + 1];
        for (std::uint32_t k = begin; k < end; ++k) {
          if (visit(index.points[k])) return true;
        }
      }
    }
  }
  return false;
}

struct Bounds {
  double lower, upper;  // of min over points of |c - p| - r_p (the ball's radius not taken off)
  int cell[3];
  std::int64_t d2;
};

// The O(1) lower bound of the header, before the ball's radius and the margin, from the fine
// cell of c (any cell gives a valid bound; this one is tight).
double FastLower(const Index& index, const Vector3& c) {
  const double hf = index.h / index.fine;
  int fi[3];
  Vector3 centre;
  for (int axis = 0; axis < 3; ++axis) {
    const double t = std::floor((c[axis] - index.origin[axis]) / hf);
    fi[axis] = !(t >= 0.0)                   ? 0
               : t >= index.fine_n[axis] - 1 ? index.fine_n[axis] - 1
                                             : static_cast<int>(t);
    centre[axis] = index.origin[axis] + (fi[axis] + 0.5) * hf;
  }
  const std::int64_t kf =
      (static_cast<std::int64_t>(fi[0]) * index.fine_n[1] + fi[1]) * index.fine_n[2] + fi[2];
  return static_cast<double>(index.fine_nearest[kf]) - index.fine_bin_radius - (c - centre).norm() -
         index.max_radius;
}

// Both O(1) bounds of the header, before the ball's radius and the margin, and the coarse cell
// a search starts from.
Bounds FastBounds(const Index& index, const Vector3& c) {
  Bounds b;
  for (int axis = 0; axis < 3; ++axis) b.cell[axis] = index.AxisCell(c[axis], axis);
  const std::int64_t k = index.Cell(b.cell[0], b.cell[1], b.cell[2]);
  b.lower = FastLower(index, c);
  const Index::Point& p = index.points[index.rep[k]];
  b.upper = Distance(c, p) - p.r;
  b.d2 = index.nearest_d2[k];
  return b;
}

}  // namespace

absl::Status CheckPointCloudOptions(const PointCloudOptions& options) {
  if (!std::isfinite(options.point_radius) || options.point_radius < 0.0) {
    return absl::InvalidArgumentError(
        absl::StrCat("point_radius ", options.point_radius, " must be finite and >= 0 (metres)"));
  }
  if (!std::isfinite(options.cell_size) || options.cell_size < 0.0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "cell_size ", options.cell_size, " must be finite and >= 0 (0: from query_radius)"));
  }
  if (options.cell_size == 0.0 &&
      !(std::isfinite(options.query_radius) && options.query_radius > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("query_radius ", options.query_radius,
                                                   " must be finite and > 0 when cell_size is 0"));
  }
  if (options.max_cells < 1 || options.max_cells > (1LL << 28)) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_cells ", options.max_cells, " must be in 1..2^28"));
  }
  return absl::OkStatus();
}

PointCloud::PointCloud(std::shared_ptr<const Index> index) : index_(std::move(index)) {}

absl::StatusOr<PointCloud> PointCloud::Create(absl::Span<const Vector3> points,
                                              absl::Span<const double> radii,
                                              const PointCloudOptions& options) {
  if (absl::Status status = CheckPointCloudOptions(options); !status.ok()) return status;
  if (static_cast<std::int64_t>(points.size()) > kMaxCloudPoints) {
    return absl::InvalidArgumentError(absl::StrCat("the cloud has ", points.size(),
                                                   " points; at most ", kMaxCloudPoints,
                                                   " (VoxelDownsample thins it)"));
  }
  if (!radii.empty() && radii.size() != points.size()) {
    return absl::InvalidArgumentError(absl::StrCat("radii has ", radii.size(), " values for ",
                                                   points.size(),
                                                   " points (give none or one per point)"));
  }
  auto index = std::make_shared<Index>();
  const std::size_t n = points.size();
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t i = 0; i < n; ++i) {
    if (!points[i].allFinite()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "point ", i, " has a coordinate that is not finite (FilterPoints drops such points)"));
    }
    const double r = radii.empty() ? options.point_radius : radii[i];
    if (!std::isfinite(r) || r < 0.0) {
      return absl::InvalidArgumentError(
          absl::StrCat("point ", i, ": radius ", r, " must be finite and >= 0"));
    }
    lo = lo.cwiseMin(points[i]);
    hi = hi.cwiseMax(points[i]);
    index->max_radius = std::max(index->max_radius, r);
  }
  if (n == 0) {
    index->start.assign(2, 0);
    return PointCloud(std::move(index));
  }
  // The cell side: as asked, grown until the grid fits max_cells and each axis 2^16 cells
  // (which keeps the distance transform's integer arithmetic exact).
  double h = options.cell_size > 0.0 ? options.cell_size : options.query_radius;
  const Vector3 extent = hi - lo;
  for (;;) {
    double cells = 1.0;
    bool fits = true;
    for (int axis = 0; axis < 3; ++axis) {
      const double count = std::floor(extent[axis] / h) + 1.0;
      fits = fits && count <= 65536.0;
      cells *= count;
    }
    if (fits && cells <= static_cast<double>(options.max_cells)) break;
    h *= 1.25;
  }
  index->h = h;
  index->origin = lo;
  for (int axis = 0; axis < 3; ++axis) {
    index->n[axis] = static_cast<int>(std::floor(extent[axis] / h)) + 1;
  }
  const std::int64_t cells = static_cast<std::int64_t>(index->n[0]) * index->n[1] * index->n[2];

  // Counting sort by cell.
  std::vector<std::uint32_t> cell_of(n);
  index->start.assign(static_cast<std::size_t>(cells) + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t k =
        index->Cell(index->AxisCell(points[i].x(), 0), index->AxisCell(points[i].y(), 1),
                    index->AxisCell(points[i].z(), 2));
    cell_of[i] = static_cast<std::uint32_t>(k);
    ++index->start[k + 1];
  }
  for (std::int64_t k = 0; k < cells; ++k) index->start[k + 1] += index->start[k];
  std::vector<std::uint32_t> fill(index->start.begin(), index->start.end() - 1);
  index->points.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = radii.empty() ? options.point_radius : radii[i];
    index->points[fill[cell_of[i]]++] = {points[i].x(), points[i].y(), points[i].z(), r};
  }
  // b: measured, so that a point binned by a rounded floor still counts.
  double scale = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    scale = std::max({scale, std::abs(lo[axis]), std::abs(lo[axis] + (index->n[axis] + 1) * h)});
  }
  index->scale = scale + index->max_radius;
  for (std::int64_t k = 0; k < cells; ++k) {
    if (index->start[k] == index->start[k + 1]) continue;
    const int iz = static_cast<int>(k % index->n[2]);
    const int iy = static_cast<int>((k / index->n[2]) % index->n[1]);
    const int ix = static_cast<int>(k / (static_cast<std::int64_t>(index->n[2]) * index->n[1]));
    const Vector3 centre(index->Centre(ix, 0), index->Centre(iy, 1), index->Centre(iz, 2));
    for (std::uint32_t i = index->start[k]; i < index->start[k + 1]; ++i) {
      const Index::Point& p = index->points[i];
      index->bin_radius = std::max(index->bin_radius, (Vector3(p.x, p.y, p.z) - centre).norm());
    }
  }
  // A little above the measured value, for the rounding of that measure.
  index->bin_radius = index->bin_radius * (1.0 + 1e-12) + kEnvironmentMargin * index->scale;

  // The distance transform of the occupied cells.
  std::vector<std::uint8_t> occupied(static_cast<std::size_t>(cells));
  for (std::int64_t k = 0; k < cells; ++k) occupied[k] = index->start[k] != index->start[k + 1];
  internal::CellDistanceTransform transform =
      internal::ComputeCellDistanceTransform(occupied, index->n);
  index->nearest.resize(static_cast<std::size_t>(cells));
  index->rep.resize(static_cast<std::size_t>(cells));
  for (std::int64_t k = 0; k < cells; ++k) {
    const double d = h * std::sqrt(static_cast<double>(transform.d2[k]));
    float f = static_cast<float>(d);
    if (static_cast<double>(f) > d) f = std::nextafter(f, 0.0f);
    index->nearest[k] = f;
    index->rep[k] = index->start[transform.site[k]];
  }
  index->nearest_d2 = std::move(transform.d2);

  // The finer transform for the lower bounds.
  int f = 3;
  auto fits = [&](int factor) {
    if (static_cast<double>(cells) * factor * factor * factor >
        static_cast<double>(options.max_cells)) {
      return false;
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (static_cast<std::int64_t>(index->n[axis]) * factor > 65536) return false;
    }
    return true;
  };
  while (f > 1 && !fits(f)) --f;
  index->fine = f;
  const double hf = h / f;
  for (int axis = 0; axis < 3; ++axis) index->fine_n[axis] = index->n[axis] * f;
  const std::int64_t fine_cells =
      static_cast<std::int64_t>(index->fine_n[0]) * index->fine_n[1] * index->fine_n[2];
  std::vector<std::uint8_t> fine_occupied(static_cast<std::size_t>(fine_cells), 0);
  for (const Index::Point& p : index->points) {
    int fi[3];
    Vector3 centre;
    const double v[3] = {p.x, p.y, p.z};
    for (int axis = 0; axis < 3; ++axis) {
      const double t = std::floor((v[axis] - lo[axis]) / hf);
      fi[axis] = !(t >= 0.0)                    ? 0
                 : t >= index->fine_n[axis] - 1 ? index->fine_n[axis] - 1
                                                : static_cast<int>(t);
      centre[axis] = lo[axis] + (fi[axis] + 0.5) * hf;
    }
    fine_occupied[(static_cast<std::int64_t>(fi[0]) * index->fine_n[1] + fi[1]) * index->fine_n[2] +
                  fi[2]] = 1;
    index->fine_bin_radius =
        std::max(index->fine_bin_radius, (Vector3(p.x, p.y, p.z) - centre).norm());
  }
  index->fine_bin_radius =
      index->fine_bin_radius * (1.0 + 1e-12) + kEnvironmentMargin * index->scale;
  const internal::CellDistanceTransform fine =
      internal::ComputeCellDistanceTransform(fine_occupied, index->fine_n);
  index->fine_nearest.resize(static_cast<std::size_t>(fine_cells));
  for (std::int64_t k = 0; k < fine_cells; ++k) {
    const double d = hf * std::sqrt(static_cast<double>(fine.d2[k]));
    float rounded = static_cast<float>(d);
    if (static_cast<double>(rounded) > d) rounded = std::nextafter(rounded, 0.0f);
    index->fine_nearest[k] = rounded;
  }
  return PointCloud(std::move(index));
}

std::int64_t PointCloud::size() const { return static_cast<std::int64_t>(index_->points.size()); }
double PointCloud::cell_size() const { return index_->h; }
std::int64_t PointCloud::cells() const {
  return static_cast<std::int64_t>(index_->start.size()) - 1;
}

std::vector<Vector3> PointCloud::Points() const {
  std::vector<Vector3> out;
  out.reserve(index_->points.size());
  for (const Index::Point& p : index_->points) out.emplace_back(p.x, p.y, p.z);
  return out;
}

int PointCloud::FirstColliding(absl::Span<const Sphere> balls) const {
  const Index& index = *index_;
  if (index.points.empty()) return -1;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Sphere& ball = balls[i];
    const double margin = index.Margin(ball);
    // The lower bound alone first: it decides most balls, without touching the points.
    if (FastLower(index, ball.center) - ball.radius - margin > 0.0) continue;
    const Bounds b = FastBounds(index, ball.center);
    if (b.upper - ball.radius - margin <= 0.0) return static_cast<int>(i);
    const Vector3& c = ball.center;
    const double reach = ball.radius + index.max_radius + margin;
    const bool hit = VisitNear(index, c, reach, b.d2, b.cell, [&](const Index::Point& p) {
      const double dx = c.x() - p.x, dy = c.y() - p.y, dz = c.z() - p.z;
      const double limit = ball.radius + p.r + margin;
      return dx * dx + dy * dy + dz * dz <= limit * limit;
    });
    if (hit) return static_cast<int>(i);
  }
  return -1;
}

void PointCloud::Clearances(absl::Span<const Sphere> balls, const ClearanceRequest& request,
                            absl::Span<ClearanceInterval> out) const {
  assert(out.size() == balls.size());
  const Index& index = *index_;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Sphere& ball = balls[i];
    if (index.points.empty()) {
      out[i] = {kInf, kInf};
      continue;
    }
    const double margin = index.Margin(ball);
    const Bounds b = FastBounds(index, ball.center);
    ClearanceInterval interval{b.lower - ball.radius - margin, b.upper - ball.radius + margin};
    if (interval.lower >= request.max_distance ||
        interval.upper - interval.lower <= request.tolerance) {
      out[i] = interval;
      continue;
    }
    // Exact: the smallest |c - p| - r_p below `cap` (the rep's value, or max_distance's).
    const Vector3& c = ball.center;
    const double cap = std::min(b.upper, request.max_distance + ball.radius);
    double best = b.upper <= cap ? b.upper : kInf;
    VisitNear(index, c, cap + index.max_radius + margin, b.d2, b.cell, [&](const Index::Point& p) {
      best = std::min(best, Distance(c, p) - p.r);
      return false;
    });
    if (best <= cap) {
      interval = {best - ball.radius - margin, best - ball.radius + margin};
    } else {
      interval.lower = std::max(interval.lower, request.max_distance - margin);
    }
    out[i] = interval;
  }
}

}  // namespace inscribe
