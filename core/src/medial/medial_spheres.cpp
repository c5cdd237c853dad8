// Medial-sphere generation, paper Section III. See medial_spheres.h for the contract.
//
// Per voxel v (side s, centre c, circumradius R = s*sqrt(3)/2): for each sample p on the sphere
// S(c, R), with B(p) its nearest boundary point, q is the other intersection of the line
// p + g (p - B(p)) with S. The medial surface crosses segment (p, q) iff B(p) != B(q) (paper, after
// [17]), so for those pairs a bracketing search locates the crossing to within epsilon. The
// crossing's object angle is the angle at it between the nearest boundary points of the two
// bracket ends. Of the candidates that pass the angle test, lie in v and lie inside the mesh, v
// keeps the one with the largest radius: the paper leaves the choice open, and the largest ball
// removes the most volume error.
#include "inscribe/medial/medial_spheres.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "base/parallel.h"
#include "medial/voxel_grid.h"

namespace inscribe {
namespace {

using internal::Grid;
using internal::VisitedVoxel;

constexpr double kSqrt3 = 1.7320508075688772;

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// K directions spread evenly over the unit sphere (Fibonacci lattice). The same set serves every
// voxel, so a voxel's result depends only on its position.
std::vector<Vector3> FibonacciDirections(int count) {
  std::vector<Vector3> directions;
  directions.reserve(static_cast<std::size_t>(count));
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / count;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    directions.emplace_back(rho * std::cos(phi), rho * std::sin(phi), z);
  }
  return directions;
}

// The same directions, reordered so that the first `count` are spread over the whole sphere
// (every (K / count)-th point of the Fibonacci spiral, which runs from pole to pole).
std::vector<Vector3> ScreeningSubsetFirst(const std::vector<Vector3>& directions,
                                          std::size_t count) {
  if (count == 0) return directions;
  std::vector<char> taken(directions.size(), 0);
  std::vector<Vector3> ordered;
  ordered.reserve(directions.size());
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t index = (2 * i + 1) * directions.size() / (2 * count);
    taken[index] = 1;
    ordered.push_back(directions[index]);
  }
  for (std::size_t i = 0; i < directions.size(); ++i) {
    if (!taken[i]) ordered.push_back(directions[i]);
  }
  return ordered;
}
struct Candidate {
  Sphere sphere;
  SurfaceContact contact;
  bool valid = false;
};

struct VoxelCounters {
  std::int64_t crossing_pairs = 0;
  std::int64_t searched_pairs = 0;
  std::int64_t candidates = 0;
  std::int64_t queries = 0;
};

struct SearchParams {
  double object_angle = 0.0;
  double epsilon = 0.0;
  // Two nearest boundary points closer than this count as the same point.
  double same_point_tolerance = 0.0;
  double pair_angle_margin = 0.0;
};

class VoxelSearch {
 public:
  // `directions`: the K sample directions, the first `screen_count` of them an evenly spread
  // subset used for screening (0: no screening).
  VoxelSearch(const BoundaryOracle& oracle, const std::vector<Vector3>& directions,
              std::size_t screen_count, const SearchParams& params)
      : oracle_(oracle), directions_(directions), screen_count_(screen_count), params_(params) {}

  // Best candidate in the cube [corner, corner + size)^3. The screening subset runs first; a
  // voxel where none of its segments crosses the medial surface inside the voxel is left empty
  // without the other samples. `last_foot`: a boundary point found before (the previous
  // voxel's), which bounds the first sample's query; updated to this voxel's last.
  Candidate Run(const Vector3& corner, double size, VoxelCounters& counters,
                std::optional<Vector3>& last_foot) const {
    Candidate best;
    best.sphere.radius = -1.0;
    const std::int64_t searched_before = counters.searched_pairs;
    Sample(0, screen_count_, corner, size, best, counters, last_foot);
    if (screen_count_ > 0 && counters.searched_pairs == searched_before) return best;
    Sample(screen_count_, directions_.size(), corner, size, best, counters, last_foot);
    return best;
  }

