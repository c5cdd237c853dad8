#include "inscribe/cover/cover_certificate.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <tuple>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "cover/cover_cells.h"
#include "inscribe/geometry/mesh_hash.h"

namespace inscribe {
namespace {

// Levels below which children are visited in parallel (8^3 = 512 subtrees).
constexpr int kParallelLevels = 3;
// The resolution of the first pass that looks for a point of the solid in no sphere.
constexpr double kWitnessPassResolution = 1.0 / 256;
// Relative margins, far above the rounding of the few operations each test makes (a dozen
// roundings of 2^-53 each), so that a settled cell is settled in exact arithmetic too.
constexpr double kContainMargin = 1e-12;  // on squared distances
constexpr double kOutsideMargin = 1e-9;   // on the distance to the boundary
const double kHalfDiagonalPerSide = std::sqrt(3.0) / 2.0 * (1.0 + 1e-12);

using Index = std::array<std::int64_t, 3>;

// A finest cell left unsettled, and whether its centre shows the set is not a cover.
struct Failure {
  int level = 0;
  Index index;
  Vector3 min = Vector3::Zero(), centre = Vector3::Zero();
  double side = 0.0;
  double depth = 0.0;  // of the centre, when it is a witness
};

// Cells in a fixed order: by level, then x, y, z index.
bool Before(const Failure& a, const Failure& b) {
  return std::tie(a.level, a.index) < std::tie(b.level, b.index);
}

// The deeper witness; of two as deep, the one with the smaller index (so the choice does not
// depend on which thread found which).
bool Deeper(const Failure& a, const Failure& b) {
  return a.depth > b.depth || (a.depth == b.depth && Before(a, b));
}

// The counts of a subtree of the octree. Of its failed cells it keeps the `keep` first in
// Before order (and at most 2 * keep between trims), so merging subtrees in any order keeps
// the same cells: the result does not depend on the schedule.
class Counts {
 public:
  explicit Counts(std::int64_t keep) : keep_(static_cast<std::size_t>(keep)) {}

  std::int64_t cells = 0, in_sphere = 0, outside = 0, failed = 0;
  std::optional<Failure> deepest;  // the deepest witness

  // A failed cell; a witness's centre is a point of the solid in no sphere.
  void Fail(const Failure& failure, bool witness) {
    ++failed;
    if (witness && (!deepest || Deeper(failure, *deepest))) deepest = failure;
    if (keep_ == 0) return;
    failures_.push_back(failure);
    if (failures_.size() > 2 * keep_) Trim();
  }

  void Merge(Counts&& other) {
    cells += other.cells;
    in_sphere += other.in_sphere;
    outside += other.outside;
    failed += other.failed;
    if (other.deepest && (!deepest || Deeper(*other.deepest, *deepest))) {
      deepest = other.deepest;
    }
    failures_.insert(failures_.end(), other.failures_.begin(), other.failures_.end());
    if (failures_.size() > 2 * keep_) Trim();
  }

  // The kept failed cells, sorted.
  std::vector<Failure> TakeFailures() && {
    Trim();
    std::sort(failures_.begin(), failures_.end(), Before);
    return std::move(failures_);
  }

 private:
  void Trim() {
    if (failures_.size() <= keep_) return;
    std::nth_element(failures_.begin(), failures_.begin() + static_cast<std::ptrdiff_t>(keep_),
                     failures_.end(), Before);
    failures_.resize(keep_);
  }

  std::size_t keep_;
  std::vector<Failure> failures_;
};

class Certifier {
 public:
  Certifier(const Solid& solid, const std::vector<Sphere>& spheres,
            const CoverCertifyOptions& options, const GenerationControl& control)
      : oracle_(solid.oracle), spheres_(spheres), options_(options), control_(control) {
    const internal::OctreeFrame frame =
        internal::MakeOctreeFrame(ComputeBoundingBox(solid.mesh().vertices), options.resolution);
    scale_ = frame.scale;
    side_ = frame.side;
    origin_ = frame.origin;
    finest_ = frame.finest;
  }

