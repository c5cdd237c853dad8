#include "inscribe/rigid_pose.h"

#include <cmath>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"

namespace inscribe {
namespace {

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
  out.rotation.normalize();
  return out;
}

}  // namespace inscribe
