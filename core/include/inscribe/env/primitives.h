// Primitive obstacles as an environment: boxes, spheres, capsules, cylinders and planes
// (half-spaces), each with its exact signed distance (metres, negative inside). Several
// primitives: a ball's clearance is the smallest of its clearances to each, so a ball inside
// two overlapping primitives reports the deeper of its two depths, not the depth in their
// union. O(#primitives) per ball.
#pragma once

#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/env/environment.h"
#include "inscribe/geometry/rigid_pose.h"

namespace inscribe {

enum class PrimitiveShape { kBox, kSphere, kCapsule, kCylinder, kPlane };

// "box", "sphere", "capsule", "cylinder", "plane".
const char* PrimitiveShapeName(PrimitiveShape shape);

// One obstacle in its own frame `pose` (in the world):
//   kBox       half_extents (x, y, z), centred on the frame's origin;
//   kSphere    radius, centred on the origin;
//   kCapsule   radius around the segment from -half_length to +half_length on the frame's z;
//   kCylinder  radius around z, from -half_length to +half_length (flat caps);
//   kPlane     the half-space z <= 0 of the frame (its normal is the frame's +z).
struct Primitive {
  PrimitiveShape shape = PrimitiveShape::kBox;
  RigidPose pose;
  Vector3 half_extents = Vector3::Zero();
  double radius = 0.0;
  double half_length = 0.0;
};

// The exact signed distance from `point` (world frame) to the primitive. O(1).
double PrimitiveSignedDistance(const Primitive& primitive, const Vector3& point);

class PrimitiveEnvironment final : public Environment {
 public:
  // INVALID_ARGUMENT naming the primitive and field: a pose NormalizedPose refuses, a size that
  // is not finite or not > 0 for its shape (half_extents for boxes; radius for spheres,
  // capsules and cylinders; half_length >= 0 for capsules, > 0 for cylinders). O(n).
  static absl::StatusOr<PrimitiveEnvironment> Create(std::vector<Primitive> primitives);

  const std::vector<Primitive>& primitives() const { return primitives_; }

  int FirstColliding(absl::Span<const Sphere> balls) const override;
  void Clearances(absl::Span<const Sphere> balls, const ClearanceRequest& request,
                  absl::Span<ClearanceInterval> out) const override;

 private:
  explicit PrimitiveEnvironment(std::vector<Primitive> primitives, double scale)
      : primitives_(std::move(primitives)), scale_(scale) {}
  ClearanceInterval Bounds(const Sphere& ball) const;

  std::vector<Primitive> primitives_;  // poses normalised
  double scale_ = 0.0;                 // largest |translation| + size
};

}  // namespace inscribe