  double finest_side() const { return std::ldexp(side_, -finest_); }
  double scale() const { return scale_; }

  absl::StatusOr<Counts> Run() {
    std::vector<std::int32_t> all(spheres_.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int32_t>(i);
    Counts counts(options_.max_failures_kept);
    Visit(0, {0, 0, 0}, all, std::numeric_limits<double>::infinity(), &counts);
    if (Cancelled()) return absl::CancelledError("cover certification cancelled");
    return counts;
  }

 private:
  bool Cancelled() const { return control_.cancelled(); }

  // Settles the cell or splits it, counting into `out`; the first levels' children run in
  // parallel, each into counts of its own merged into the parent's as it ends.
  void Visit(int level, const Index& index, const std::vector<std::int32_t>& candidates,
             double distance_bound, Counts* out) {
    if (Cancelled()) return;
    Counts& counts = *out;
    ++counts.cells;
    const double side = std::ldexp(side_, -level);
    Vector3 lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = origin_[k] + static_cast<double>(index[k]) * side;
      hi[k] = lo[k] + side;
    }
    // The spheres that reach into the cell; one containing it settles it.
    std::vector<std::int32_t> near;
    near.reserve(candidates.size());
    for (const std::int32_t i : candidates) {
      const Sphere& s = spheres_[static_cast<std::size_t>(i)];
      double inside2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double gap = std::max({lo[k] - s.center[k], s.center[k] - hi[k], 0.0});
        inside2 += gap * gap;
      }
      const double far2 = internal::FarthestCornerSquared(s.center, lo, hi);
      const double r2 = s.radius * s.radius;
      if (far2 * (1.0 + kContainMargin) <= r2) {
        ++counts.in_sphere;
        Settled(level);
        return;
      }
      if (inside2 < r2) near.push_back(i);
    }
    const Vector3 centre = lo + Vector3::Constant(0.5 * side);
    const BoundaryPoint closest = std::isfinite(distance_bound)
                                      ? oracle_.ClosestPoint(centre, distance_bound)
                                      : oracle_.ClosestPoint(centre);
    const double half_diagonal = side * kHalfDiagonalPerSide;
    const Side centre_side = oracle_.Classify(centre, closest);
    if (closest.distance > half_diagonal * (1.0 + kOutsideMargin) + 1e-12 * scale_ &&
        centre_side == Side::kOutside) {
      ++counts.outside;
      Settled(level);
      return;
    }
    const bool witness = centre_side == Side::kInside && !InAny(centre, near);
    if (level == finest_ || (witness && options_.stop_at_witness)) {
      Failure failure{level, index, lo, centre, side, 0.0};
      if (witness) failure.depth = closest.distance;
      counts.Fail(failure, witness);
      Settled(level);
      return;
    }
    const double child_bound = closest.distance + half_diagonal;
    const auto child = [&](int c, Counts* into) {
      const Index sub = {2 * index[0] + (c & 1), 2 * index[1] + ((c >> 1) & 1),
                         2 * index[2] + ((c >> 2) & 1)};
      Visit(level + 1, sub, near, child_bound, into);
    };
    if (level < kParallelLevels) {
      std::mutex merge_mutex;
      internal::ParallelFor(0, 8, [&](int c) {
        Counts sub(options_.max_failures_kept);
        child(c, &sub);
        const std::lock_guard<std::mutex> lock(merge_mutex);
        counts.Merge(std::move(sub));
      });
    } else {
      for (int c = 0; c < 8; ++c) child(c, &counts);
    }
    if (level == kParallelLevels) Settled(level);
  }

  // Strictly outside every sphere listed, with margin.
  bool InAny(const Vector3& p, const std::vector<std::int32_t>& listed) const {
    for (const std::int32_t i : listed) {
      const Sphere& s = spheres_[static_cast<std::size_t>(i)];
      if ((p - s.center).squaredNorm() <= s.radius * s.radius * (1.0 + kContainMargin)) {
        return true;
      }
    }
    return false;
  }

