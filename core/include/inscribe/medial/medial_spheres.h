// Medial-sphere generation (paper Section III): internal spheres tangent to the boundary, their
// centres within epsilon of the medial surface, at most one centre per voxel.
#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>

#include "absl/status/statusor.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/boundary_oracle.h"

namespace inscribe {

struct MedialSphereOptions {
  // sigma: side of the cubic voxels, mesh units, > 0. Ignored by GenerateWithSphereBudget.
  double voxel_size = 0.0;
  // theta: candidates whose object angle (the angle at the medial point between its two nearest
  // boundary points) is below this are dropped. Radians, in (0, pi). Paper default 0.6.
  double object_angle = 0.6;
  // Search tolerance along each sample segment: centres lie within epsilon of the medial
  // surface. Mesh units; 0 means 1e-4 of the bounding-box diagonal.
  double epsilon = 0.0;
  // K: sample points per voxel on its circumscribed sphere (a fixed Fibonacci set). Each costs
  // two closest-point queries plus a search where the segment crosses the medial surface.
  int samples = 32;
  // Screening: each voxel first tries this many samples (a separate Fibonacci set, so they
  // add to the K) and takes the full set only if one of their segments through the voxel has
  // ends with different nearest boundary points (a pair that is searched, wherever its
  // crossing lies). 0 (or >= samples) turns it off: every voxel gets the full set. Can miss a
  // sheet that only a few of the K segments cross.
  int screen_samples = 8;
  // Corner screening, before any sampling: one closest-point query per grid vertex (shared by
  // the 8 voxels around it); a voxel whose 8 corners' inward directions at their nearest
  // boundary points all lie within (object_angle - 0.1 rad) of each other is skipped, since a
  // medial sheet of that angle cutting the voxel would split its corners into two groups
  // differing by about that angle. So is a voxel where every corner pair differing by that
  // much points to a sheet (estimated from the two nearest points' tangent planes) more than
  // half a voxel away: near a thin tube's axis the directions turn fast across voxels that the
  // axis does not reach. Can miss a sheet that enters and leaves a voxel through one face.
  bool corner_screen = true;
  // Optional pruning, off by default (pi): a crossing pair whose two ends' nearest boundary
  // points both lie inside faces is searched only if the angle between the ends' directions to
  // them is at least object_angle minus this margin (radians). That angle is the crossing's
  // object angle for two faces, so the low-angle sheets that every edge of a faceted tube
  // grows are skipped (0.1 saves a third of knot1's queries); but on CAD models such as
  // fandisk it also drops useful crossings (nerr 0.090 -> 0.102 at 500 spheres).
  double pair_angle_margin = M_PI;
  // Split voxels that the boundary may cross into 8 half-size voxels, each keeping its own
  // sphere (at most 8 spheres there; paper Section VI-D). Tighter boundary fit, more spheres.
  bool subdivide_boundary = false;
  // Refuse grids with more voxels than this (bounding box / sigma^3, before culling): a tiny
  // sigma is an INVALID_ARGUMENT naming both numbers, never an out-of-memory or a hang.
  std::int64_t max_voxels = 20'000'000;
};

// Progress and cancellation for long runs. `on_progress` is called on the calling thread with
// the fraction done in [0, 1] (monotone; 1 at the end of a successful run); `cancel` is polled
// between and inside voxel batches: set it and the run returns CANCELLED promptly.
struct GenerationControl {
  std::function<void(double fraction)> on_progress;
  const std::atomic<bool>* cancel = nullptr;

