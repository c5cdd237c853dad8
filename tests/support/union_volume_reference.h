// Two references for the volume of a union of balls, independent of the library's 3-D
// formulas (inscribe/union_of_balls.h), for tests that check UnionVolume against them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "inscribe/geometry/sphere.h"

namespace inscribe::testing {

// vol(union of balls) = integral over z of the area of the union of the disks that the plane
// at height z cuts from the balls. Each area is exact (Green's theorem over the uncovered circle
// arcs); between "events" (a sphere's top or bottom, two slice circles touching, three slice
// circles through one point) the area is analytic in z, so Gauss-Legendre with `order` nodes
// on each event interval converges fast (tests rely on 1e-12 relative at the default order).
// balls: non-empty, radii > 0. Cost O(n^3) for the events plus O(n^2) per node and slice.
double SliceQuadratureVolume(std::vector<Sphere> balls, int order = 24);

// A Monte Carlo estimate and its standard error (one sigma), in the balls' length unit cubed.
struct MonteCarloEstimate {
  double volume;
  double standard_error;
};

// Which balls may contain a point: a uniform grid over the balls' bounding box, of cells about
// the largest radius wide (at most 64 per axis). Keeps a reference to `balls`, which must be
// non-empty and outlive the grid.
class BallGrid {
 public:
  explicit BallGrid(const std::vector<Sphere>& balls);
  // Corners of the balls' axis-aligned bounding box.
  const Vector3& lo() const { return lo_; }
  const Vector3& hi() const { return hi_; }
  // True when p is in (or on) one of the balls.
  bool Contains(const Vector3& p) const;

 private:
  int Cell(double v, int k) const;
  std::size_t Index(int x, int y, int z) const;

  const std::vector<Sphere>& balls_;
  Vector3 lo_, hi_;
  int dims_[3];
  std::vector<std::vector<std::size_t>> cells_;
};

// `samples` points uniform in the balls' bounding box, counted in parallel over fixed blocks of
// samples with one seed each, so the result does not depend on the thread schedule.
// balls: non-empty.
MonteCarloEstimate MonteCarloVolume(const std::vector<Sphere>& balls, std::int64_t samples,
                                    std::uint64_t seed);

}  // namespace inscribe::testing
