// A robot's states against an environment (env/environment.h): for each joint vector of a
// batch, whether the robot is in collision with the world or with itself, and per link (or
// per sphere) a certified interval for its clearance to the world; certificates reused along
// a motion; motion segments checked by their clearances (conservative advancement) or at a
// resolution.
//
// The robot is its spheres per link (robot_spheres.h's RobotSpheres, link frames, metres):
// against the world each sphere's radius grows by its link's collision_buffer, in
// self-collision checks by its self_collision_buffer. Self-collision checks every pair of
// links with spheres that self_collision_ignore does not list: two links collide when any of
// their spheres overlap or touch (|c_a - c_b| <= r_a + r_b, up to the environment margin).
// A link's clearance is the smallest of its spheres' clearances (environment.h).
//
// Certificate reuse: after a sphere's query at centre c0 gave [lower, upper], at a later state
// where the same sphere's centre c1 is at distance d from c0 (computed from the two posed
// centres, plus the margin), [lower - L d, upper + L d] still holds (L the environment's
// Lipschitz constant), and the sphere needs no query while that interval answers the
// question (lower > 0 for yes/no; the tolerance or max_distance for intervals).
//
// Segments: between states q0 and q1 the configuration moves linearly, q(t) = q0 + t (q1 -
// q0). A sphere's centre then travels at most D = sum over the joints above its link of
// |delta of the joint's value| * R, where R bounds the distance from the sphere's centre to
// the joint's axis along the whole segment (revolute joints; 1 for prismatic ones): the sum
// of the fixed offsets (joint origins and anchors) between the joint and the centre, plus the
// travel of prismatic joints between them at the segment's ends. That is the arc length of
// the centre's path, so the swept ball stays within D of both ends' balls: a sub-segment is
// clear when, for every sphere, lower(t0) + lower(t1) > L D, and for every enabled pair of
// links, pair lower(t0) + pair lower(t1) > D_a + D_b (the links' largest D). Otherwise it is
// halved, down to SegmentOptions::min_step.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "inscribe/env/environment.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/robot_spheres.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::robot {

struct StateQuery {
  // false: yes/no, every state stops at its first collision (world first, then self); true:
  // clearance intervals per link, and self-collision, for every state.
  bool intervals = false;
  // With intervals: per sphere too, each to `clearance`'s tolerance.
  bool per_sphere = false;
  bool self_collision = true;
  // How tight intervals must be; per link: upper - lower of the link's interval.
  ClearanceRequest clearance;
  // Treat the batch as a motion: each state reuses the certificates of the states before it.
  bool reuse_certificates = false;
};

// Flat arrays, state-major, for batches: entry [s * links + k] is state s, link k.
struct StateBatchResult {
  int states = 0, links = 0, spheres = 0;
  std::vector<std::uint8_t> collides;               // per state: world or self
  std::vector<std::uint8_t> world_collision;        // per state (yes/no: only when found first)
  std::vector<std::uint8_t> self_collision;         // per state (yes/no: only when checked)
  std::vector<ClearanceInterval> link_clearance;    // states x links, with intervals
  std::vector<ClearanceInterval> sphere_clearance;  // states x spheres, with per_sphere
  std::int64_t ball_queries = 0;                    // balls handed to the environment
  std::int64_t reused = 0;                          // sphere checks a certificate answered
};

struct SegmentOptions {
  enum class Method {
    kClearance,   // conservative advancement (the header): a proof when it says clear
    kResolution,  // states every `resolution` apart: no proof in between
  };
  Method method = Method::kClearance;
  // kClearance: sub-segments shorter than this (in t, 0 < min_step <= 1) are accepted when
  // both ends are clear, and the segment is then reported clear but not proved.
  double min_step = 1.0 / 1024;
  // kResolution: the largest step between checked states, in the max norm of the joint
  // values (radians or metres), > 0.
  double resolution = 0.01;
};

struct SegmentResult {
  bool collides = false;  // a checked state collides (at t_collision)
  bool proved = false;    // clear, with the proof of the header (kClearance)
  double t_collision = -1.0;
  std::int64_t states_checked = 0;
};

class RobotStateChecker {
 public:
  // `robot`'s tree gives the kinematics and the motion bounds; `spheres` the spheres per link
  // (links not in the model, or without spheres, are not checked). INVALID_ARGUMENT naming
  // the problem: Kinematics::Create's and CheckRobotSpheres' errors, a link of `spheres` that
  // `robot` does not have, a padded radius below 0 (naming link and sphere), a robot without
  // spheres. O(#spheres + #links^2).
  static absl::StatusOr<RobotStateChecker> Create(const UrdfRobot& robot,
                                                  const RobotSpheres& spheres);

  const Kinematics& kinematics() const;
  int variables() const;
  // The checked links (those with spheres, in the model's order) and their spheres.
  const std::vector<std::string>& links() const;
  int spheres() const;
  // The link pairs self-collision checks (indices into links()).
  const std::vector<std::pair<int, int>>& self_pairs() const;

  // The spheres at q in the world frame with their world padding (collision_buffer) plus
  // `extra` metres, in link order: what the self-filter drops points inside. Errors:
  // Kinematics::LinkPoses'.
  absl::StatusOr<std::vector<Sphere>> WorldSpheres(absl::Span<const double> q,
                                                   double extra = 0.0) const;

  // Every state of `states` (count x variables(), row-major). Errors: INVALID_ARGUMENT for a
  // size that is not a multiple of variables(), a non-finite value (naming state and
  // variable), CheckClearanceRequest's. O(states * (#links + #spheres + pairs' spheres)),
  // far less for states the early exits and certificates answer.
  absl::StatusOr<StateBatchResult> CheckStates(absl::Span<const double> states,
                                               const Environment& environment,
                                               const StateQuery& query = {}) const;

  // The segment from q0 to q1. Errors: as CheckStates; INVALID_ARGUMENT for options out of
  // range (naming the field).
  absl::StatusOr<SegmentResult> CheckSegment(absl::Span<const double> q0,
                                             absl::Span<const double> q1,
                                             const Environment& environment,
                                             const SegmentOptions& options = {}) const;

  // How far each sphere's centre can travel on the segment (the header's D), metres, in
  // sphere order. Errors: as CheckStates.
  absl::StatusOr<std::vector<double>> SegmentTravelBounds(absl::Span<const double> q0,
                                                          absl::Span<const double> q1) const;

  struct Model;
  explicit RobotStateChecker(std::shared_ptr<const Model> model);

 private:
  std::shared_ptr<const Model> model_;
};

}  // namespace inscribe::robot
