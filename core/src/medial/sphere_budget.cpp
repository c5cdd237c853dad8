// The voxel-size search behind --max-spheres: GenerateWithSphereBudget (medial_spheres.h).
//
// The sphere count n(sigma) falls roughly like sigma^-2 (one sphere per voxel met by the medial
// surface's salient sheets), but not monotonically. The search first brackets the budget N
// (a sigma with n <= N, the "accepted" side, and a smaller one with n > N), stepping by the
// power law fitted to the runs so far, then narrows the bracket by interpolating log n against
// log sigma, kept inside the bracket's middle 80%, and bisects whenever a run failed to
// halve the bracket (the count jumps where the grid's alignment changes).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "absl/strings/str_cat.h"
#include "inscribe/medial/medial_spheres.h"
#include "medial/voxel_grid.h"

namespace inscribe {
namespace {

struct Run {
  double voxel_size = 0.0;
  std::int64_t count = 0;
};

// Slope of log n against log sigma (negative), from two runs; `fallback` when undefined.
double LogSlope(const Run& x, const Run& y, double fallback) {
  if (x.count <= 0 || y.count <= 0 || x.voxel_size == y.voxel_size || x.count == y.count) {
    return fallback;
  }
  const double slope =
      (std::log(static_cast<double>(y.count)) - std::log(static_cast<double>(x.count))) /
      (std::log(y.voxel_size) - std::log(x.voxel_size));
  return std::clamp(slope, -3.0, -0.5);
}

}  // namespace

absl::StatusOr<SphereBudgetResult> GenerateWithSphereBudget(const BoundaryOracle& oracle,
                                                            const SphereBudgetOptions& options,
                                                            const GenerationControl& control) {
  const auto start = std::chrono::steady_clock::now();
  if (options.max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("the sphere budget must be at least 1, got ", options.max_spheres));
  }
  if (!(options.relative_tolerance > 0.0 && options.relative_tolerance < 1.0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the search's relative tolerance must lie in (0, 1), got ", options.relative_tolerance));
  }
  if (options.max_runs < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("the search needs at least one run, got ", options.max_runs));
  }
  const BoundingBox box = ComputeBoundingBox(oracle.mesh().vertices);
  const double diagonal = box.diagonal();
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) {
    return absl::InvalidArgumentError("mesh has an empty or non-finite bounding box");
  }
  const double target = static_cast<double>(options.max_spheres);
  // The finest sigma the voxel limit allows: below it runs would be refused.
  const double finest = internal::FinestVoxelSize(box, options.base.max_voxels);

  SphereBudgetResult result;
  std::optional<MedialSphereResult> accepted;  // smallest sigma with n <= N
  std::optional<Run> rejected;                 // largest sigma with n > N
  std::optional<Run> previous;
  double slope = -2.0;
  double previous_gap = 0.0;  // relative bracket width before the last run, once bracketed
  double sigma = std::max(finest, internal::VoxelSizeForCount(diagonal, target));
  double reported = 0.0;

  for (int run = 0; run < options.max_runs; ++run) {
    MedialSphereOptions run_options = options.base;
    run_options.voxel_size = sigma;
    GenerationControl run_control;
    run_control.cancel = control.cancel;
    if (control.on_progress) {
      // Runs left are unknown up front: count the bracket halvings still needed, and keep the
      // reported fraction monotone.
      double remaining = 3.0;
      if (accepted && rejected) {
        remaining = std::max(1.0, std::log2(std::log(accepted->voxel_size / rejected->voxel_size) /
                                            std::log1p(options.relative_tolerance)));
      }
      const double done = static_cast<double>(run);
      run_control.on_progress = [&, done, remaining](double fraction) {
        reported = std::max(reported, (done + fraction) / (done + 1.0 + remaining));
        control.on_progress(reported);
      };
    }
    absl::StatusOr<MedialSphereResult> attempt =
        GenerateMedialSpheres(oracle, run_options, run_control);
    if (!attempt.ok()) return attempt.status();
    ++result.runs;
    const Run current{sigma, static_cast<std::int64_t>(attempt->set.size())};
    if (previous) slope = LogSlope(*previous, current, slope);
    previous = current;
    if (current.count <= options.max_spheres) {
      if (!accepted || sigma < accepted->voxel_size) accepted = std::move(*attempt);
    } else if (!rejected || sigma > rejected->voxel_size) {
      rejected = current;
    }

    if (accepted && rejected) {
      const double gap = accepted->voxel_size / rejected->voxel_size - 1.0;
      if (gap <= options.relative_tolerance) break;
      const double log_lo = std::log(rejected->voxel_size);
      const double log_hi = std::log(accepted->voxel_size);
      const double accepted_count =
          static_cast<double>(std::max<std::size_t>(accepted->set.size(), 1));
      const double local = LogSlope(
          Run{accepted->voxel_size, static_cast<std::int64_t>(accepted_count)}, *rejected, slope);
      double guess = log_hi + (std::log(target) - std::log(accepted_count)) / local;
      guess = std::clamp(guess, log_lo + 0.1 * (log_hi - log_lo), log_lo + 0.9 * (log_hi - log_lo));
      // Safeguard: the count jumps where the grid's alignment changes, and interpolation across
      // a jump creeps; when the last run did not halve the bracket, bisect instead.
      if (previous_gap > 0.0 && gap > 0.5 * previous_gap) guess = 0.5 * (log_lo + log_hi);
      previous_gap = gap;
      sigma = std::exp(guess);
    } else if (accepted) {
      // Every run so far fits: refine, aiming a little past the budget to find its edge.
      if (accepted->voxel_size <= finest) break;  // the voxel limit stops refinement here
      const double count = static_cast<double>(std::max<std::size_t>(accepted->set.size(), 1));
      const double factor = std::pow(1.03 * target / count, 1.0 / slope);
      sigma = std::max(finest, accepted->voxel_size * std::clamp(factor, 0.25, 0.95));
    } else {
      // Every run so far has too many spheres: coarsen, aiming a little under the budget.
      const double factor =
          std::pow(0.97 * target / static_cast<double>(current.count), 1.0 / slope);
      sigma *= std::clamp(factor, 1.05, 4.0);
      if (sigma > 4.0 * diagonal) {
        return absl::ResourceExhaustedError(absl::StrCat(
            "no voxel size gives at most ", options.max_spheres, " spheres (", current.count,
            " with one voxel spanning the mesh); raise the sphere budget"));
      }
    }
  }
  if (!accepted) {
    return absl::ResourceExhaustedError(absl::StrCat("no voxel size within ", options.max_runs,
                                                     " runs gave at most ", options.max_spheres,
                                                     " spheres"));
  }
  result.best = std::move(*accepted);
  result.rejected_voxel_size = rejected ? rejected->voxel_size : 0.0;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (control.on_progress) control.on_progress(1.0);
  return result;
}

}  // namespace inscribe
