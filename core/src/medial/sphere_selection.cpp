// Optimised sphere selection: a pool of medial spheres on a fine grid, then greedy maximum
// coverage of sample points. See sphere_selection.h for the contract.
//
// The samples are the points of a regular grid inside at least one pool ball, kept as one bit
// per grid point (1: not yet covered) in rows along x. A ball meets each row in one run of
// points, so counting a ball's gain is a popcount over its runs and choosing it clears them.
#include "inscribe/medial/sphere_selection.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/cpu_clones.h"
#include "base/parallel.h"
#include "medial/coverage_grid.h"
#include "medial/voxel_grid.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr std::int64_t kMinGridPoints = 4096;
constexpr std::int64_t kMaxGridPoints = std::int64_t{1} << 31;

using internal::BitField;
using internal::CoverCounts;
using internal::SampleGrid;

// A ball's gain when queued, an upper bound of its gain now (gains only fall); the queue's top
// is the largest, then the lowest index.
struct Pending {
  std::int64_t gain = 0;
  std::int32_t index = 0;
  bool operator<(const Pending& other) const {
    return gain != other.gain ? gain < other.gain : index > other.index;
  }
};

absl::Status Cancelled() { return absl::CancelledError("sphere selection cancelled"); }

// The best replacement found so far for a chosen ball in a swap pass: its gain, its index (the
// leaving ball's own while none beats it), and the candidates counted.
struct SwapChoice {
  std::int64_t gain = 0;
  std::int32_t index = 0;
  std::int64_t evaluations = 0;
};

}  // namespace

const char* SphereSelectionName(SphereSelection selection) {
  switch (selection) {
    case SphereSelection::kPaper:
      return "paper";
    case SphereSelection::kOptimised:
      return "optimised";
  }
  return "unknown";
}

