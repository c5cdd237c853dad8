// Private: the sample grid of the optimised selection (sphere_selection.cpp) and its bit
// fields. Sample points lie on a regular grid; a bit field keeps one bit per point in rows
// along x, and a ball meets each row in one run of points, so counting the points of a ball
// still set is a popcount over its runs. Each bit field also keeps the number of set bits of
// every block of 64 x 4 x 4 points (one word of 4 x 4 rows), so a count can take a block
// wholly inside the ball at once and skip an empty one. The greedy keeps each ball's gain by
// counting, in a field holding only the points a choice cleared, the blocks of their overlap.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "inscribe/geometry/sphere.h"

namespace inscribe::internal {

// Sample points origin + spacing * (i, j, k), 0 <= i < dims[0] etc. Row (j, k) holds its
// dims[0] points; bit fields give each row `words_per_row` 64-bit words.
class SampleGrid {
 public:
  // The finest grid of at most max_points points over the balls' bounding box, centred in it.
  SampleGrid(const std::vector<Sphere>& balls, std::int64_t max_points);

  double spacing() const { return spacing_; }
  std::int64_t dim(int axis) const { return dims_[axis]; }
  std::int64_t row_length() const { return dims_[0]; }
  std::int64_t rows() const { return dims_[1] * dims_[2]; }
  std::int64_t words_per_row() const { return words_per_row_; }
  std::int64_t row(std::int64_t j, std::int64_t k) const { return j + dims_[1] * k; }

  // A ball in grid units: centre (origin at point (0, 0, 0), one unit per spacing) and radius.
  struct Ball {
    Vector3 c;
    double r;
  };
  Vector3 PointAt(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return origin_ + spacing_ * Vector3(static_cast<double>(i), static_cast<double>(j),
                                        static_cast<double>(k));
  }
  Ball ToGrid(const Sphere& ball) const {
    return Ball{(ball.center - origin_) / spacing_, ball.radius / spacing_};
  }

  // The ball's slices along z: the first and last k of the points it holds.
  void SliceRange(const Ball& ball, std::int64_t& k0, std::int64_t& k1) const {
    k0 = std::max<std::int64_t>(0, Ceil(ball.c.z() - ball.r));
    k1 = std::min<std::int64_t>(dims_[2] - 1, Floor(ball.c.z() + ball.r));
  }
  // Slice k of the ball (k from SliceRange): false if empty, else the squared radius of its
  // disc in `slice` and the rows j0..j1 it meets.
  bool Slice(const Ball& ball, std::int64_t k, double& slice, std::int64_t& j0,
             std::int64_t& j1) const {
    const double dz = static_cast<double>(k) - ball.c.z();
    slice = ball.r * ball.r - dz * dz;
    if (slice < 0.0) return false;
    const double ry = std::sqrt(slice);
    j0 = std::max<std::int64_t>(0, Ceil(ball.c.y() - ry));
    j1 = std::min<std::int64_t>(dims_[1] - 1, Floor(ball.c.y() + ry));
    return j0 <= j1;
  }
  // Row j of a slice (j from Slice): false if the ball holds none of its points, else they are
  // first..last (inclusive). With SliceRange and Slice, the one rule of which points a ball
  // holds.
  bool Chord(const Ball& ball, double slice, std::int64_t j, std::int64_t& first,
             std::int64_t& last) const {
    const double dy = static_cast<double>(j) - ball.c.y();
    const double chord = slice - dy * dy;
    if (chord < 0.0) return false;
    const double rx = std::sqrt(chord);
    first = std::max<std::int64_t>(0, Ceil(ball.c.x() - rx));
    last = std::min<std::int64_t>(dims_[0] - 1, Floor(ball.c.x() + rx));
    return first <= last;
  }

