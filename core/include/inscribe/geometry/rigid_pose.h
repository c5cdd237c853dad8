// Rigid motions: where a sphere set (or mesh) sits in the world.
#pragma once

#include <Eigen/Geometry>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe {

// x_world = rotation * x_local + translation. `rotation` is a unit quaternion (w, x, y, z).
struct RigidPose {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Vector3 translation = Vector3::Zero();

  Vector3 operator*(const Vector3& local) const { return rotation * local + translation; }
  // this * other: first `other`, then this.
  RigidPose operator*(const RigidPose& other) const {
    return RigidPose{rotation * other.rotation, rotation * other.translation + translation};
  }
  RigidPose Inverse() const {
    const Eigen::Quaterniond inverse = rotation.conjugate();
    return RigidPose{inverse, -(inverse * translation)};
  }
};

// INVALID_ARGUMENT unless every number is finite and the quaternion's norm is within 1e-6 of
// 1 (callers that read rounded quaternions normalise first; see NormalizedPose).
absl::Status CheckPose(const RigidPose& pose);

// The pose with its quaternion scaled to unit length; a quaternion already unit to rounding
// (squared norm within 16 ulps of 1) is kept as it is, so normalising twice gives the same
// bits as once. INVALID_ARGUMENT for non-finite numbers or a quaternion whose norm is not
// within 1e-3 of 1 (a typo rather than rounding).
absl::StatusOr<RigidPose> NormalizedPose(const RigidPose& pose);

}  // namespace inscribe
