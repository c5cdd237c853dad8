#include "inscribe/geometry/rigid_pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace inscribe {
namespace {

// Normalising is idempotent to the bit (a service normalising what a client already did gets
// the client's pose), and the result is unit to rounding.
TEST(NormalizedPose, TwiceIsOnceToTheBit) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> off(-1e-4, 1e-4);
  for (int trial = 0; trial < 100000; ++trial) {
    RigidPose pose;
    pose.rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng));
    pose.rotation.normalize();
    pose.rotation.coeffs() *= 1.0 + off(rng);
    pose.translation = Vector3(normal(rng), normal(rng), normal(rng));
    absl::StatusOr<RigidPose> once = NormalizedPose(pose);
    ASSERT_TRUE(once.ok());
    absl::StatusOr<RigidPose> twice = NormalizedPose(*once);
    ASSERT_TRUE(twice.ok());
    ASSERT_EQ(once->rotation.coeffs(), twice->rotation.coeffs()) << "trial " << trial;
    ASSERT_EQ(once->translation, pose.translation);
    ASSERT_NEAR(once->rotation.norm(), 1.0, 1e-15);
    ASSERT_TRUE(CheckPose(*once).ok());
  }
}

TEST(NormalizedPose, RefusesTyposAndNonFiniteNumbers) {
  RigidPose pose;
  pose.rotation = Eigen::Quaterniond(1.01, 0, 0, 0);
  absl::StatusOr<RigidPose> r = NormalizedPose(pose);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("unit quaternion"), std::string::npos) << r.status();
  pose.rotation = Eigen::Quaterniond(1, 0, 0, 0);
  pose.translation.z() = std::nan("");
  EXPECT_FALSE(NormalizedPose(pose).ok());
  EXPECT_FALSE(CheckPose(pose).ok());
}

}  // namespace
}  // namespace inscribe