  // Progress: the share of the level-3 subtrees done.
  void Settled(int level) {
    if (level > kParallelLevels || !control_.on_progress) return;
    const std::int64_t weight = std::int64_t{1} << (3 * (kParallelLevels - level));
    const std::int64_t done = settled_.fetch_add(weight) + weight;
    std::lock_guard<std::mutex> lock(progress_mutex_);
    control_.on_progress(static_cast<double>(done) / (1 << (3 * kParallelLevels)));
  }

  const BoundaryOracle& oracle_;
  const std::vector<Sphere>& spheres_;
  const CoverCertifyOptions& options_;
  const GenerationControl& control_;
  double scale_ = 1.0, side_ = 1.0;
  Vector3 origin_ = Vector3::Zero();
  int finest_ = 0;
  std::atomic<std::int64_t> settled_{0};
  std::mutex progress_mutex_;
};

}  // namespace

absl::StatusOr<std::vector<double>> SphereProtrusions(const Solid& solid,
                                                      const std::vector<Sphere>& spheres) {
  if (absl::Status s = CheckSpheres(spheres); !s.ok()) return s;
  // The oracle's distances err by a few ulps of the coordinates, not of the extent.
  const BoundingBox box = ComputeBoundingBox(solid.mesh().vertices);
  const double scale = std::max(
      {box.extent().maxCoeff(), box.min.cwiseAbs().maxCoeff(), box.max.cwiseAbs().maxCoeff()});
  std::vector<double> protrusions(spheres.size());
  internal::ParallelFor(std::size_t{0}, spheres.size(), [&](std::size_t i) {
    const Sphere& s = spheres[i];
    const BoundaryPoint closest = solid.oracle.ClosestPoint(s.center);
    // Depth of the centre: + inside, - outside. A centre too close to the boundary for its
    // side to matter counts as outside (the larger protrusion).
    const bool inside = solid.oracle.Classify(s.center, closest) == Side::kInside &&
                        closest.distance > 1e-9 * scale;
    const double depth = inside ? closest.distance : -closest.distance;
    // Rounded up: the distance and the subtraction are each within a few ulps.
    const double p = s.radius - depth;
    protrusions[i] = p + 1e-12 * std::abs(p) + 1e-12 * scale;
  });
  return protrusions;
}

absl::StatusOr<double> SphereProtrusionBound(const Solid& solid,
                                             const std::vector<Sphere>& spheres) {
  absl::StatusOr<std::vector<double>> protrusions = SphereProtrusions(solid, spheres);
  if (!protrusions.ok()) return protrusions.status();
  double delta = 0.0;
  for (const double p : *protrusions) delta = std::max(delta, p);
  return delta;
}

absl::StatusOr<std::vector<Sphere>> CoverCores(const std::vector<Sphere>& cover,
                                               const std::vector<double>& protrusions) {
  if (protrusions.size() != cover.size()) {
    return absl::InvalidArgumentError(absl::StrCat("cover protrusions: ", protrusions.size(),
                                                   " values for ", cover.size(), " spheres"));
  }
  std::vector<Sphere> cores;
  for (std::size_t i = 0; i < cover.size(); ++i) {
    if (!std::isfinite(protrusions[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("cover protrusions: value ", i, " (", protrusions[i], ") is not finite"));
    }
    const double radius = cover[i].radius - protrusions[i];
    if (radius > 0.0) cores.push_back(Sphere{cover[i].center, radius});
  }
  return cores;
}

absl::Status CheckCoverCertificateBinding(const CoverCertificate& certificate,
                                          const std::vector<Sphere>& spheres,
                                          absl::string_view mesh_sha256) {
  if (certificate.spheres_sha256.empty() || certificate.mesh_sha256.empty()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the cover certificate names no ", certificate.spheres_sha256.empty() ? "spheres" : "mesh",
        " it was proved for (it was recorded without them, or by an older inscribe): certify "
        "the spheres again against their mesh"));
  }
  const std::string given = FormatSha256(SpheresSha256(spheres));
  if (certificate.spheres_sha256 != given) {
    return absl::FailedPreconditionError(
        absl::StrCat("the cover certificate was made for other spheres (",
                     certificate.spheres_sha256, ") than these ", spheres.size(), " (", given,
                     "): the spheres were edited after they were certified; certify them again "
                     "against their mesh"));
  }
  if (certificate.protrusions.size() != spheres.size()) {
    return absl::FailedPreconditionError(
        absl::StrCat("the cover certificate holds ", certificate.protrusions.size(),
                     " protrusions for ", spheres.size(),
                     " spheres (one per sphere is needed); certify them again against their mesh"));
  }
  if (!mesh_sha256.empty() && certificate.mesh_sha256 != mesh_sha256) {
    return absl::FailedPreconditionError(
        absl::StrCat("the cover certificate was proved against mesh ", certificate.mesh_sha256,
                     ", not ", mesh_sha256, ": certify the spheres again against this mesh"));
  }
  return absl::OkStatus();
}

