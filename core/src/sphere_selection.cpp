// Optimised sphere selection: a pool of medial spheres on a fine grid, then greedy maximum
// coverage of sample points. See sphere_selection.h for the contract.
//
// The samples are the points of a regular grid inside at least one pool ball, kept as one bit
// per grid point (1: not yet covered) in rows along x. A ball meets each row in one run of
// points, so counting a ball's gain is a popcount over its runs and choosing it clears them.
#include "inscribe/sphere_selection.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <queue>
#include <utility>

#include "absl/strings/str_cat.h"
#include "voxel_grid.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr std::int64_t kMinGridPoints = 4096;
constexpr std::int64_t kMaxGridPoints = std::int64_t{1} << 31;

// Sample points origin + spacing * (i, j, k), 0 <= i < dims[0] etc. Row (j, k) holds its
// dims[0] points; bit fields give each row `words_per_row` 64-bit words.
class SampleGrid {
 public:
  SampleGrid(const std::vector<Sphere>& balls, std::int64_t max_points) {
    Vector3 low = Vector3::Constant(std::numeric_limits<double>::infinity());
    Vector3 high = -low;
    for (const Sphere& ball : balls) {
      low = low.cwiseMin(ball.center - Vector3::Constant(ball.radius));
      high = high.cwiseMax(ball.center + Vector3::Constant(ball.radius));
    }
    const Vector3 extent = high - low;
    spacing_ = std::cbrt(extent.prod() / static_cast<double>(max_points));
    // Sides round up to whole spacings: grow the spacing until the points fit.
    while (PointsAt(extent, spacing_) > static_cast<double>(max_points)) spacing_ *= 1.001;
    for (int axis = 0; axis < 3; ++axis) {
      dims_[axis] = static_cast<std::int64_t>(std::floor(extent[axis] / spacing_)) + 1;
    }
    // Centre the points in the box.
    origin_ = low + 0.5 * (extent - spacing_ * Vector3(static_cast<double>(dims_[0] - 1),
                                                       static_cast<double>(dims_[1] - 1),
                                                       static_cast<double>(dims_[2] - 1)));
    words_per_row_ = (dims_[0] + 63) / 64;
  }

  double spacing() const { return spacing_; }
  std::int64_t row_length() const { return dims_[0]; }
  std::int64_t rows() const { return dims_[1] * dims_[2]; }
  std::int64_t words_per_row() const { return words_per_row_; }

  // Calls f(row, first, last) for each row the ball meets, with its points first..last
  // (inclusive) inside the ball.
  template <typename F>
  void ForEachRun(const Sphere& ball, F&& f) const {
    const Vector3 c = (ball.center - origin_) / spacing_;
    const double rs = ball.radius / spacing_;
    const std::int64_t k0 = std::max<std::int64_t>(0, Ceil(c.z() - rs));
    const std::int64_t k1 = std::min<std::int64_t>(dims_[2] - 1, Floor(c.z() + rs));
    for (std::int64_t k = k0; k <= k1; ++k) {
      const double dz = static_cast<double>(k) - c.z();
      const double slice = rs * rs - dz * dz;
      if (slice < 0.0) continue;
      const double ry = std::sqrt(slice);
      const std::int64_t j0 = std::max<std::int64_t>(0, Ceil(c.y() - ry));
      const std::int64_t j1 = std::min<std::int64_t>(dims_[1] - 1, Floor(c.y() + ry));
      for (std::int64_t j = j0; j <= j1; ++j) {
        const double dy = static_cast<double>(j) - c.y();
        const double chord = slice - dy * dy;
        if (chord < 0.0) continue;
        const double rx = std::sqrt(chord);
        const std::int64_t i0 = std::max<std::int64_t>(0, Ceil(c.x() - rx));
        const std::int64_t i1 = std::min<std::int64_t>(dims_[0] - 1, Floor(c.x() + rx));
        if (i0 <= i1) f(j + dims_[1] * k, i0, i1);
      }
    }
  }

 private:
  static double PointsAt(const Vector3& extent, double spacing) {
    return (std::floor(extent.x() / spacing) + 1.0) * (std::floor(extent.y() / spacing) + 1.0) *
           (std::floor(extent.z() / spacing) + 1.0);
  }
  static std::int64_t Ceil(double x) { return static_cast<std::int64_t>(std::ceil(x)); }
  static std::int64_t Floor(double x) { return static_cast<std::int64_t>(std::floor(x)); }

  Vector3 origin_ = Vector3::Zero();
  double spacing_ = 0.0;
  std::array<std::int64_t, 3> dims_ = {0, 0, 0};
  std::int64_t words_per_row_ = 0;
};

// One bit per sample point of a SampleGrid.
class BitField {
 public:
  explicit BitField(const SampleGrid& grid)
      : words_per_row_(grid.words_per_row()),
        words_(static_cast<std::size_t>(grid.words_per_row() * grid.rows()), 0) {}

