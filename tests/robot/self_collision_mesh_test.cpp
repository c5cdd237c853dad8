// The self-collision matrix on an arm of CGAL demo meshes (support/mesh_arm.h: continuous,
// revolute, fixed, prismatic and mimic joints; certified covers with padding, cores inside):
// equal to a brute force (forward kinematics by hand, every sphere pair, at the same samples);
// sound against FCL (every "never" pair's solids apart at every sample, every interval holding
// the exact distance); independent of the thread count.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "inscribe/distance/certified_distance.h"
#include "inscribe/robot/self_collision.h"
#include "support/fcl_solid_distance.h"
#include "support/mesh_arm.h"
#include "support/test_meshes.h"

namespace inscribe::robot {
namespace {

constexpr double kPadding = 0.002;  // metres
constexpr std::int64_t kSamples = 1000;
constexpr std::uint64_t kSeed = 11;

struct Arm {
  testing::MeshArm arm;
  testing::MeshArmCovers covers;
  std::unique_ptr<Kinematics> kinematics;
  std::vector<testing::FclSolid> fcl;
  double largest = 0.0;  // the largest bounding-box side of any link, metres
};

class SelfCollisionMesh : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const std::string& model : testing::MeshArmModels()) {
      if (testing::TestMeshPath(model).empty()) return;  // the tests skip
    }
    std::vector<Mesh> meshes;
    for (const std::string& model : testing::MeshArmModels()) {
      SCOPED_TRACE(model);
      meshes.push_back(testing::LoadTestMesh(model));
    }
    auto arm = std::make_unique<Arm>();
    absl::StatusOr<testing::MeshArm> built =
        testing::BuildMeshArm(std::move(meshes), testing::MeshArmJoints::kMixed);
    ASSERT_TRUE(built.ok()) << built.status();
    arm->arm = *std::move(built);
    absl::StatusOr<testing::MeshArmCovers> covers = testing::CoverMeshArm(arm->arm, 8, kPadding);
    ASSERT_TRUE(covers.ok()) << covers.status();
    arm->covers = *std::move(covers);
    absl::StatusOr<Kinematics> kinematics = Kinematics::Create(arm->arm.robot);
    ASSERT_TRUE(kinematics.ok()) << kinematics.status();
    arm->kinematics = std::make_unique<Kinematics>(*std::move(kinematics));
    for (const Solid& solid : arm->arm.solids) {
      arm->fcl.push_back(testing::MakeFclSolid(solid));
      arm->largest =
          std::max(arm->largest, ComputeBoundingBox(solid.mesh().vertices).extent().maxCoeff());
    }
    arm_ = arm.release();
  }
  static void TearDownTestSuite() {
    delete arm_;
    arm_ = nullptr;
  }
  void SetUp() override {
    for (const std::string& model : testing::MeshArmModels()) INSCRIBE_REQUIRE_MESH(model);
    ASSERT_NE(arm_, nullptr);
  }

  static SelfCollisionMatrix Matrix(std::int64_t samples, std::uint64_t seed) {
    SelfCollisionOptions options;
    options.samples = samples;
    options.seed = seed;
    absl::StatusOr<SelfCollisionMatrix> matrix =
        ComputeSelfCollisionMatrix(*arm_->kinematics, arm_->covers.links, options);
    EXPECT_TRUE(matrix.ok()) << matrix.status();
    return matrix.ok() ? *std::move(matrix) : SelfCollisionMatrix{};
  }

  static Arm* arm_;
};

Arm* SelfCollisionMesh::arm_ = nullptr;

// Forward kinematics written out from the joints: a joint's value is its variable's (the
// actuated joints without mimic, in file order) or its mimic's multiplier * value + offset.
std::vector<Eigen::Isometry3d> HandPoses(const UrdfRobot& robot, const std::vector<double>& q) {
  std::map<std::string, double> value;
  std::size_t next = 0;
  for (const UrdfJoint& joint : robot.joints) {
    const bool moves = joint.type == UrdfJointType::kRevolute ||
                       joint.type == UrdfJointType::kContinuous ||
                       joint.type == UrdfJointType::kPrismatic;
    if (moves && !joint.mimic) value[joint.name] = q.at(next++);
  }
  for (const UrdfJoint& joint : robot.joints) {  // the arm's mimics name earlier joints
    if (joint.mimic) {
      value[joint.name] =
          joint.mimic->multiplier * value.at(joint.mimic->joint) + joint.mimic->offset;
    }
  }
  std::map<std::string, Eigen::Isometry3d> pose = {
      {robot.links[0].name, Eigen::Isometry3d::Identity()}};
  for (const UrdfJoint& joint : robot.joints) {  // the arm's joints come parents first
    Eigen::Isometry3d t = pose.at(joint.parent);
    t.translate(joint.origin.xyz);
    t.rotate(RotationFromRpy(joint.origin.rpy));
    const double v = value.count(joint.name) ? value.at(joint.name) : 0.0;
    if (joint.type == UrdfJointType::kPrismatic) {
      t.translate(v * joint.axis);
    } else if (joint.type != UrdfJointType::kFixed) {
      t.rotate(Eigen::AngleAxisd(v, joint.axis));
    }
    pose[joint.child] = t;
  }
  std::vector<Eigen::Isometry3d> poses;
  for (const UrdfLink& link : robot.links) poses.push_back(pose.at(link.name));
  return poses;
}