absl::StatusOr<SphereSelection> ParseSphereSelection(absl::string_view name) {
  for (SphereSelection selection : {SphereSelection::kPaper, SphereSelection::kOptimised}) {
    if (name == SphereSelectionName(selection)) return selection;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown sphere selection '", name, "': expected paper or optimised"));
}

// Cloned for x86-64-v2 as BitField::CountIn is (coverage_grid.cpp): the clears and the row
// walks inlined here popcount and round too.
INSCRIBE_CLONES_X86_64_V2 absl::StatusOr<CoverageSelection> SelectByCoverage(
    const std::vector<Sphere>& balls, const CoverageSelectionOptions& options,
    const GenerationControl& control) {
  if (options.max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("the sphere budget must be at least 1, got ", options.max_spheres));
  }
  if (options.grid_points < kMinGridPoints || options.grid_points > kMaxGridPoints) {
    return absl::InvalidArgumentError(absl::StrCat("grid_points must lie in [", kMinGridPoints,
                                                   ", 2^31], got ", options.grid_points));
  }
  if (balls.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return absl::InvalidArgumentError(
        absl::StrCat("too many balls to choose from: ", balls.size(), " (at most 2^31 - 1)"));
  }
  if (absl::Status valid = CheckSpheres(balls); !valid.ok()) return valid;
  CoverageSelection out;
  if (balls.empty()) return out;

  const SampleGrid grid(balls, options.grid_points);
  out.grid_spacing = grid.spacing();
  BitField uncovered(grid);
  uncovered.SetAll(balls);
  out.samples = uncovered.CountAll();
  if (control.cancelled()) return Cancelled();

  // Every point of every ball is set: a ball's gain is its number of points.
  const std::size_t n = balls.size();
  std::vector<std::int64_t> gains(n);
  internal::ParallelForRange(std::size_t{0}, n, 64, [&](std::size_t begin, std::size_t end) {
    if (control.cancelled()) return;
    for (std::size_t i = begin; i != end; ++i) gains[i] = grid.CountPoints(balls[i]);
  });
  if (control.cancelled()) return Cancelled();
  // Each ball's points, an upper bound of any gain it has later (the swaps' pruning).
  std::vector<std::int64_t> points;
  if (options.swap_passes > 0) points = gains;
  // The gains up front count as a quarter of the work, the greedy choice as the rest.
  if (control.on_progress) control.on_progress(0.25);
  out.evaluations = static_cast<std::int64_t>(n);
  std::vector<Pending> heap;
  heap.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (gains[i] > 0) heap.push_back({gains[i], static_cast<std::int32_t>(i)});
  }
  std::priority_queue<Pending> queue(std::less<Pending>(), std::move(heap));

  // Greedy: the ball with the largest gain, kept exact. A choice clears its points, and every
  // ball with a gain loses exactly the points it shares with them (ClearedPoints: counted over
  // the blocks both meet, nothing for balls clear of them). The queue holds every ball with a
  // gain once, under its gain when queued, an upper bound of its gain now: a popped ball whose
  // gain has fallen since goes back under its gain now, and one whose gain has not is the
  // largest (lowest index first) and is chosen.
  internal::ClearedPoints cleared(grid);
  std::vector<std::int32_t> live;  // the balls with a gain, refreshed every 64 choices
  while (!queue.empty() && static_cast<std::int64_t>(out.chosen.size()) < options.max_spheres) {
    if (control.cancelled()) return Cancelled();
    const Pending top = queue.top();
    queue.pop();
    const auto i = static_cast<std::size_t>(top.index);
    if (gains[i] != top.gain) {
      if (gains[i] > 0) queue.push({gains[i], top.index});
      continue;
    }
    cleared.Take(uncovered, balls[i]);
    gains[i] = 0;
    out.chosen.push_back(top.index);
    if (live.empty() || (out.chosen.size() & 63) == 0) {
      live.clear();
      for (std::size_t b = 0; b < n; ++b) {
        if (gains[b] > 0) live.push_back(static_cast<std::int32_t>(b));
      }
    }
    internal::ParallelForRange(std::size_t{0}, live.size(), 64,
                               [&](std::size_t begin, std::size_t end) {
                                 for (std::size_t b = begin; b != end; ++b) {
                                   const auto j = static_cast<std::size_t>(live[b]);
                                   if (gains[j] > 0) gains[j] -= cleared.CountIn(balls[j]);
                                 }
                               });
    if (control.on_progress && out.chosen.size() % 16 == 0) {
      control.on_progress(0.25 + 0.75 * static_cast<double>(out.chosen.size()) /
                                     static_cast<double>(options.max_spheres));
    }
  }

  // Swaps: each chosen ball in turn (least sole cover first) gives way to the unchosen ball
  // overlapping it that covers the most once it is gone, when that is strictly more.
  if (options.swap_passes > 0 && out.chosen.size() < 65535) {
    CoverCounts cover(grid, std::move(uncovered));
    std::vector<char> chosen(n, 0);
    for (std::int32_t index : out.chosen) {
      cover.Add(balls[static_cast<std::size_t>(index)]);
      chosen[static_cast<std::size_t>(index)] = 1;
    }
    for (int pass = 0; pass < options.swap_passes; ++pass) {
      std::vector<Pending> order;  // sole cover, then index; least first
      for (std::int32_t index : out.chosen) {
        order.push_back({cover.once().CountIn(balls[static_cast<std::size_t>(index)]), index});
      }
      std::sort(order.begin(), order.end(), [](const Pending& a, const Pending& b) {
        return a.gain != b.gain ? a.gain < b.gain : a.index < b.index;
      });
      std::int64_t swaps = 0;
      for (std::size_t slot = 0; slot < order.size(); ++slot) {
        if (control.cancelled()) return Cancelled();
        const std::int32_t leaving = order[slot].index;
        const Sphere& s = balls[static_cast<std::size_t>(leaving)];
        cover.Remove(s);
        // The candidates in parallel, each chunk in index order: a ball with no more points
        // than the best gain so far cannot beat it (ties go to the leaving ball, then to the
        // lowest index), so it is not counted; the result is the sequential scan's.
        const SwapChoice identity{cover.uncovered().CountIn(s), leaving, 0};
        const SwapChoice found = internal::ParallelReduce(
            std::size_t{0}, n, 512, identity,
            [&](std::size_t begin, std::size_t end, SwapChoice best) {
              for (std::size_t c = begin; c != end; ++c) {
                if (chosen[c] || points[c] <= best.gain) continue;
                const Sphere& candidate = balls[c];
                const double reach = s.radius + candidate.radius;
                if ((candidate.center - s.center).squaredNorm() >= reach * reach) continue;
                const std::int64_t gain = cover.uncovered().CountIn(candidate);
                ++best.evaluations;
                if (gain > best.gain) {
                  best.gain = gain;
                  best.index = static_cast<std::int32_t>(c);
                }
              }
              return best;
            },
            [](SwapChoice a, const SwapChoice& b) {
              const std::int64_t evaluations = a.evaluations + b.evaluations;
              if (b.gain > a.gain) a = b;
              a.evaluations = evaluations;
              return a;
            });
        out.evaluations += found.evaluations;
        const std::int32_t best = found.index;
        cover.Add(balls[static_cast<std::size_t>(best)]);
        if (best != leaving) {
          chosen[static_cast<std::size_t>(leaving)] = 0;
          chosen[static_cast<std::size_t>(best)] = 1;
          std::replace(out.chosen.begin(), out.chosen.end(), leaving, best);
          ++swaps;
        }
      }
      out.swaps += swaps;
      if (swaps == 0) break;
    }
    out.covered = out.samples - cover.uncovered().CountAll();
  } else {
    out.covered = out.samples - uncovered.CountAll();
  }
  std::sort(out.chosen.begin(), out.chosen.end());
  if (control.on_progress) control.on_progress(1.0);
  return out;
}