  void Set(std::int64_t row, std::int64_t first, std::int64_t last) {
    ForEachWord(row, first, last, [](std::uint64_t& word, std::uint64_t mask) { word |= mask; });
  }
  void Clear(std::int64_t row, std::int64_t first, std::int64_t last) {
    ForEachWord(row, first, last, [](std::uint64_t& word, std::uint64_t mask) { word &= ~mask; });
  }
  void Set(std::int64_t row, std::int64_t i) {
    words_[Word(row, i)] |= std::uint64_t{1} << (i & 63);
  }
  void Clear(std::int64_t row, std::int64_t i) {
    words_[Word(row, i)] &= ~(std::uint64_t{1} << (i & 63));
  }
  // Set points among first..last.
  std::int64_t Count(std::int64_t row, std::int64_t first, std::int64_t last) const {
    const std::uint64_t* words = &words_[Word(row, 0)];
    const std::int64_t w0 = first >> 6;
    const std::int64_t w1 = last >> 6;
    const std::uint64_t head = ~std::uint64_t{0} << (first & 63);
    const std::uint64_t tail = ~std::uint64_t{0} >> (63 - (last & 63));
    if (w0 == w1) return __builtin_popcountll(words[w0] & head & tail);
    std::int64_t count = __builtin_popcountll(words[w0] & head);
    for (std::int64_t w = w0 + 1; w < w1; ++w) count += __builtin_popcountll(words[w]);
    return count + __builtin_popcountll(words[w1] & tail);
  }
  std::int64_t CountAll() const {
    std::int64_t count = 0;
    for (std::uint64_t word : words_) count += __builtin_popcountll(word);
    return count;
  }

 private:
  std::size_t Word(std::int64_t row, std::int64_t i) const {
    return static_cast<std::size_t>(row * words_per_row_ + (i >> 6));
  }
  template <typename Op>
  void ForEachWord(std::int64_t row, std::int64_t first, std::int64_t last, Op&& op) {
    std::uint64_t* words = &words_[Word(row, 0)];
    const std::int64_t w0 = first >> 6;
    const std::int64_t w1 = last >> 6;
    const std::uint64_t head = ~std::uint64_t{0} << (first & 63);
    const std::uint64_t tail = ~std::uint64_t{0} >> (63 - (last & 63));
    if (w0 == w1) {
      op(words[w0], head & tail);
      return;
    }
    op(words[w0], head);
    for (std::int64_t w = w0 + 1; w < w1; ++w) op(words[w], ~std::uint64_t{0});
    op(words[w1], tail);
  }

  std::int64_t words_per_row_ = 0;
  std::vector<std::uint64_t> words_;
};

// Points of `ball` set in `field`.
std::int64_t CountIn(const SampleGrid& grid, const BitField& field, const Sphere& ball) {
  std::int64_t count = 0;
  grid.ForEachRun(ball, [&](std::int64_t row, std::int64_t first, std::int64_t last) {
    count += field.Count(row, first, last);
  });
  return count;
}

// The chosen balls' cover of the samples, point by point, for the swap search: how many chosen
// balls hold each point, the points held by none (`uncovered`) and by exactly one (`once`).
// Every point of a pool ball is a sample, so adding and removing pool balls keeps the fields
// exact.
class CoverCounts {
 public:
  CoverCounts(const SampleGrid& grid, BitField uncovered)
      : grid_(grid),
        uncovered_(std::move(uncovered)),
        once_(grid),
        counts_(static_cast<std::size_t>(grid.row_length() * grid.rows()), 0) {}

  const BitField& uncovered() const { return uncovered_; }
  const BitField& once() const { return once_; }

  // A chosen ball (the greedy's are counted in this way once it has cleared their points).
  void Add(const Sphere& ball) { Change(ball, +1); }
  void Remove(const Sphere& ball) { Change(ball, -1); }

 private:
  void Change(const Sphere& ball, int step) {
    grid_.ForEachRun(ball, [&](std::int64_t row, std::int64_t first, std::int64_t last) {
      std::uint16_t* count = &counts_[static_cast<std::size_t>(row * grid_.row_length())];
      for (std::int64_t i = first; i <= last; ++i) {
        const int now = count[i] + step;
        count[i] = static_cast<std::uint16_t>(now);
        if (now == 0) {
          uncovered_.Set(row, i);
          once_.Clear(row, i);
        } else if (now == 1) {
          uncovered_.Clear(row, i);
          once_.Set(row, i);
        } else if (now == 2) {
          once_.Clear(row, i);
        }
      }
    });
  }

  const SampleGrid& grid_;
  BitField uncovered_;
  BitField once_;
  std::vector<std::uint16_t> counts_;
};

// The lazy greedy chooses a ball whose fresh gain is within 2^-kSlackShift of the best upper
// bound left, rather than recounting the others: each choice then covers at least (1 - 2^-4)
// of the best gain, which keeps a guarantee of 1 - e^-(1 - 2^-4) of the optimum and saves most
// recounts of large balls whose gains fall a little at every choice near them.
constexpr int kSlackShift = 4;