absl::Status CheckCoverCertifyOptions(const CoverCertifyOptions& options) {
  if (!(options.resolution > 0.0 && options.resolution <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("cover resolution must lie in (0, 1], got ", options.resolution));
  }
  if (options.max_failures_kept < 0) {
    return absl::InvalidArgumentError("max_failures_kept must be >= 0");
  }
  return absl::OkStatus();
}

absl::StatusOr<CoverCertificate> CertifyCover(const Solid& solid,
                                              const std::vector<Sphere>& spheres,
                                              const CoverCertifyOptions& options,
                                              const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = CheckCoverCertifyOptions(options); !s.ok()) return s;
  absl::StatusOr<std::vector<double>> protrusions = SphereProtrusions(solid, spheres);
  if (!protrusions.ok()) return protrusions.status();

  // With stop_at_witness, a coarse pass first: a set that misses a point of the solid usually
  // shows it there, without splitting the cells along its tangencies down to the finest.
  CoverCertifyOptions coarse = options;
  coarse.resolution = std::max(options.resolution, kWitnessPassResolution);
  const bool two_passes = options.stop_at_witness && coarse.resolution > options.resolution;
  GenerationControl quiet;
  quiet.cancel = control.cancel;
  Certifier first(solid, spheres, coarse, quiet);
  std::optional<Counts> counts;
  if (two_passes) {
    absl::StatusOr<Counts> coarse_counts = first.Run();
    if (!coarse_counts.ok()) return coarse_counts.status();
    counts = *std::move(coarse_counts);
  }
  Certifier full(solid, spheres, options, control);
  const bool disproved = counts && counts->deepest.has_value();
  if (!disproved) {
    absl::StatusOr<Counts> full_counts = full.Run();
    if (!full_counts.ok()) return full_counts.status();
    counts = *std::move(full_counts);
  }
  const Certifier& certifier = disproved ? first : full;

  CoverCertificate out;
  out.certified = counts->failed == 0;
  out.mesh_sha256 = solid.sha256;
  out.spheres_sha256 = FormatSha256(SpheresSha256(spheres));
  for (const double p : *protrusions) out.delta = std::max(out.delta, p);
  out.protrusions = *std::move(protrusions);
  out.resolution = certifier.finest_side();
  out.cells = counts->cells;
  out.cells_in_sphere = counts->in_sphere;
  out.cells_outside = counts->outside;
  out.failed_cells = counts->failed;
  const std::optional<Failure> deepest = counts->deepest;
  const std::vector<Failure> failures = std::move(*counts).TakeFailures();
  out.failures.reserve(failures.size());
  for (const Failure& f : failures) out.failures.push_back(CoverCell{f.min, f.side});
  if (deepest) {
    out.uncovered_point = deepest->centre;
    out.uncovered_depth = deepest->depth;
    double gap = std::numeric_limits<double>::infinity();
    for (const Sphere& s : spheres)
      gap = std::min(gap, (deepest->centre - s.center).norm() - s.radius);
    out.uncovered_gap = std::max(gap, 0.0);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace inscribe