  // Calls f(row, first, last) for each row the ball meets, with its points first..last
  // (inclusive) inside the ball.
  template <typename F>
  __attribute__((always_inline)) void ForEachRun(const Sphere& sphere, F&& f) const {
    ForEachRunInSlices(sphere, 0, dims_[2] - 1, f);
  }
  // The same, for the slices k_low..k_high only.
  template <typename F>
  __attribute__((always_inline)) void ForEachRunInSlices(const Sphere& sphere, std::int64_t k_low,
                                                         std::int64_t k_high, F&& f) const {
    const Ball ball = ToGrid(sphere);
    std::int64_t k0, k1;
    SliceRange(ball, k0, k1);
    k0 = std::max(k0, k_low);
    k1 = std::min(k1, k_high);
    for (std::int64_t k = k0; k <= k1; ++k) {
      double slice;
      std::int64_t j0, j1;
      if (!Slice(ball, k, slice, j0, j1)) continue;
      for (std::int64_t j = j0; j <= j1; ++j) {
        std::int64_t first, last;
        if (Chord(ball, slice, j, first, last)) f(row(j, k), first, last);
      }
    }
  }

  // The number of points inside the ball (those ForEachRun gives).
  std::int64_t CountPoints(const Sphere& ball) const;

  static std::int64_t Ceil(double x) { return static_cast<std::int64_t>(std::ceil(x)); }
  static std::int64_t Floor(double x) { return static_cast<std::int64_t>(std::floor(x)); }

 private:
  Vector3 origin_ = Vector3::Zero();
  double spacing_ = 0.0;
  std::array<std::int64_t, 3> dims_ = {0, 0, 0};
  std::int64_t words_per_row_ = 0;
};

// One bit per sample point of a SampleGrid, with the set bits of each block of 64 x 4 x 4
// points counted.
class BitField {
 public:
  static constexpr std::int64_t kBlockRows = 4;  // block side along y and along z, in points

  explicit BitField(const SampleGrid& grid);

  void Set(std::int64_t row, std::int64_t first, std::int64_t last) {
    ForEachWord(row, first, last, [](std::uint64_t& word, std::uint64_t mask) {
      const std::int32_t added = __builtin_popcountll(~word & mask);
      word |= mask;
      return added;
    });
  }
  void Clear(std::int64_t row, std::int64_t first, std::int64_t last) {
    ForEachWord(row, first, last, [](std::uint64_t& word, std::uint64_t mask) {
      const std::int32_t removed = __builtin_popcountll(word & mask);
      word &= ~mask;
      return -removed;
    });
  }
  // Clears first..last of `row` and sets the points it cleared (those that were set) in
  // `into`, a field of the same grid.
  __attribute__((always_inline)) void MoveTo(std::int64_t row, std::int64_t first,
                                             std::int64_t last, BitField& into) {
    std::uint64_t* into_words = &into.words_[Word(row, 0)];
    std::int32_t* into_blocks = &into.block_counts_[Block(row, 0)];
    ForEachWord(row, first, last, [&](std::uint64_t& word, std::uint64_t mask) {
      const std::uint64_t moved = word & mask;
      const std::int32_t count = __builtin_popcountll(moved);
      const std::ptrdiff_t w = &word - &words_[Word(row, 0)];
      into_words[w] |= moved;
      into_blocks[w] += count;
      word &= ~mask;
      return -count;
    });
  }
  void Set(std::int64_t row, std::int64_t i) { Set(row, i, i); }
  // Sets every point inside any of the balls (in parallel).
  void SetAll(const std::vector<Sphere>& balls);
  void Clear(std::int64_t row, std::int64_t i) { Clear(row, i, i); }

  // The bits of a row's word w that its points first..last (inclusive) occupy.
  static std::uint64_t RunMask(std::int64_t w, std::int64_t first, std::int64_t last) {
    std::uint64_t mask = ~std::uint64_t{0};
    if (w == first >> 6) mask &= ~std::uint64_t{0} << (first & 63);
    if (w == last >> 6) mask &= ~std::uint64_t{0} >> (63 - (last & 63));
    return mask;
  }

