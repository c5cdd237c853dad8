#include "inscribe/geometry/rigid_pose.h"

#include <cmath>
#include <limits>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

// |q|^2 of a quaternion normalised in double lies within a few ulps of 1.
constexpr double kUnitQuaternionTolerance = 16.0 * std::numeric_limits<double>::epsilon();

absl::Status CheckFinite(const RigidPose& pose) {
  if (!pose.rotation.coeffs().allFinite() || !pose.translation.allFinite()) {
    return absl::InvalidArgumentError("pose has a non-finite number");
  }
  return absl::OkStatus();
}

std::string Describe(const Eigen::Quaterniond& q) {
  return absl::StrCat("(", q.w(), ", ", q.x(), ", ", q.y(), ", ", q.z(), ")");
}

}  // namespace

absl::Status CheckPose(const RigidPose& pose) {
  if (absl::Status s = CheckFinite(pose); !s.ok()) return s;
  const double norm = pose.rotation.norm();
  if (!(std::abs(norm - 1.0) <= 1e-6)) {
    return absl::InvalidArgumentError(
        absl::StrCat("quaternion ", Describe(pose.rotation), " has norm ", norm, ", not 1"));
  }
  return absl::OkStatus();
}

absl::StatusOr<RigidPose> NormalizedPose(const RigidPose& pose) {
  if (absl::Status s = CheckFinite(pose); !s.ok()) return s;
  const double norm = pose.rotation.norm();
  if (!(std::abs(norm - 1.0) <= 1e-3)) {
    return absl::InvalidArgumentError(absl::StrCat("quaternion ", Describe(pose.rotation),
                                                   " has norm ", norm,
                                                   "; expected a unit quaternion (w x y z)"));
  }
  RigidPose out = pose;
  // Already unit to rounding (a pose normalised once): unchanged, so normalising again (a
  // service normalising what a client already did) gives the same bits.
  if (std::abs(pose.rotation.squaredNorm() - 1.0) <= kUnitQuaternionTolerance) return out;
  out.rotation.normalize();
  return out;
}

}  // namespace inscribe
