// The one interface a robot-state checker asks about the world: for balls (robot spheres in
// the world frame, metres), "does any touch an obstacle?" and "how far is each from the
// obstacles?", answered with certified intervals. Point clouds (point_cloud.h), signed
// distance grids (distance_grid.h) and primitives (primitives.h) implement it.
//
// A ball's clearance is the signed distance from its surface to the obstacles': for a ball
// (c, r), clearance = f(c) - r, with f(c) the signed distance from c to the obstacles
// (negative inside one). A ball collides when its clearance is <= 0 (closed sets touching).
// Every answer is sound under floating point: lower <= clearance <= upper always, "no
// collision" is answered only when clearance > 0 is proved, and "collision" may be answered
// for a ball whose clearance is positive by less than the environment's rounding margin
// (at most kEnvironmentMargin times its coordinate scale plus kCertifiedDistanceFloor).
#pragma once

#include <limits>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {

// Relative rounding margin of environment answers: this fraction of the coordinate scale (the
// largest |coordinate| + radius of the obstacles and the ball), plus kCertifiedDistanceFloor
// (certified_distance.h). A distance in double from a few subtractions, squares and one
// square root errs by a few units in the last place (about 1e-15 relative); this margin stays
// far above that.
inline constexpr double kEnvironmentMargin = 1e-12;

// A certified interval for a ball's clearance, metres: lower <= clearance <= upper.
struct ClearanceInterval {
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  // Whether the interval proves the ball clear of the obstacles.
  bool clear() const { return lower > 0.0; }
};

// How tight a clearance interval must be.
struct ClearanceRequest {
  // upper - lower <= tolerance, metres (>= 0; +infinity: whatever the environment bounds in
  // O(1) per ball), unless lower >= max_distance. Point clouds then search their points;
  // a grid's width is its own (distance_grid.h) whatever is asked.
  double tolerance = 0.0;
  // Clearances at or beyond this distance need not be tight: the interval then only proves
  // lower >= max_distance (its upper may be +infinity). Metres, > 0 (+infinity: every
  // interval tight). A planner's activation distance.
  double max_distance = std::numeric_limits<double>::infinity();
};

// OK, or INVALID_ARGUMENT naming the field: a tolerance that is NaN or negative, a
// max_distance that is NaN or not positive. O(1).
absl::Status CheckClearanceRequest(const ClearanceRequest& request);

// Immutable once built, so queries from several threads need no lock.
class Environment {
 public:
  virtual ~Environment() = default;

  // The index of the first ball of `balls` (centres in the world frame, radii >= 0) that is
  // not proved clear, or -1 when every one is. Stops at the first. Balls are not checked
  // (the robot-state checker checks its spheres once).
  virtual int FirstColliding(absl::Span<const Sphere> balls) const = 0;

  // An interval for every ball: out[i] for balls[i] (out.size() == balls.size()).
  // `request` is checked by the caller (CheckClearanceRequest).
  virtual void Clearances(absl::Span<const Sphere> balls, const ClearanceRequest& request,
                          absl::Span<ClearanceInterval> out) const = 0;

  // L such that |f(x) - f(y)| <= L |x - y| for the signed distance f this environment
  // bounds: 1 for exact distances, the grid's stated constant for a grid. A ball that moved
  // by at most d keeps clearance >= lower - L d (the certificate reuse of robot_states.h).
  virtual double Lipschitz() const { return 1.0; }
};

}  // namespace inscribe