 private:
  // The previous sample's nearest boundary point bounds the next sample's query.
  void Sample(std::size_t first, std::size_t last, const Vector3& corner, double size,
              Candidate& best, VoxelCounters& counters,
              std::optional<Vector3>& previous_foot) const {
    const Vector3 centre = corner + Vector3::Constant(0.5 * size);
    const double circumradius = 0.5 * kSqrt3 * size;
    for (std::size_t d = first; d < last; ++d) {
      const Vector3 p = centre + circumradius * directions_[d];
      const BoundaryPoint bp =
          previous_foot ? Query(p, *previous_foot, counters) : Query(p, counters);
      previous_foot = bp.point;
      const Vector3 away = p - bp.point;
      const double away_length = away.norm();
      if (!(away_length > 1e-12 * circumradius)) continue;  // p on the boundary
      const Vector3 unit = away / away_length;
      // p + t*unit meets S again at t = -2 (p - c).unit.
      const double t = -2.0 * (p - centre).dot(unit);
      if (!(std::abs(t) > 1e-9 * circumradius)) continue;  // the line only touches S
      const Vector3 q = p + t * unit;
      // Only a crossing inside the voxel is kept: a segment that misses the voxel (padded by
      // epsilon) needs neither q's query nor a search.
      std::array<double, 2> inside_voxel;
      if (!ClipToBox(p, q - p, corner, size, params_.epsilon, inside_voxel)) continue;
      const BoundaryPoint bq = Query(q, bp.point, counters);
      if ((bq.point - bp.point).norm() <= params_.same_point_tolerance) continue;
      ++counters.crossing_pairs;
      // When both nearest boundary points lie inside faces, the angle between the two ends'
      // directions to them is the crossing's object angle (if the crossing's own nearest points
      // lie on those faces): pairs far below theta are not searched. Near edges and corners
      // the directions can differ much from the crossing's, so those pairs are always searched.
      if (InFaceInterior(bp) && InFaceInterior(bq)) {
        const Vector3 from_p = bp.point - p;
        const Vector3 from_q = bq.point - q;
        const double pair_angle = std::atan2(from_p.cross(from_q).norm(), from_p.dot(from_q));
        if (pair_angle < params_.object_angle - params_.pair_angle_margin) continue;
      }
      ++counters.searched_pairs;
      // No point of the segment is farther than this from the boundary: skip searches that
      // cannot beat the best radius so far.
      const double radius_bound = 0.5 * (bp.distance + bq.distance + std::abs(t));
      if (radius_bound <= best.sphere.radius) continue;
      TryCrossing(p, bp, q, bq, inside_voxel, corner, size, best, counters);
    }
  }

  // Inside a triangle, off its edges and corners (the closest-point routine gives exact zero
  // weights on edges and corners).
  static bool InFaceInterior(const BoundaryPoint& foot) {
    return foot.barycentric.minCoeff() > 0.0;
  }

  BoundaryPoint Query(const Vector3& x, VoxelCounters& counters) const {
    ++counters.queries;
    return oracle_.ClosestPoint(x);
  }

  // The same answer, faster: `known` is a boundary point, so the nearest one is no farther
  // than it.
  BoundaryPoint Query(const Vector3& x, const Vector3& known, VoxelCounters& counters) const {
    ++counters.queries;
    return oracle_.ClosestPointNear(x, known);
  }

