// Continuous refinement of an internal sphere set: projected gradient ascent on the exact
// volume of the balls' union, each ball kept inside the solid.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

struct InternalRefinementOptions {
  // Gradient steps tried, >= 0; 0 returns the input unchanged.
  int iterations = 20;
  // Points sampled on each sphere (a Fibonacci lattice) to estimate the exposed area and flux
  // that make the volume's gradient, >= 16. Only the step direction comes from samples; each
  // step is accepted only if the exact union volume grows.
  int samples_per_sphere = 256;
};

// OK, or INVALID_ARGUMENT naming the first bad field. O(1).
absl::Status CheckInternalRefinementOptions(const InternalRefinementOptions& options);

struct InternalRefinement {
  std::vector<Sphere> spheres;  // same count and order as the input
  double volume_before = 0.0;   // exact union volume (UnionVolume) of the input
  double volume_after = 0.0;    // of `spheres`; >= volume_before
  int iterations = 0;           // steps tried
  int accepted = 0;             // steps that grew the volume
};

// Moves centres and radii of `spheres` (each with its centre inside the solid of `oracle` and
// its radius at most the distance to the boundary) to grow the union's volume. The gradient
// w.r.t. r_i is the exposed area of sphere i, w.r.t. c_i the integral of the outward normal
// over that area. After a step every ball is projected: a centre that leaves the solid keeps
// its old ball; otherwise r := min(r', d (1 - 1e-9)) with d the oracle's distance from the new
// centre, so a ball tangent to the boundary stays tangent (its radius follows d). A ball takes
// only a move that gains to first order (see docs/algorithms.md for the tangent balls' three
// directions). Steps are halved until the exact volume grows (at most 8 halvings), so the
// volume never falls. Deterministic (serial).
// Errors: INVALID_ARGUMENT for bad options or spheres.
absl::StatusOr<InternalRefinement> RefineInternalSpheres(
    const BoundaryOracle& oracle, const std::vector<Sphere>& spheres,
    const InternalRefinementOptions& options = {});

}  // namespace inscribe
