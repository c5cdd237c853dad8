#include "inscribe/robot/mjcf_orientation.h"

#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace inscribe::robot {
namespace {

// Below this norm MuJoCo's compiler (mjMINVAL) takes a vector for zero.
constexpr double kTiny = 1e-15;

Eigen::Matrix3d FromQuaternion(double w, double x, double y, double z) {
  return Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
}

}  // namespace

absl::StatusOr<Eigen::Matrix3d> MjcfQuatRotation(const Eigen::Vector4d& wxyz) {
  const double norm = wxyz.norm();
  if (!std::isfinite(norm) || norm < kTiny) {
    return absl::InvalidArgumentError("the quaternion is zero (or not finite)");
  }
  return FromQuaternion(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}

absl::StatusOr<Eigen::Matrix3d> MjcfAxisAngleRotation(const Vector3& axis, double angle) {
  const double norm = axis.norm();
  if (!std::isfinite(norm) || norm < kTiny || !std::isfinite(angle)) {
    return absl::InvalidArgumentError("the axis of axisangle is zero (or not finite)");
  }
  return Eigen::AngleAxisd(angle, axis / norm).toRotationMatrix();
}

absl::StatusOr<Eigen::Matrix3d> MjcfEulerRotation(const Vector3& angles,
                                                  absl::string_view sequence) {
  if (sequence.size() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("eulerseq '", sequence, "' is not three of x y z X Y Z"));
  }
  Eigen::Quaterniond turned = Eigen::Quaterniond::Identity();
  for (int i = 0; i < 3; ++i) {
    const char letter = sequence[static_cast<std::size_t>(i)];
    Vector3 axis;
    switch (letter) {
      case 'x':
      case 'X':
        axis = Vector3::UnitX();
        break;
      case 'y':
      case 'Y':
        axis = Vector3::UnitY();
        break;
      case 'z':
      case 'Z':
        axis = Vector3::UnitZ();
        break;
      default:
        return absl::InvalidArgumentError(
            absl::StrCat("eulerseq '", sequence, "' is not three of x y z X Y Z"));
    }
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(angles[i], axis));
    const bool intrinsic = letter >= 'a';
    turned = intrinsic ? turned * turn : turn * turned;
  }
  return turned.normalized().toRotationMatrix();
}

absl::StatusOr<Eigen::Matrix3d> MjcfXyAxesRotation(const Vector3& x, const Vector3& y) {
  const double x_norm = x.norm();
  if (!std::isfinite(x_norm) || x_norm < kTiny) {
    return absl::InvalidArgumentError("the x axis of xyaxes is zero (or not finite)");
  }
  const Vector3 ux = x / x_norm;
  const Vector3 y_orthogonal = y - y.dot(ux) * ux;
  const double y_norm = y_orthogonal.norm();
  if (!std::isfinite(y_norm) || y_norm < kTiny) {
    return absl::InvalidArgumentError(
        "the y axis of xyaxes is zero or parallel to the x axis (or not finite)");
  }
  Eigen::Matrix3d rotation;
  rotation.col(0) = ux;
  rotation.col(1) = y_orthogonal / y_norm;
  rotation.col(2) = ux.cross(rotation.col(1));
  return rotation;
}

absl::StatusOr<Eigen::Matrix3d> MjcfZAxisRotation(const Vector3& z) {
  const double norm = z.norm();
  if (!std::isfinite(norm) || norm < kTiny) {
    return absl::InvalidArgumentError("the z axis is zero (or not finite)");
  }
  Vector3 axis = Vector3::UnitZ().cross(z);
  const double s = axis.norm();
  // Parallel to z: MuJoCo takes x as the axis (a half turn for -z, none for +z).
  axis = s < 1e-10 ? Vector3::UnitX() : Vector3(axis / s);
  const double angle = std::atan2(s, z.z());
  const double half = 0.5 * angle;
  const Vector3 v = std::sin(half) * axis;
  return FromQuaternion(std::cos(half), v.x(), v.y(), v.z());
}

}  // namespace inscribe::robot