double AllPairs(const std::vector<Sphere>& a, const Eigen::Isometry3d& pa,
                const std::vector<Sphere>& b, const Eigen::Isometry3d& pb) {
  double best = INFINITY;
  for (const Sphere& s : a) {
    for (const Sphere& t : b) {
      best = std::min(best, ((pa * s.center) - (pb * t.center)).norm() - s.radius - t.radius);
    }
  }
  return best;
}

double Reach(const LinkCollisionGeometry& g) {
  double reach = 0.0;
  for (const auto* set : {&g.spheres, &g.inner}) {
    for (const Sphere& s : *set) reach = std::max(reach, s.center.norm() + s.radius);
  }
  return reach;
}

// lower, upper as self_collision.h defines them, from every sphere pair.
std::pair<double, double> BruteInterval(const LinkCollisionGeometry& a, const Eigen::Isometry3d& pa,
                                        const LinkCollisionGeometry& b,
                                        const Eigen::Isometry3d& pb) {
  const double scale =
      std::max(pa.translation().norm() + Reach(a), pb.translation().norm() + Reach(b));
  const double margin = kCertifiedDistanceMargin * scale + kCertifiedDistanceFloor;
  const double d = AllPairs(a.spheres, pa, b.spheres, pb);
  const double lower = std::max(0.0, d - margin);
  const double upper = std::min(AllPairs(a.inner, pa, b.inner, pb),
                                std::max(0.0, d) + *a.certified_delta + *b.certified_delta);
  return {lower, std::max(lower, std::max(0.0, upper) + margin)};
}

RigidPose ToRigid(const Eigen::Isometry3d& pose) {
  return RigidPose{Eigen::Quaterniond(pose.linear()), pose.translation()};
}

TEST_F(SelfCollisionMesh, MatrixEqualsABruteForceOverEverySpherePair) {
  const SelfCollisionMatrix matrix = Matrix(kSamples, kSeed);
  EXPECT_TRUE(matrix.certified);
  const std::vector<LinkCollisionGeometry>& g = arm_->covers.links;
  const UrdfRobot& robot = arm_->arm.robot;
  ASSERT_EQ(matrix.pairs.size(), 21u);  // 7 links, all with spheres

  struct Brute {
    std::int64_t colliding = 0;
    double min_lower = INFINITY, min_upper = INFINITY, min_sphere_distance = INFINITY;
    bool at_default = false;
  };
  std::map<std::pair<int, int>, Brute> brute;
  const auto visit = [&](const std::vector<double>& q, bool is_default) {
    const std::vector<Eigen::Isometry3d> poses = HandPoses(robot, q);
    for (int a = 0; a < 7; ++a) {
      for (int b = a + 1; b < 7; ++b) {
        const auto [lower, upper] = BruteInterval(g[a], poses[a], g[b], poses[b]);
        Brute& r = brute[{a, b}];
        if (is_default) {
          r.at_default = !(lower > 0.0);
          continue;
        }
        r.colliding += lower > 0.0 ? 0 : 1;
        r.min_lower = std::min(r.min_lower, lower);
        r.min_upper = std::min(r.min_upper, upper);
        r.min_sphere_distance = std::min(r.min_sphere_distance,
                                         AllPairs(g[a].spheres, poses[a], g[b].spheres, poses[b]));
      }
    }
  };
  // MoveIt's default state by hand: every joint's limits hold 0 here.
  visit(std::vector<double>(arm_->kinematics->variables().size(), 0.0), true);
  for (const std::vector<double>& q : SampleConfigurations(*arm_->kinematics, kSamples, kSeed)) {
    visit(q, false);
  }
  int never = 0, disabled = 0;
  for (const LinkPairCollision& pair : matrix.pairs) {
    const Brute& r = brute.at({pair.link_a, pair.link_b});
    const std::string name = matrix.links[pair.link_a] + "-" + matrix.links[pair.link_b];
    EXPECT_EQ(pair.colliding_samples, r.colliding) << name;
    EXPECT_EQ(pair.colliding_at_default, r.at_default) << name;
    EXPECT_NEAR(pair.min_lower, r.min_lower, 1e-12) << name;
    EXPECT_NEAR(pair.min_upper, r.min_upper, 1e-12) << name;
    EXPECT_NEAR(pair.min_sphere_distance, r.min_sphere_distance, 1e-12) << name;
    // Adjacent by hand: parent and child (link6 hangs from link4, beside link5).
    const bool adjacent = pair.link_b == pair.link_a + 1 && pair.link_b != 6;
    CollisionPairClass expected = CollisionPairClass::kSometimes;
    if (adjacent || (pair.link_a == 4 && pair.link_b == 6)) {
      expected = CollisionPairClass::kAdjacent;
    } else if (r.at_default) {
      expected = CollisionPairClass::kDefault;
    } else if (r.colliding >= 0.95 * kSamples) {
      expected = CollisionPairClass::kAlways;
    } else if (r.colliding == 0) {
      expected = CollisionPairClass::kNever;
    }
    EXPECT_EQ(pair.type, expected) << name;
    never += pair.type == CollisionPairClass::kNever;
    disabled += CollisionDisabled(pair.type);
  }
  // The arm folds onto itself: some pairs are sometimes in collision, others never.
  EXPECT_GT(never, 0);
  EXPECT_LT(disabled, 21);
}

