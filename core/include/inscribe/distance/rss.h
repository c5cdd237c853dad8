// The rectangle swept sphere (RSS) bounding volume (Larsen, Gottschalk, Lin, Manocha 2000, as
// in PQP), fitted to sets of balls for the sphere-set hierarchy of paper Section VI-C: medial
// spheres lie along flat sheets whose radius varies smoothly, which an RSS bounds tightly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

// A rectangle swept sphere: every point within `radius` of the rectangle
//   {origin + s * axes.col(0) + t * axes.col(1) : 0 <= s <= length[0], 0 <= t <= length[1]}.
// Frame and units are the caller's (the balls' frame for FitRss). A zero length in one
// direction makes the rectangle a segment (a capsule), in both a point (a ball).
struct Rss {
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // orthonormal columns: edge 0, edge 1,
                                                       // normal = edge 0 x edge 1
  Vector3 origin = Vector3::Zero();                    // a corner of the rectangle
  double length[2] = {0.0, 0.0};                       // edge lengths, >= 0
  double radius = 0.0;                                 // >= 0
};

// A tight RSS containing every ball balls[indices[i]], i < count (count >= 1; indices in
// range). Orientation: principal axes of the covariance of the centres (edge 0 along the
// largest spread, the normal along the smallest). Radius: half the spread of the balls along
// the normal, so the rectangle's plane is centred between the extreme balls. Rectangle: the
// smallest (PQP's procedure, adapted to balls) such that ball i's centre is within
// radius - r_i of it: first per axis, then grown where a ball lies beyond a corner, then
// each edge moved inward as far as every ball stays inside. Finally the radius is recomputed
// as max_i(distance(c_i, rectangle) + r_i) and padded by 32 ulps of (radius + the largest
// |coordinate| of the centres), so every ball is inside even after the rounding of a later
// distance computation. A single ball gives a zero rectangle at its centre with radius = its
// radius, exactly; coincident centres likewise (within rounding) with the largest radius;
// collinear centres a segment.
// Cost: O(count): a few passes over the balls, one 3x3 eigendecomposition and one temporary
// array; about 0.2 us + 23 ns per ball (bench/rss_bench).
Rss FitRss(const std::vector<Sphere>& balls, const std::int32_t* indices, std::size_t count);

// Signed distance between RSS `a` and RSS `b` placed into a's frame by (rotation, translation):
// a point x of b's frame is at rotation * x + translation in a's frame (rotation orthonormal).
// Equals the distance between the two rectangles minus a.radius and b.radius; negative when
// the swept volumes overlap (down to -(a.radius + b.radius) when the rectangles intersect).
// Hence a lower bound on |c_a - c_b| - r_a - r_b for any balls (c_a, r_a) inside a and
// (c_b, r_b) inside b. Exact up to rounding (about 1e-16 of the rectangles' extent and
// distance): the algorithm of RectangleDistance without witness points, plus a clamp when
// either rectangle is a point (length 0 in both directions, e.g. a hierarchy's leaf ball).
// Cost (bench/rss_bench, one core, RelWithDebInfo): about 11 ns when one side is a point,
// 25-35 ns for separated rectangles, 60-110 ns for overlapping ones; no allocation,
// thread-safe.
double RssDistance(const Rss& a, const Eigen::Matrix3d& rotation, const Vector3& translation,
                   const Rss& b);

// Distance between the rectangles of `a` and `b` (radii ignored), both in the same frame,
// with closest points point_a on a's rectangle and point_b on b's (either pointer may be
// null). Exact in floating point for every configuration: apart, parallel, coplanar,
// crossing, touching, and degenerate (segment or point) rectangles; 0, with
// point_a == point_b a common point, when the rectangles intersect (a crossing edge, a
// corner inside the other rectangle; rectangles that overlap within a common plane may give
// a value of rounding size, ~1e-16 of their extent, instead of 0).
//
// Method: the closest pair has a point on an edge of one rectangle, so the distance is the
// smallest over the 8 edges of the edge's distance to the other rectangle; each of those is
// a convex piecewise-quadratic function of the edge parameter, minimised exactly at a corner
// or at the root of its piecewise-linear derivative. A candidate pair (p, q) whose
// difference d = q - p satisfies the optimality (separating plane) condition - p maximises
// d.x over a's rectangle and q minimises d.y over b's - ends the search early: first any
// corner of b, then any corner of a (tested branch-free, all four at once), then the edges'
// interior minima. Cost: as RssDistance plus ~10 ns for the witness points.
double RectangleDistance(const Rss& a, const Rss& b, Vector3* point_a, Vector3* point_b);

}  // namespace inscribe