// A ball's last counted gain; the queue's top is the largest gain, then the lowest index.
struct Pending {
  std::int64_t gain = 0;
  std::int32_t index = 0;
  bool operator<(const Pending& other) const {
    return gain != other.gain ? gain < other.gain : index > other.index;
  }
};

absl::Status Cancelled() { return absl::CancelledError("sphere selection cancelled"); }

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

absl::StatusOr<CoverageSelection> SelectByCoverage(const std::vector<Sphere>& balls,
                                                   const CoverageSelectionOptions& options,
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
  for (const Sphere& ball : balls) {
    grid.ForEachRun(ball, [&uncovered](std::int64_t row, std::int64_t first, std::int64_t last) {
      uncovered.Set(row, first, last);
    });
  }
  out.samples = uncovered.CountAll();
  if (control.cancelled()) return Cancelled();

  const std::size_t n = balls.size();
  std::vector<std::int64_t> gains(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 64),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      if (control.cancelled()) return;
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        gains[i] = CountIn(grid, uncovered, balls[i]);
                      }
                    });
  if (control.cancelled()) return Cancelled();
  // The gains up front count as a quarter of the work, the greedy choice as the rest.
  if (control.on_progress) control.on_progress(0.25);
  out.evaluations = static_cast<std::int64_t>(n);
  std::vector<Pending> heap;
  heap.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (gains[i] > 0) heap.push_back({gains[i], static_cast<std::int32_t>(i)});
  }
  std::priority_queue<Pending> queue(std::less<Pending>(), std::move(heap));

  // Greedy: lazy evaluation of the ball with the largest gain.
  std::int64_t iterations = 0;
  while (!queue.empty() && static_cast<std::int64_t>(out.chosen.size()) < options.max_spheres) {
    if ((++iterations & 255) == 0 && control.cancelled()) return Cancelled();
    Pending top = queue.top();
    queue.pop();
    const Sphere& ball = balls[static_cast<std::size_t>(top.index)];
    top.gain = CountIn(grid, uncovered, ball);
    ++out.evaluations;
    if (top.gain == 0) continue;
    // Every other ball's last count bounds its gain from above: when one of them may still
    // beat this ball's fresh count by more than the slack, recount that one first.
    if (!queue.empty() && top.gain < queue.top().gain - (queue.top().gain >> kSlackShift)) {
      queue.push(top);
      continue;
    }
    grid.ForEachRun(ball, [&uncovered](std::int64_t row, std::int64_t first, std::int64_t last) {
      uncovered.Clear(row, first, last);
    });
    out.chosen.push_back(top.index);
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
        order.push_back(
            {CountIn(grid, cover.once(), balls[static_cast<std::size_t>(index)]), index});
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
        std::int32_t best = leaving;
        std::int64_t best_gain = CountIn(grid, cover.uncovered(), s);
        for (std::size_t c = 0; c < n; ++c) {
          if (chosen[c]) continue;
          const Sphere& candidate = balls[c];
          const double reach = s.radius + candidate.radius;
          if ((candidate.center - s.center).squaredNorm() >= reach * reach) continue;
          const std::int64_t gain = CountIn(grid, cover.uncovered(), candidate);
          ++out.evaluations;
          if (gain > best_gain) {
            best_gain = gain;
            best = static_cast<std::int32_t>(c);
          }
        }
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
  std::optional<MedialSphereResult> pool;
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
    const double count = static_cast<double>(attempt->set.size());
    // Keep the run nearest the target (in ratio) among those with more spheres than the budget,
    // else the richest.
    auto score = [&](const MedialSphereResult& r) {
      const double c = static_cast<double>(r.set.size());
      const bool rich = c > static_cast<double>(options.max_spheres);
      return std::make_pair(rich, rich ? -std::abs(std::log(c / target)) : c);
    };
    if (!pool || score(*attempt) > score(*pool)) pool = std::move(*attempt);
    if (count >= 0.5 * target && count <= 2.0 * target) break;
    if (count < 0.5 * target && sigma <= finest) break;  // the voxel limit stops refinement
    // The count falls roughly like sigma^-2.
    const double factor = std::sqrt(std::max(count, 1.0) / target);
    sigma = std::max(finest, sigma * std::clamp(factor, 0.25, 4.0));
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
  absl::StatusOr<CoverageSelection> chosen =
      SelectByCoverage(pool->set.spheres, select, select_control);
  if (!chosen.ok()) return chosen.status();
  result.pool_size = static_cast<std::int64_t>(pool->set.size());
  SphereSet set;
  set.spheres.reserve(chosen->chosen.size());
  set.contacts.reserve(chosen->chosen.size());
  for (std::int32_t index : chosen->chosen) {
    set.spheres.push_back(pool->set.spheres[static_cast<std::size_t>(index)]);
    set.contacts.push_back(pool->set.contacts[static_cast<std::size_t>(index)]);
  }
  result.best = *std::move(pool);
  result.best.set = std::move(set);
  result.selection = *std::move(chosen);
  result.seconds = SecondsSince(start);
  report(1.0);
  return result;
}

}  // namespace inscribe