std::int64_t DefaultSelectionGridPoints(std::int64_t max_spheres) {
  constexpr std::int64_t kPerSphere = 8192;
  constexpr std::int64_t kBase = std::int64_t{1} << 22;
  constexpr std::int64_t kMost = std::int64_t{1} << 26;
  if (max_spheres <= kBase / kPerSphere) return kBase;
  return std::min(kMost, max_spheres * kPerSphere);
}

absl::Status CheckOptimisedSphereOptions(const OptimisedSphereOptions& options) {
  if (options.max_spheres <= 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("the sphere budget must be at least 1, got ", options.max_spheres));
  }
  if (!(options.pool_factor >= 1.5 && options.pool_factor <= 64.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("pool_factor must lie in [1.5, 64], got ", options.pool_factor));
  }
  if (options.grid_points != 0 &&
      (options.grid_points < kMinGridPoints || options.grid_points > kMaxGridPoints)) {
    return absl::InvalidArgumentError(
        absl::StrCat("grid_points must be 0 (the default) or lie in [", kMinGridPoints,
                     ", 2^31], got ", options.grid_points));
  }
  if (options.max_pool_runs < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_pool_runs must be at least 1, got ", options.max_pool_runs));
  }
  return CheckMedialSphereOptions(options.base, /*need_voxel_size=*/false);
}

