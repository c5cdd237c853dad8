// The selection's sample grid and bit fields. See coverage_grid.h.
#include "medial/coverage_grid.h"

#include <limits>

#include "base/cpu_clones.h"
#include "base/parallel.h"

namespace inscribe::internal {
namespace {

double PointsAt(const Vector3& extent, double spacing) {
  return (std::floor(extent.x() / spacing) + 1.0) * (std::floor(extent.y() / spacing) + 1.0) *
         (std::floor(extent.z() / spacing) + 1.0);
}

// A block counts as wholly inside a ball when its farthest point is inside by this relative
// margin of r^2, and as outside when its nearest point is outside by it: far above the
// rounding of SampleGrid's row rule, so such blocks hold exactly the points it gives.
constexpr double kBlockMargin = 1e-6;

}  // namespace

SampleGrid::SampleGrid(const std::vector<Sphere>& balls, std::int64_t max_points) {
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

INSCRIBE_CLONES_X86_64_V2 std::int64_t SampleGrid::CountPoints(const Sphere& ball) const {
  std::int64_t count = 0;
  ForEachRun(ball, [&count](std::int64_t, std::int64_t first, std::int64_t last) {
    count += last - first + 1;
  });
  return count;
}

BitField::BitField(const SampleGrid& grid)
    : grid_(grid),
      words_per_row_(grid.words_per_row()),
      blocks_y_((grid.dim(1) + kBlockRows - 1) / kBlockRows),
      words_(static_cast<std::size_t>(grid.words_per_row() * grid.rows()), 0),
      block_counts_(static_cast<std::size_t>(grid.words_per_row() * blocks_y_ *
                                             ((grid.dim(2) + kBlockRows - 1) / kBlockRows)),
                    0) {}

void BitField::SetAll(const std::vector<Sphere>& balls) {
  // In parallel over slabs of kBlockRows slices, which share no word and no block count.
  const std::int64_t slabs = (grid_.dim(2) + kBlockRows - 1) / kBlockRows;
  ParallelForRange(std::int64_t{0}, slabs, 1, [&](std::int64_t begin, std::int64_t end) {
    SetInSlices(balls, begin * kBlockRows, end * kBlockRows - 1);
  });
}

// Cloned as CountIn is: a loop body of SetAll would be built for the baseline only.
INSCRIBE_CLONES_X86_64_V2 void BitField::SetInSlices(const std::vector<Sphere>& balls,
                                                     std::int64_t k_low, std::int64_t k_high) {
  // The runs' bits first, then the blocks of these slices counted once from their words.
  for (const Sphere& ball : balls) {
    grid_.ForEachRunInSlices(ball, k_low, k_high,
                             [this](std::int64_t row, std::int64_t first, std::int64_t last) {
                               std::uint64_t* words = &words_[Word(row, 0)];
                               for (std::int64_t w = first >> 6; w <= last >> 6; ++w) {
                                 words[w] |= RunMask(w, first, last);
                               }
                             });
  }
  const std::int64_t k_end = std::min(k_high, grid_.dim(2) - 1);
  for (std::int64_t kb = k_low / kBlockRows; kb <= k_end / kBlockRows; ++kb) {
    for (std::int64_t jb = 0; jb < blocks_y_; ++jb) {
      std::fill_n(&block_counts_[Block3(0, jb, kb)], words_per_row_, 0);
    }
  }
  for (std::int64_t k = k_low; k <= k_end; ++k) {
    for (std::int64_t j = 0; j < grid_.dim(1); ++j) {
      const std::int64_t row = grid_.row(j, k);
      const std::uint64_t* words = &words_[Word(row, 0)];
      std::int32_t* blocks = &block_counts_[Block(row, 0)];
      for (std::int64_t w = 0; w < words_per_row_; ++w) blocks[w] += __builtin_popcountll(words[w]);
    }
  }
}

std::int64_t BitField::CountAll() const {
  std::int64_t count = 0;
  for (std::int32_t block : block_counts_) count += block;
  return count;
}

// Cloned for x86-64-v2 (popcnt, SSE4.1 rounding), chosen at load time: with the baseline's
// library popcount and floor the count runs at half speed.
std::int64_t BitField::CountIn(const Sphere& sphere) const {
  return CountIn(sphere, {0, 0, 0}, {grid_.dim(0) - 1, grid_.dim(1) - 1, grid_.dim(2) - 1});
}

INSCRIBE_CLONES_X86_64_V2 std::int64_t BitField::CountIn(
    const Sphere& sphere, const std::array<std::int64_t, 3>& box_low,
    const std::array<std::int64_t, 3>& box_high) const {
  const SampleGrid::Ball ball = grid_.ToGrid(sphere);
  // The blocks looked at: ForEachRun's slices along z; along x and y its runs end where square
  // roots of rounded differences put them, so one point further.
  std::int64_t k0, k1;
  grid_.SliceRange(ball, k0, k1);
  k0 = std::max(k0, box_low[2]);
  k1 = std::min(k1, box_high[2]);
  if (k0 > k1) return 0;
  std::int64_t low[2], high[2];
  for (int axis = 0; axis < 2; ++axis) {
    low[axis] = std::max(box_low[axis], SampleGrid::Ceil(ball.c[axis] - ball.r) - 1);
    high[axis] = std::min(box_high[axis], SampleGrid::Floor(ball.c[axis] + ball.r) + 1);
    if (low[axis] > high[axis]) return 0;
  }
  const double r2 = ball.r * ball.r;
  const double inner = r2 * (1.0 - kBlockMargin);
  const double outer = r2 * (1.0 + kBlockMargin);
  // Squared distances from the centre to the nearest and farthest points of [lo, hi] on `axis`.
  auto near_far = [&ball](int axis, std::int64_t lo, std::int64_t hi, double& near2, double& far2) {
    const double a = static_cast<double>(lo) - ball.c[axis];
    const double b = static_cast<double>(hi) - ball.c[axis];
    const double nearest = a > 0.0 ? a : (b < 0.0 ? b : 0.0);
    near2 += nearest * nearest;
    far2 += std::max(a * a, b * b);
  };
  const std::int64_t w_first = low[0] >> 6;
  const std::int64_t w_last = high[0] >> 6;
  std::int64_t count = 0;
  for (std::int64_t kb = k0 / kBlockRows; kb <= k1 / kBlockRows; ++kb) {
    const std::int64_t z0 = kb * kBlockRows;
    const std::int64_t z1 = std::min(grid_.dim(2) - 1, z0 + kBlockRows - 1);
    for (std::int64_t jb = low[1] / kBlockRows; jb <= high[1] / kBlockRows; ++jb) {
      const std::int64_t y0 = jb * kBlockRows;
      const std::int64_t y1 = std::min(grid_.dim(1) - 1, y0 + kBlockRows - 1);
      // The blocks of this group of 4 x 4 rows, up to 64 at a time: empty or outside ones are
      // skipped, wholly inside ones counted at once, and the words of the rest (bit w - chunk
      // of `straddling`) popcounted row by row.
      for (std::int64_t chunk = w_first; chunk <= w_last; chunk += 64) {
        const std::int64_t chunk_last = std::min(w_last, chunk + 63);
        std::uint64_t straddling = 0;
        for (std::int64_t w = chunk; w <= chunk_last; ++w) {
          const std::int32_t in_block = block_counts_[Block3(w, jb, kb)];
          if (in_block == 0) continue;
          double near2 = 0.0, far2 = 0.0;
          near_far(0, w * 64, std::min(grid_.dim(0) - 1, w * 64 + 63), near2, far2);
          near_far(1, y0, y1, near2, far2);
          near_far(2, z0, z1, near2, far2);
          if (far2 <= inner) {
            count += in_block;
          } else if (near2 <= outer) {
            straddling |= std::uint64_t{1} << (w - chunk);
          }
        }
        if (straddling == 0) continue;
        for (std::int64_t k = std::max(z0, k0); k <= std::min(z1, k1); ++k) {
          double slice;
          std::int64_t j0, j1;
          if (!grid_.Slice(ball, k, slice, j0, j1)) continue;
          for (std::int64_t j = std::max(y0, j0); j <= std::min(y1, j1); ++j) {
            std::int64_t first, last;
            if (!grid_.Chord(ball, slice, j, first, last)) continue;
            const std::uint64_t* words = &words_[Word(grid_.row(j, k), 0)];
            const std::int64_t from = std::max(first >> 6, chunk);
            const std::int64_t to = std::min(last >> 6, chunk_last);
            for (std::int64_t w = from; w <= to; ++w) {
              if (!((straddling >> (w - chunk)) & 1)) continue;
              count += __builtin_popcountll(words[w] & RunMask(w, first, last));
            }
          }
        }
      }
    }
  }
  return count;
}

INSCRIBE_CLONES_X86_64_V2 void ClearedPoints::Take(BitField& field, const Sphere& sphere) {
  for (const Run& run : runs_) kept_.Clear(run.row, run.first, run.last);
  runs_.clear();
  low_.fill(std::numeric_limits<std::int64_t>::max());
  high_.fill(std::numeric_limits<std::int64_t>::min());
  const SampleGrid::Ball ball = grid_.ToGrid(sphere);
  std::int64_t k0, k1;
  grid_.SliceRange(ball, k0, k1);
  for (std::int64_t k = k0; k <= k1; ++k) {
    double slice;
    std::int64_t j0, j1;
    if (!grid_.Slice(ball, k, slice, j0, j1)) continue;
    for (std::int64_t j = j0; j <= j1; ++j) {
      std::int64_t first, last;
      if (!grid_.Chord(ball, slice, j, first, last)) continue;
      const std::int64_t row = grid_.row(j, k);
      field.MoveTo(row, first, last, kept_);
      const std::int64_t lowest = kept_.FirstSet(row, first, last);
      if (lowest > last) continue;
      runs_.push_back(Run{row, first, last});
      const std::int64_t highest = kept_.LastSet(row, first, last);
      const std::int64_t point_low[3] = {lowest, j, k};
      const std::int64_t point_high[3] = {highest, j, k};
      for (int axis = 0; axis < 3; ++axis) {
        low_[axis] = std::min(low_[axis], point_low[axis]);
        high_[axis] = std::max(high_[axis], point_high[axis]);
      }
    }
  }
}

INSCRIBE_CLONES_X86_64_V2 std::int64_t ClearedPoints::CountIn(const Sphere& sphere) const {
  if (runs_.empty()) return 0;
  // Balls clear of the kept points' box by a point's width (far above the row rule's
  // rounding) hold none of them.
  const SampleGrid::Ball ball = grid_.ToGrid(sphere);
  double gap2 = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double below = static_cast<double>(low_[axis]) - ball.c[axis];
    const double above = ball.c[axis] - static_cast<double>(high_[axis]);
    const double gap = std::max({below, above, 0.0});
    gap2 += gap * gap;
  }
  if (gap2 > (ball.r + 1.0) * (ball.r + 1.0)) return 0;
  return kept_.CountIn(sphere, low_, high_);
}

void CoverCounts::Change(const Sphere& ball, int step) {
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

}  // namespace inscribe::internal