  // Whether `cancel` is set.
  bool cancelled() const { return cancel != nullptr && cancel->load(std::memory_order_relaxed); }
};

struct MedialSphereStats {
  std::int64_t grid_voxels = 0;      // voxels of the grid over the bounding box
  std::int64_t visited_voxels = 0;   // inside or possibly crossing the boundary (incl. splits)
  std::int64_t boundary_voxels = 0;  // of those, possibly crossed by the boundary
  std::int64_t screened_voxels = 0;  // of those, skipped by the corner screen
  std::int64_t crossing_pairs = 0;   // sample pairs whose nearest boundary points differ
  std::int64_t searched_pairs = 0;   // of those, searched (pair angle near theta or above)
  std::int64_t candidates = 0;       // medial points passing angle, voxel and inside tests
  std::int64_t closest_point_queries = 0;
  double seconds = 0.0;  // wall time of this run
};

struct MedialSphereResult {
  // Spheres ordered by voxel (x fastest, then y, then z; sub-voxels by octant), with contacts:
  // every sphere's radius is the exact (double-precision) distance from its centre to the
  // boundary, and its contact is the boundary point at that distance.
  SphereSet set;
  double voxel_size = 0.0;  // sigma used
  double epsilon = 0.0;     // epsilon used (resolved from the default)
  // Voxel (i, j, k) is grid_origin + sigma * ([i, i+1) x [j, j+1) x [k, k+1)); the grid has
  // grid_dims cells per axis and is centred on the mesh's bounding box.
  Vector3 grid_origin = Vector3::Zero();
  std::array<std::int64_t, 3> grid_dims = {0, 0, 0};
  MedialSphereStats stats;
};

// OK, or INVALID_ARGUMENT naming the first option out of range (as GenerateMedialSpheres
// refuses it). `need_voxel_size`: voxel_size must be positive and finite too. O(1).
absl::Status CheckMedialSphereOptions(const MedialSphereOptions& options, bool need_voxel_size);

// One run at fixed voxel_size. Parallel over voxels (TBB); the output is the same bit for bit
// for the same mesh and options regardless of thread count or scheduling.
// Errors: INVALID_ARGUMENT for sigma <= 0 or non-finite, theta outside (0, pi), epsilon < 0,
// samples outside [2, 4096], too many voxels; CANCELLED.
// Cost: O(visited voxels * samples * log(sigma/epsilon)) closest-point queries.
absl::StatusOr<MedialSphereResult> GenerateMedialSpheres(const BoundaryOracle& oracle,
                                                         const MedialSphereOptions& options,
                                                         const GenerationControl& control = {});

// The sphere budget of a generation (GenerateSphereSet, GenerateCover) when neither a voxel
// size nor a budget is given.
inline constexpr std::int64_t kDefaultMaxSpheres = 500;

struct SphereBudgetOptions {
  // N: at most this many spheres, > 0.
  std::int64_t max_spheres = 0;
  // Everything but voxel_size is used as given for each run.
  MedialSphereOptions base;
  // The search stops when the smallest sigma found with <= N spheres and the largest sigma found
  // with > N spheres are within this relative gap.
  double relative_tolerance = 0.01;
  // Hard cap on generation runs.
  int max_runs = 24;
};

struct SphereBudgetResult {
  MedialSphereResult best;  // the finest accepted run (most spheres, at most N)
  int runs = 0;             // generation runs made by the search
  double seconds = 0.0;     // wall time of the whole search, all runs included
  // Largest sigma seen that gave more than N spheres (0 if none): the search's other bracket.
  double rejected_voxel_size = 0.0;
};

// The finest voxel grid giving at most N spheres, i.e. the smallest sigma (the paper's "largest
// voxel resolution") with sphere count <= N, to within relative_tolerance. The count is not
// strictly monotone in sigma; the search brackets the budget and refines by interpolating
// log(count) against log(sigma). Errors as GenerateMedialSpheres, plus N <= 0, and
// RESOURCE_EXHAUSTED if even the coarsest sensible grid exceeds N.
absl::StatusOr<SphereBudgetResult> GenerateWithSphereBudget(const BoundaryOracle& oracle,
                                                            const SphereBudgetOptions& options,
                                                            const GenerationControl& control = {});

}  // namespace inscribe