absl::StatusOr<OptimisedSphereResult> GenerateOptimisedSpheres(
    const BoundaryOracle& oracle, const OptimisedSphereOptions& options,
    const GenerationControl& control) {
  const Clock::time_point start = Clock::now();
  if (absl::Status valid = CheckOptimisedSphereOptions(options); !valid.ok()) return valid;
  const BoundingBox box = ComputeBoundingBox(oracle.mesh().vertices);
  const double diagonal = box.diagonal();
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) {
    return absl::InvalidArgumentError("mesh has an empty or non-finite bounding box");
  }
  const double target = options.pool_factor * static_cast<double>(options.max_spheres);
  const double finest = internal::FinestVoxelSize(box, options.base.max_voxels);
  double sigma = std::max(finest, internal::VoxelSizeForCount(diagonal, target));

  // Pool runs take the first 85% of the progress, the selection the rest; the number of runs
  // is unknown up front, so each run is reported as if it were the last but one.
  constexpr double kPoolShare = 0.85;
  double reported = 0.0;
  auto report = [&](double fraction) {
    if (!control.on_progress) return;
    reported = std::max(reported, fraction);
    control.on_progress(reported);
  };

  OptimisedSphereResult result;
  // Every run's spheres are medial spheres of the mesh. A run that falls short of the target
  // is followed by a finer one, and its spheres join that run's in the pool: the pool of run i
  // is its own spheres and those of every earlier run with fewer (the coarser ones).
  std::vector<MedialSphereResult> runs;
  auto pool_count = [&runs](std::size_t i) {
    std::size_t count = runs[i].set.size();
    for (std::size_t j = 0; j < i; ++j) {
      if (runs[j].set.size() < runs[i].set.size()) count += runs[j].set.size();
    }
    return static_cast<double>(count);
  };
  // Keep the run whose pool is nearest the target (in ratio) among those with more spheres
  // than the budget, else the richest.
  auto score = [&](std::size_t i) {
    const double c = pool_count(i);
    const bool rich = c > static_cast<double>(options.max_spheres);
    return std::make_pair(rich, rich ? -std::abs(std::log(c / target)) : c);
  };
  std::size_t kept = 0;
  for (int run = 0; run < options.max_pool_runs; ++run) {
    MedialSphereOptions run_options = options.base;
    run_options.voxel_size = sigma;
    GenerationControl run_control;
    run_control.cancel = control.cancel;
    if (control.on_progress) {
      const double done = static_cast<double>(run);
      run_control.on_progress = [&, done](double fraction) {
        report(kPoolShare * (done + fraction) / (done + 2.0));
      };
    }
    absl::StatusOr<MedialSphereResult> attempt =
        GenerateMedialSpheres(oracle, run_options, run_control);
    if (!attempt.ok()) return attempt.status();
    ++result.runs;
    runs.push_back(*std::move(attempt));
    const std::size_t last = runs.size() - 1;
    if (last == 0 || score(last) > score(kept)) kept = last;
    const double count = static_cast<double>(runs[last].set.size());
    const double pooled = pool_count(last);
    if (pooled >= 0.5 * target && pooled <= 2.0 * target) break;
    if (pooled < 0.5 * target && sigma <= finest) break;  // the voxel limit stops refinement
    // The count falls roughly like sigma^-2. Short of the target, the next run aims at the rest
    // (this run's pool joins it); over it, at the target alone.
    const double aim = pooled < 0.5 * target ? target - pooled : target;
    const double factor = std::sqrt(std::max(count, 1.0) / aim);
    sigma = std::max(finest, sigma * std::clamp(factor, 0.25, 4.0));
  }
  // The kept run first, then the coarser runs in the order made: with one run, its own order.
  MedialSphereResult& pool_run = runs[kept];
  SphereSet pool = pool_run.set;
  for (std::size_t j = 0; j < kept; ++j) {
    if (runs[j].set.size() >= pool_run.set.size()) continue;
    pool.spheres.insert(pool.spheres.end(), runs[j].set.spheres.begin(), runs[j].set.spheres.end());
    pool.contacts.insert(pool.contacts.end(), runs[j].set.contacts.begin(),
                         runs[j].set.contacts.end());
  }

  CoverageSelectionOptions select;
  select.max_spheres = options.max_spheres;
  select.swap_passes = options.swap_passes;
  select.grid_points = options.grid_points != 0 ? options.grid_points
                                                : DefaultSelectionGridPoints(options.max_spheres);
  GenerationControl select_control;
  select_control.cancel = control.cancel;
  if (control.on_progress) {
    select_control.on_progress = [&](double fraction) {
      report(kPoolShare + (1.0 - kPoolShare) * fraction);
    };
  }
  absl::StatusOr<CoverageSelection> chosen = SelectByCoverage(pool.spheres, select, select_control);
  if (!chosen.ok()) return chosen.status();
  result.pool_size = static_cast<std::int64_t>(pool.size());
  SphereSet set;
  set.spheres.reserve(chosen->chosen.size());
  set.contacts.reserve(chosen->chosen.size());
  for (std::int32_t index : chosen->chosen) {
    set.spheres.push_back(pool.spheres[static_cast<std::size_t>(index)]);
    set.contacts.push_back(pool.contacts[static_cast<std::size_t>(index)]);
  }
  result.best = std::move(pool_run);
  result.best.set = std::move(set);
  result.selection = *std::move(chosen);
  result.seconds = SecondsSince(start);
  report(1.0);
  return result;
}

}  // namespace inscribe
