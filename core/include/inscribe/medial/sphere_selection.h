// Optimised sphere selection. The paper keeps one medial sphere per voxel of the
// finest grid within the budget, which spreads the budget evenly over the medial surface; the
// paper itself notes that this is not the distribution that minimises the volume error, where
// a good set has more large spheres and fewer small ones. GenerateOptimisedSpheres makes a pool
// of medial spheres on a finer grid (about pool_factor times the budget) and keeps the N that
// cover the most of the pool's union (SelectByCoverage). Every chosen sphere is a pool sphere
// with its contact, so the set is internal and tangent exactly as the paper's is.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

// How a sphere budget is spent.
enum class SphereSelection {
  // Section III: the finest voxel grid giving at most N spheres, one per voxel
  // (GenerateWithSphereBudget).
  kPaper,
  // The N spheres of a finer grid's pool covering the most volume (GenerateOptimisedSpheres).
  kOptimised,
};

// "paper", "optimised": the names the CLI, the service and the bindings use.
const char* SphereSelectionName(SphereSelection selection);
// The selection SphereSelectionName names; INVALID_ARGUMENT listing both names otherwise.
absl::StatusOr<SphereSelection> ParseSphereSelection(absl::string_view name);

struct CoverageSelectionOptions {
  // N: at most this many balls are chosen, > 0.
  std::int64_t max_spheres = 0;
  // The volume is measured by a regular grid of sample points over the balls' bounding box,
  // with at most this many points (>= 4096, <= 2^31). More points: finer volume estimates,
  // proportionally more time.
  std::int64_t grid_points = std::int64_t{1} << 22;
  // Swap passes after the greedy choice (>= 0; 0: the greedy set as it is). Each pass offers
  // every chosen ball's place to the unchosen balls overlapping it.
  int swap_passes = 0;
};

struct CoverageSelection {
  std::vector<std::int32_t> chosen;  // indices into the input balls, ascending
  std::int64_t samples = 0;          // grid points inside at least one ball
  std::int64_t covered = 0;          // of those, inside a chosen ball
  std::int64_t evaluations = 0;      // gains counted over whole balls (up front, swap passes)
  std::int64_t swaps = 0;            // chosen balls replaced in the swap passes
  double grid_spacing = 0.0;         // distance between neighbouring sample points

  // covered / samples: the share of the balls' union the chosen ones hold (0 without samples).
  double covered_fraction() const {
    return samples > 0 ? static_cast<double>(covered) / static_cast<double>(samples) : 0.0;
  }
};

// Chooses at most N of `balls` whose union holds the most sample points: the greedy maximum
// coverage, each step taking the ball that adds the most points (the lowest index among
// equals). Coverage is submodular, so the set covers at least 1 - 1/e (63%) of what the best N
// balls cover, and in practice far more. The gains are kept exact by subtracting from each
// ball the points it shares with each choice. Stops early when no ball adds a sample.
// Deterministic whatever the thread count.
// Errors: INVALID_ARGUMENT for N <= 0, grid_points out of range, a bad ball (CheckSphere) or
// more than 2^31 - 1 balls; CANCELLED.
// Cost: O(sum over balls of (r / h)^2) up front (h the grid spacing), then per choice a test
// of every ball with a gain and, for those that share points with it, a count over the blocks
// of their overlap; memory 2 grid_points / 8 bytes.
absl::StatusOr<CoverageSelection> SelectByCoverage(const std::vector<Sphere>& balls,
                                                   const CoverageSelectionOptions& options,
                                                   const GenerationControl& control = {});

struct OptimisedSphereOptions {
  // N: at most this many spheres, > 0.
  std::int64_t max_spheres = 0;
  // The pool's medial-sphere options; voxel_size is chosen here (ignored).
  MedialSphereOptions base;
  // The pool aims at this many times N medial spheres, in [1.5, 64]. A richer pool gives a
  // smaller error and costs a finer grid.
  double pool_factor = 3.0;
  // SelectByCoverage's sample grid; 0: DefaultSelectionGridPoints(max_spheres).
  std::int64_t grid_points = 0;
  // Hard cap on pool runs (the first sigma is a guess; later runs correct it), >= 1.
  int max_pool_runs = 4;
  // SelectByCoverage's swap passes.
  int swap_passes = CoverageSelectionOptions{}.swap_passes;
};

// The sample grid used for a budget of N when none is given: 2^22 points, more for budgets
// over 512 (8,192 per sphere, up to 2^26).
std::int64_t DefaultSelectionGridPoints(std::int64_t max_spheres);

struct OptimisedSphereResult {
  // The kept pool run with `set` replaced by the chosen spheres and their contacts, in pool
  // order (the kept run's by voxel, then the coarser runs'); voxel_size and stats are the kept
  // run's.
  MedialSphereResult best;
  std::int64_t pool_size = 0;  // medial spheres in the pool (of every run it took)
  int runs = 0;                // pool runs made (generation runs, as SphereBudgetResult::runs)
  CoverageSelection selection;
  double seconds = 0.0;  // wall time: every pool run and the selection
};

// OK, or INVALID_ARGUMENT naming the first bad field of `options` (as OptimisedSphereOptions
// spells it), the medial options' included. O(1).
absl::Status CheckOptimisedSphereOptions(const OptimisedSphereOptions& options);

// The optimised selection: a pool of medial spheres (GenerateMedialSpheres on a grid whose
// sigma is corrected until the pool holds between half and twice pool_factor * N spheres, or
// the voxel limit or max_pool_runs stops it; a run that falls short is followed by a finer
// one aimed at the rest, and the pool is the kept run's spheres followed by those of every
// earlier run with fewer), then SelectByCoverage over it. Deterministic.
// Errors: CheckOptimisedSphereOptions', GenerateMedialSpheres', SelectByCoverage's; CANCELLED.
absl::StatusOr<OptimisedSphereResult> GenerateOptimisedSpheres(
    const BoundaryOracle& oracle, const OptimisedSphereOptions& options,
    const GenerationControl& control = {});

}  // namespace inscribe
