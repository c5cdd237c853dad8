// The pieces a cover's spheres are made from (sphere_cover.cpp): which sphere holds which part
// of the boundary, minimum enclosing balls, and the simple constructions a budget's cover is
// compared with (one enclosing ball, k-center clusters, a sphere split in two).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "inscribe/cover/sphere_cover.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/solid/solid.h"

namespace inscribe::internal {

// A sphere grown to reach a point or a cell's corner reaches this much farther (relative), far
// above rounding, so the certificate's own margin (1e-12 on squares) is met.
inline constexpr double kReachMargin = 1e-9;

// A ladder's base: a boundary point, and the mesh vertex it is (-1: a point of a triangle).
struct LadderBase {
  Vector3 point;
  std::int64_t vertex = -1;
};

// The spheres a cover is chosen from. From each base point p of the boundary with inward
// normal n (the vertex normal at a vertex, else the face normal), centres c = p + s n on a
// ladder of depths s = s0, sqrt(2) s0, 2 s0, ... up to s_max while c stays inside and gets
// deeper, each with radius depth(c), and the deepest centre on the normal (a golden-section
// search): internal balls from tiny ones near the boundary (which reach a sharp feature with
// little growth) to the medial ball under p (which reaches far with little growth on flat
// parts). The deepest centre of each ladder is appended to `interior`. Parallel.
std::vector<Sphere> LadderCandidates(const Solid& solid, const std::vector<LadderBase>& base,
                                     double s0, double s_max, std::vector<Vector3>* interior);

// What each sphere alone must hold: every mesh triangle goes whole to the sphere whose radius
// must grow least to hold its corners, or is split in four until that costs at most `edge`
// more than the least growth any sphere needs at its centroid or at one of its corners (or its
// edges are at most `edge`); each `interior` point goes to the sphere that must grow least to reach
// it. Per sphere, the corners of its pieces and its interior points (a ball holding them holds the
// pieces: it is convex). Deterministic; parallel over triangles. `spheres` not empty.
std::vector<std::vector<Vector3>> OwnedPoints(const Mesh& mesh, const std::vector<Sphere>& spheres,
                                              const std::vector<Vector3>& interior, double edge);

// The spheres grown (never shrunk) to hold what OwnedPoints gives each, with `margin` to spare
// (so every point within `margin` of a piece is held too).
std::vector<Sphere> HoldBoundary(const Mesh& mesh, const std::vector<Sphere>& spheres,
                                 const std::vector<Vector3>& interior, double edge, double margin);

// The minimum enclosing ball of `points` (not empty; CGAL's Min_sphere_of_spheres_d in
// floating point), its radius then the largest distance from its centre to a point, padded
// so that every point lies inside.
Sphere EnclosingBall(const std::vector<Vector3>& points);

// k-center clusters of `points` (none for no points): k centres by farthest-first traversal (from
// the point farthest from their mean), each point to its nearest centre, then two rounds of each
// cluster's enclosing ball and each point to the ball it is deepest in relative to its radius
// (least |p - c| - r). At most k balls, one per non-empty cluster. Deterministic.
std::vector<Sphere> KCenterBalls(const std::vector<Vector3>& points, std::size_t k);

// The budgets up to kMonotoneCoverBudget at which every construction runs with
// CoverConstructions::monotone: 1..8, then about every factor of sqrt(2) (11, 16, 23, 32, 45,
// 64).
bool ConstructionBudget(std::int64_t n);

// The better of two certified covers: the lesser delta, then the lesser summed (positive)
// protrusion, then fewer spheres.
bool BetterCover(const GeneratedCover& a, const GeneratedCover& b);

// Depth of a point: its distance to the boundary, negative outside.
double Depth(const Solid& solid, const Vector3& p);

}  // namespace inscribe::internal
