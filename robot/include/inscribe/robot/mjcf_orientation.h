// MJCF's orientations as MuJoCo's compiler reads them (XML reference, "Frame orientations"):
// `quat` (w x y z), `axisangle`, `euler` with the compiler's `eulerseq`, `xyaxes`, `zaxis`, and
// the frame `fromto` gives a capsule, cylinder, box or ellipsoid. Each returns the rotation of the
// element's frame in its parent's frame.
#pragma once

#include <Eigen/Geometry>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe::robot {

// `quat="w x y z"`, normalised. INVALID_ARGUMENT for a zero or non-finite quaternion.
absl::StatusOr<Eigen::Matrix3d> MjcfQuatRotation(const Eigen::Vector4d& wxyz);

// `axisangle="x y z a"`: a turn by a (radians) about the axis, normalised. INVALID_ARGUMENT
// for a zero axis.
absl::StatusOr<Eigen::Matrix3d> MjcfAxisAngleRotation(const Vector3& axis, double angle);

// `euler="a b c"` (radians) in `sequence`, three of x y z X Y Z: one turn per angle about the
// axis its letter names, composed as MuJoCo does letter by letter: a lower-case letter turns
// about the axis of the frame turned so far (intrinsic: R = R * R_i), an upper-case one about
// the parent's fixed axis (extrinsic: R = R_i * R). INVALID_ARGUMENT for another sequence.
absl::StatusOr<Eigen::Matrix3d> MjcfEulerRotation(const Vector3& angles,
                                                  absl::string_view sequence);

// `xyaxes="x1 x2 x3 y1 y2 y3"`: the frame's x axis, and its y axis made orthogonal to x
// (Gram-Schmidt), z = x cross y. INVALID_ARGUMENT when x is zero or y is parallel to it.
absl::StatusOr<Eigen::Matrix3d> MjcfXyAxesRotation(const Vector3& x, const Vector3& y);

// `zaxis="x y z"` and the direction of `fromto`: the smallest turn taking (0, 0, 1) to the
// direction (about z x v by atan2(|z x v|, v_z)); for v along -z, a half turn about x, as
// MuJoCo's compiler. INVALID_ARGUMENT for a zero vector.
absl::StatusOr<Eigen::Matrix3d> MjcfZAxisRotation(const Vector3& z);

}  // namespace inscribe::robot
