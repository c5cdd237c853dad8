// The choice of a cover's spheres among candidate balls (sphere_cover.cpp): the points a
// cover must reach, a grid to find them near a centre, each candidate's reach lists, and the
// greedy set covers of the budget and delta modes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"

namespace inscribe::internal {

// How much candidate i must grow to reach sample p: |p - c_i| - r_i.
inline double Growth(const Sphere& s, const Vector3& p) { return (p - s.center).norm() - s.radius; }

// The points a cover must reach: the mesh vertices, boundary samples, and the deepest
// candidate centres (standing in for the interior).
struct CoverSamples {
  std::vector<Vector3> points;
};

// Uniform grid over points, for the points within a distance of a centre.
class PointGrid {
 public:
  PointGrid(const std::vector<Vector3>& points, double cell) : points_(points), cell_(cell) {
    lo_ = hi_ = points.empty() ? Vector3::Zero() : points[0];
    for (const Vector3& p : points) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
    for (int k = 0; k < 3; ++k) {
      dims_[k] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi_[k] - lo_[k]) / cell) + 1);
    }
    std::vector<std::int64_t> key(points.size());
    start_.assign(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]) + 1, 0);
    for (std::size_t i = 0; i < points.size(); ++i) {
      key[i] = Key(Cell(points[i]));
      ++start_[static_cast<std::size_t>(key[i]) + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    order_.resize(points.size());
    std::vector<std::int64_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < points.size(); ++i) {
      order_[static_cast<std::size_t>(fill[static_cast<std::size_t>(key[i])]++)] =
          static_cast<std::int32_t>(i);
    }
  }

  // Calls f(index) for every point within `radius` of `center` (and maybe a few more).
  template <typename F>
  void ForEachNear(const Vector3& center, double radius, F&& f) const {
    const Eigen::Array3i a = Cell(center - Vector3::Constant(radius));
    const Eigen::Array3i b = Cell(center + Vector3::Constant(radius));
    for (int x = a[0]; x <= b[0]; ++x) {
      for (int y = a[1]; y <= b[1]; ++y) {
        for (int z = a[2]; z <= b[2]; ++z) {
          const std::int64_t k = Key(Eigen::Array3i(x, y, z));
          for (std::int64_t j = start_[static_cast<std::size_t>(k)];
               j < start_[static_cast<std::size_t>(k) + 1]; ++j) {
            f(static_cast<std::size_t>(order_[static_cast<std::size_t>(j)]));
          }
        }
      }
    }
  }

 private:
  Eigen::Array3i Cell(const Vector3& p) const {
    Eigen::Array3i c;
    for (int k = 0; k < 3; ++k) {
      const double v = std::floor((p[k] - lo_[k]) / cell_);
      c[k] = static_cast<int>(std::clamp(v, 0.0, static_cast<double>(dims_[k] - 1)));
    }
    return c;
  }
  std::int64_t Key(const Eigen::Array3i& c) const {
    return (static_cast<std::int64_t>(c[0]) * dims_[1] + c[1]) * dims_[2] + c[2];
  }

  const std::vector<Vector3>& points_;
  double cell_;
  Vector3 lo_, hi_;
  std::int64_t dims_[3] = {1, 1, 1};
  std::vector<std::int64_t> start_;
  std::vector<std::int32_t> order_;
};

// For each candidate, the samples it reaches by growing at most `limit`, sorted by growth:
// the candidate's cover set at any threshold t <= limit is a prefix.
struct ReachLists {
  std::vector<std::size_t> begin;  // candidate i: entries [begin[i], begin[i + 1])
  std::vector<float> growth;       // rounded; only orders and thresholds the choice
  std::vector<std::int32_t> sample;

  std::size_t Prefix(std::size_t i, double t) const {
    const auto first = growth.begin() + static_cast<std::ptrdiff_t>(begin[i]);
    const auto last = growth.begin() + static_cast<std::ptrdiff_t>(begin[i + 1]);
    return static_cast<std::size_t>(std::upper_bound(first, last, static_cast<float>(t)) - first);
  }
};

ReachLists MakeReachLists(const std::vector<Sphere>& candidates, const CoverSamples& samples,
                          const PointGrid& grid, double limit);

// Greedy set cover at threshold t: repeatedly the candidate reaching the most samples not yet
// reached (ties: the lower index), lazily re-counted. The chosen candidates, or nothing when
// more than `limit` are needed or some sample is out of every candidate's reach.
std::optional<std::vector<std::size_t>> GreedyCover(const ReachLists& lists,
                                                    std::size_t num_samples, double t,
                                                    std::size_t limit);

// The farthest-first choice of `count` candidates (Gonzalez): the deepest, then repeatedly the
// one reaching the worst-served sample with the least growth. Entry k-1: the growth that
// serves every sample with the first k chosen (non-increasing; 0 once every sample is
// reached). O(count * (#samples + #candidates)).
std::vector<double> FarthestFirstThresholds(const std::vector<Sphere>& candidates,
                                            const CoverSamples& samples, std::size_t count);

// The budget mode's choice: at most `count` candidates reaching every sample with the least
// growth threshold found (a binary search over greedy set covers, from the farthest-first
// choice's threshold down).
std::vector<std::size_t> ChooseForBudget(const std::vector<Sphere>& candidates,
                                         const CoverSamples& samples, const PointGrid& grid,
                                         std::size_t count, const GenerationControl& control);

}  // namespace inscribe::internal