TEST_F(SelfCollisionMesh, NeverPairsAreApartInFclAtEverySample) {
  const SelfCollisionMatrix matrix = Matrix(kSamples, kSeed);
  const auto samples = SampleConfigurations(*arm_->kinematics, kSamples, kSeed);
  int checked = 0;
  for (const std::vector<double>& q : samples) {
    const auto poses = arm_->kinematics->LinkPoses(q);
    ASSERT_TRUE(poses.ok());
    for (const LinkPairCollision& pair : matrix.pairs) {
      if (pair.type != CollisionPairClass::kNever) continue;
      const testing::ExactSolidDistance exact =
          testing::SolidDistance(arm_->fcl[pair.link_a], ToRigid((*poses)[pair.link_a]),
                                 arm_->fcl[pair.link_b], ToRigid((*poses)[pair.link_b]));
      ASSERT_EQ(exact.contact, testing::SolidContact::kApart)
          << matrix.links[pair.link_a] << "-" << matrix.links[pair.link_b];
      ASSERT_GT(exact.distance, 0.0);
      ASSERT_GE(exact.distance, pair.min_lower - 1e-9 * arm_->largest);
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST_F(SelfCollisionMesh, IntervalsHoldFclsExactDistance) {
  const auto samples = SampleConfigurations(*arm_->kinematics, 300, kSeed + 1);
  const double slack = 1e-9 * arm_->largest;  // FCL's own rounding
  int apart = 0, touching = 0;
  for (const std::vector<double>& q : samples) {
    const auto intervals = LinkPairIntervals(*arm_->kinematics, arm_->covers.links, q);
    ASSERT_TRUE(intervals.ok()) << intervals.status();
    const auto poses = arm_->kinematics->LinkPoses(q);
    ASSERT_TRUE(poses.ok());
    for (const LinkPairInterval& interval : *intervals) {
      const testing::ExactSolidDistance exact =
          testing::SolidDistance(arm_->fcl[interval.link_a], ToRigid((*poses)[interval.link_a]),
                                 arm_->fcl[interval.link_b], ToRigid((*poses)[interval.link_b]));
      ASSERT_LE(interval.lower, exact.distance + slack);
      ASSERT_GE(interval.upper, exact.distance - slack);
      ASSERT_LE(interval.lower, interval.upper);
      (exact.distance > 0.0 ? apart : touching) += 1;
    }
  }
  EXPECT_GT(apart, 0);
  EXPECT_GT(touching, 0);
}

TEST_F(SelfCollisionMesh, MatrixIsTheSameOnOneThreadAndOnMany) {
  SelfCollisionMatrix one, many;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = Matrix(5000, 3);
  }
  many = Matrix(5000, 3);
  ASSERT_EQ(one.pairs.size(), many.pairs.size());
  for (std::size_t i = 0; i < one.pairs.size(); ++i) {
    const LinkPairCollision& a = one.pairs[i];
    const LinkPairCollision& b = many.pairs[i];
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.colliding_samples, b.colliding_samples);
    EXPECT_EQ(a.colliding_at_default, b.colliding_at_default);
    EXPECT_EQ(a.min_lower, b.min_lower);
    EXPECT_EQ(a.min_upper, b.min_upper);
    EXPECT_EQ(a.min_sphere_distance, b.min_sphere_distance);
  }
  // Another seed sees other configurations.
  const SelfCollisionMatrix other = Matrix(5000, 4);
  bool differs = false;
  for (std::size_t i = 0; i < one.pairs.size(); ++i) {
    differs = differs || one.pairs[i].min_upper != other.pairs[i].min_upper;
  }
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace inscribe::robot