  // Set points among first..last of `row`.
  std::int64_t Count(std::int64_t row, std::int64_t first, std::int64_t last) const {
    const std::uint64_t* words = &words_[Word(row, 0)];
    std::int64_t count = 0;
    for (std::int64_t w = first >> 6; w <= last >> 6; ++w) {
      count += __builtin_popcountll(words[w] & RunMask(w, first, last));
    }
    return count;
  }
  std::int64_t CountAll() const;
  // The first set point among first..last of `row`, last + 1 if none; the last, first - 1 if
  // none.
  std::int64_t FirstSet(std::int64_t row, std::int64_t first, std::int64_t last) const {
    const std::uint64_t* words = &words_[Word(row, 0)];
    for (std::int64_t w = first >> 6; w <= last >> 6; ++w) {
      const std::uint64_t bits = words[w] & RunMask(w, first, last);
      if (bits != 0) return w * 64 + __builtin_ctzll(bits);
    }
    return last + 1;
  }
  std::int64_t LastSet(std::int64_t row, std::int64_t first, std::int64_t last) const {
    const std::uint64_t* words = &words_[Word(row, 0)];
    for (std::int64_t w = last >> 6; w >= first >> 6; --w) {
      const std::uint64_t bits = words[w] & RunMask(w, first, last);
      if (bits != 0) return w * 64 + 63 - __builtin_clzll(bits);
    }
    return first - 1;
  }

  // Set points inside `ball`; the same as summing Count over grid.ForEachRun(ball), faster.
  std::int64_t CountIn(const Sphere& ball) const;
  // The same, for a field whose set points all lie in the box low..high (grid points,
  // inclusive): only the blocks in the box are looked at.
  std::int64_t CountIn(const Sphere& ball, const std::array<std::int64_t, 3>& low,
                       const std::array<std::int64_t, 3>& high) const;

 private:
  std::size_t Word(std::int64_t row, std::int64_t w) const {
    return static_cast<std::size_t>(row * words_per_row_ + w);
  }
  std::size_t Block(std::int64_t row, std::int64_t w) const {
    const std::int64_t j = row % grid_.dim(1);
    const std::int64_t k = row / grid_.dim(1);
    return Block3(w, j / kBlockRows, k / kBlockRows);
  }
  std::size_t Block3(std::int64_t w, std::int64_t jb, std::int64_t kb) const {
    return static_cast<std::size_t>(w + words_per_row_ * (jb + blocks_y_ * kb));
  }
  // Sets the balls' points in slices k_low..k_high.
  void SetInSlices(const std::vector<Sphere>& balls, std::int64_t k_low, std::int64_t k_high);
  // op(word, mask) changes the word and returns the change in its set bits.
  template <typename Op>
  void ForEachWord(std::int64_t row, std::int64_t first, std::int64_t last, Op&& op) {
    std::uint64_t* words = &words_[Word(row, 0)];
    const std::size_t block = Block(row, 0);
    for (std::int64_t w = first >> 6; w <= last >> 6; ++w) {
      block_counts_[block + static_cast<std::size_t>(w)] += op(words[w], RunMask(w, first, last));
    }
  }

  const SampleGrid& grid_;
  std::int64_t words_per_row_ = 0;
  std::int64_t blocks_y_ = 0;
  std::vector<std::uint64_t> words_;
  std::vector<std::int32_t> block_counts_;
};

// The points one greedy choice cleared from a bit field, in a field of their own: the gain of
// a ball near the choice then falls by exactly the points it shares with them, counted over
// the blocks of their box, instead of being recounted over the whole ball.
class ClearedPoints {
 public:
  explicit ClearedPoints(const SampleGrid& grid) : grid_(grid), kept_(grid) {}

  // Clears the ball's points from `field` and keeps those that were set (only these), in
  // place of the last Take's.
  void Take(BitField& field, const Sphere& ball);
  // Kept points inside `ball`: what field.CountIn(ball) lost to the last Take.
  std::int64_t CountIn(const Sphere& ball) const;

 private:
  struct Run {
    std::int64_t row, first, last;
  };

  const SampleGrid& grid_;
  BitField kept_;
  std::vector<Run> runs_;  // the last Take's runs (with a kept point), to clear kept_
  // The box of the kept points, in grid points (empty: low > high).
  std::array<std::int64_t, 3> low_ = {0, 0, 0};
  std::array<std::int64_t, 3> high_ = {-1, -1, -1};
};

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
  void Change(const Sphere& ball, int step);

  const SampleGrid& grid_;
  BitField uncovered_;
  BitField once_;
  std::vector<std::uint16_t> counts_;
};

}  // namespace inscribe::internal