  // Locates the medial crossing on (p, q) to within epsilon and keeps it in `best` if it passes.
  // The part of segment p + s*d, s in [0, 1], inside the cube [corner, corner + size]^3
  // grown by `pad` on every side, as [s_in, s_out] in `interval`; false if it misses.
  static bool ClipToBox(const Vector3& p, const Vector3& d, const Vector3& corner, double size,
                        double pad, std::array<double, 2>& interval) {
    double s_in = 0.0;
    double s_out = 1.0;
    for (int axis = 0; axis < 3; ++axis) {
      const double lo = corner[axis] - pad;
      const double hi = corner[axis] + size + pad;
      if (d[axis] == 0.0) {
        if (p[axis] < lo || p[axis] > hi) return false;
        continue;
      }
      double a = (lo - p[axis]) / d[axis];
      double b = (hi - p[axis]) / d[axis];
      if (a > b) std::swap(a, b);
      s_in = std::max(s_in, a);
      s_out = std::min(s_out, b);
      if (s_in > s_out) return false;
    }
    interval = {s_in, s_out};
    return true;
  }

  // `inside_voxel`: the segment parameters inside the (padded) voxel; once the bracket leaves
  // that interval the crossing it converges to lies outside the voxel, and the search stops.
  void TryCrossing(const Vector3& p, const BoundaryPoint& bp, const Vector3& q,
                   const BoundaryPoint& bq, const std::array<double, 2>& inside_voxel,
                   const Vector3& corner, double size, Candidate& best,
                   VoxelCounters& counters) const {
    const Vector3 segment = q - p;
    const double length = segment.norm();
    // Parameter s in [0, 1] along the segment; the bracket [lo, hi] has nearest boundary points
    // a (the p side) and b (the q side).
    double lo = 0.0;
    double hi = 1.0;
    BoundaryPoint a = bp;
    BoundaryPoint b = bq;
    const double tolerance = params_.epsilon / length;  // bracket width to reach, in s
    const double half_step = 0.49 * tolerance;
    int misses = 0;
    // A point's nearest boundary point belongs to the p side if it is closer to a than to b.
    auto on_p_side = [&](const BoundaryPoint& f) {
      return (f.point - a.point).squaredNorm() <= (f.point - b.point).squaredNorm();
    };
    auto probe = [&](double s) {
      const Vector3 x = p + s * segment;
      const BoundaryPoint f =
          Query(x, (x - a.point).squaredNorm() < (x - b.point).squaredNorm() ? a.point : b.point,
                counters);
      if (on_p_side(f)) {
        lo = s;
        a = f;
        return true;
      }
      hi = s;
      b = f;
      return false;
    };
    while (hi - lo > tolerance) {
      if (hi < inside_voxel[0] || lo > inside_voxel[1]) return;
      double estimate = std::numeric_limits<double>::quiet_NaN();
      if (misses < 3) estimate = CrossingEstimate(p, segment, lo, a, hi, b);
      if (std::isfinite(estimate) && estimate > lo && estimate < hi) {
        // Probe just before and just after the estimate: when it is right (the usual case for
        // locally flat boundary), two queries close the bracket to within epsilon.
        const double before = std::max(lo, estimate - half_step);
        const double after = std::min(hi, estimate + half_step);
        if (before > lo && !probe(before)) {
          ++misses;
          continue;
        }
        if (after < hi && probe(after)) ++misses;
      } else {
        probe(0.5 * (lo + hi));
      }
    }
    const Vector3 m = p + 0.5 * (lo + hi) * segment;
    const Vector3 to_a = a.point - m;
    const Vector3 to_b = b.point - m;
    const double angle = std::atan2(to_a.cross(to_b).norm(), to_a.dot(to_b));
    if (!(angle >= params_.object_angle)) return;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(m[axis] >= corner[axis] && m[axis] < corner[axis] + size)) return;
    }
    const BoundaryPoint contact =
        Query(m, to_a.squaredNorm() < to_b.squaredNorm() ? a.point : b.point, counters);
    if (!(contact.distance > best.sphere.radius) || !(contact.distance > 0.0)) return;
    if (oracle_.Classify(m) != Side::kInside) return;
    ++counters.candidates;
    best.valid = true;
    best.sphere = Sphere{m, contact.distance};
    best.contact = SurfaceContact{contact.triangle, contact.barycentric};
  }

  // Where the two sides' distance functions, each linearised at its own bracket end (distance
  // to the tangent plane through its nearest boundary point), are equal. Exact when both
  // nearest features are planar faces; NaN when undefined.
  static double CrossingEstimate(const Vector3& p, const Vector3& segment, double lo,
                                 const BoundaryPoint& a, double hi, const BoundaryPoint& b) {
    const Vector3 x_lo = p + lo * segment;
    const Vector3 x_hi = p + hi * segment;
    const double d_lo = (x_lo - a.point).norm();
    const double d_hi = (x_hi - b.point).norm();
    if (!(d_lo > 0.0) || !(d_hi > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    const double slope_lo = (x_lo - a.point).dot(segment) / d_lo;
    const double slope_hi = (x_hi - b.point).dot(segment) / d_hi;
    const double denominator = slope_lo - slope_hi;
    if (!(std::abs(denominator) > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return (d_hi - d_lo + slope_lo * lo - slope_hi * hi) / denominator;
  }

  const BoundaryOracle& oracle_;
  const std::vector<Vector3>& directions_;
  std::size_t screen_count_;
  SearchParams params_;
};

}  // namespace

absl::Status CheckMedialSphereOptions(const MedialSphereOptions& options, bool need_voxel_size) {
  if (need_voxel_size && !(std::isfinite(options.voxel_size) && options.voxel_size > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("voxel size must be a positive finite number, got ", options.voxel_size));
  }
  if (!(options.object_angle > 0.0 && options.object_angle < M_PI)) {
    return absl::InvalidArgumentError(
        absl::StrCat("object angle must lie in (0, pi) radians, got ", options.object_angle));
  }
  if (!(std::isfinite(options.epsilon) && options.epsilon >= 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("epsilon must be a finite number >= 0, got ", options.epsilon));
  }
  if (options.samples < 2 || options.samples > 4096) {
    return absl::InvalidArgumentError(
        absl::StrCat("samples per voxel must lie in [2, 4096], got ", options.samples));
  }
  if (options.screen_samples < 0 || options.screen_samples > 4096) {
    return absl::InvalidArgumentError(absl::StrCat(
        "screening samples per voxel must lie in [0, 4096], got ", options.screen_samples));
  }
  if (!(options.pair_angle_margin >= 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the pair-angle margin must be a number >= 0, got ", options.pair_angle_margin));
  }
  if (options.max_voxels <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("the voxel limit must be positive, got ", options.max_voxels));
  }
  return absl::OkStatus();
}

absl::StatusOr<MedialSphereResult> GenerateMedialSpheres(const BoundaryOracle& oracle,
                                                         const MedialSphereOptions& options,
                                                         const GenerationControl& control) {
  const Clock::time_point start = Clock::now();
  if (absl::Status status = CheckMedialSphereOptions(options, /*need_voxel_size=*/true);
      !status.ok()) {
    return status;
  }
  const Mesh& mesh = oracle.mesh();
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const double diagonal = box.diagonal();
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) {
    return absl::InvalidArgumentError("mesh has an empty or non-finite bounding box");
  }
  absl::StatusOr<Grid> grid = internal::MakeGrid(box, options.voxel_size, options.max_voxels);
  if (!grid.ok()) return grid.status();

  MedialSphereResult result;
  result.voxel_size = options.voxel_size;
  result.epsilon = options.epsilon > 0.0 ? options.epsilon : 1e-4 * diagonal;
  result.stats.grid_voxels = grid->count();
  result.grid_origin = grid->origin;
  result.grid_dims = grid->dims;

  SearchParams params;
  params.object_angle = options.object_angle;
  params.epsilon = result.epsilon;
  params.same_point_tolerance = 1e-9 * diagonal;
  params.pair_angle_margin = options.pair_angle_margin;
  const std::size_t screen_count =
      options.screen_samples > 0 && options.screen_samples < options.samples
          ? static_cast<std::size_t>(options.screen_samples)
          : 0;
  const std::vector<Vector3> directions =
      ScreeningSubsetFirst(FibonacciDirections(options.samples), screen_count);
  const VoxelSearch search(oracle, directions, screen_count, params);

  if (control.cancelled()) return absl::CancelledError("medial-sphere generation cancelled");
  std::int64_t queries = 0;
  const std::vector<VisitedVoxel> voxels =
      internal::CullVoxels(oracle, *grid, queries, control.cancel);
  if (control.cancelled()) return absl::CancelledError("medial-sphere generation cancelled");
  result.stats.visited_voxels = static_cast<std::int64_t>(voxels.size());
  for (const VisitedVoxel& voxel : voxels) result.stats.boundary_voxels += voxel.boundary;

  // Each voxel (or each of its 8 halves) yields at most one candidate, stored in its slot so
  // that the output order, and so the output, do not depend on scheduling.
  std::vector<char> screened_in;
  if (options.corner_screen) {
    screened_in = internal::ScreenByCorners(
        oracle, *grid, voxels, options.object_angle - internal::kCornerScreenMargin,
        internal::kCornerScreenReach * grid->size, queries, control.cancel);
    if (control.cancelled()) return absl::CancelledError("medial-sphere generation cancelled");
  }
  for (char pass : screened_in) result.stats.screened_voxels += pass == 0;
  const int slots = options.subdivide_boundary ? 8 : 1;
  const double size = grid->size;
  const std::size_t batch = 2048;
  for (std::size_t first = 0; first < voxels.size(); first += batch) {
    if (control.cancelled()) return absl::CancelledError("medial-sphere generation cancelled");
    const std::size_t last = std::min(voxels.size(), first + batch);
    std::vector<Candidate> found((last - first) * static_cast<std::size_t>(slots));
    std::vector<VoxelCounters> counters(last - first);
    internal::ParallelForRange(first, last, 8, [&](std::size_t begin, std::size_t end) {
      std::optional<Vector3> last_foot;  // bounds queries only: the answers do not depend on it
      for (std::size_t v = begin; v != end; ++v) {
        if (control.cancelled()) return;
        if (!screened_in.empty() && !screened_in[v]) continue;
        const VisitedVoxel& voxel = voxels[v];
        const Vector3 corner = grid->corner(voxel.index[0], voxel.index[1], voxel.index[2]);
        VoxelCounters& count = counters[v - first];
        Candidate* out = &found[(v - first) * static_cast<std::size_t>(slots)];
        if (!options.subdivide_boundary || !voxel.boundary) {
          out[0] = search.Run(corner, size, count, last_foot);
          continue;
        }
        const double half = 0.5 * size;
        for (int octant = 0; octant < 8; ++octant) {
          const Vector3 sub_corner =
              corner + half * Vector3((octant & 1) ? 1.0 : 0.0, (octant & 2) ? 1.0 : 0.0,
                                      (octant & 4) ? 1.0 : 0.0);
          ++count.queries;
          const double distance = oracle.SignedDistance(sub_corner + Vector3::Constant(0.5 * half));
          if (distance > 0.5 * kSqrt3 * half) continue;  // this half is wholly outside
          out[octant] = search.Run(sub_corner, half, count, last_foot);
        }
      }
    });
    if (control.cancelled()) return absl::CancelledError("medial-sphere generation cancelled");
    for (const Candidate& candidate : found) {
      if (!candidate.valid) continue;
      result.set.spheres.push_back(candidate.sphere);
      result.set.contacts.push_back(candidate.contact);
    }
    for (const VoxelCounters& count : counters) {
      result.stats.crossing_pairs += count.crossing_pairs;
      result.stats.searched_pairs += count.searched_pairs;
      result.stats.candidates += count.candidates;
      queries += count.queries;
    }
    if (control.on_progress) {
      control.on_progress(static_cast<double>(last) / static_cast<double>(voxels.size()));
    }
  }
  if (voxels.empty() && control.on_progress) control.on_progress(1.0);
  result.stats.closest_point_queries = queries;
  result.stats.seconds = SecondsSince(start);
  return result;
}

}  // namespace inscribe
