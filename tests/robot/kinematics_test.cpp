// Kinematics (robot/include/inscribe/robot/kinematics.h): forward kinematics against 4x4
// matrices composed by hand (Rodrigues' formula, rpy written out) on random trees, every joint
// type, mimic chains, every error Create names, and the sampler's determinism.
#include "inscribe/robot/kinematics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace inscribe::robot {
namespace {

using ::testing::HasSubstr;

using Matrix4 = Eigen::Matrix4d;

// R = Rz(yaw) Ry(pitch) Rx(roll) written element by element.
Eigen::Matrix3d HandRpy(const Vector3& rpy) {
  const double cr = std::cos(rpy.x()), sr = std::sin(rpy.x()), cp = std::cos(rpy.y()),
               sp = std::sin(rpy.y()), cy = std::cos(rpy.z()), sy = std::sin(rpy.z());
  Eigen::Matrix3d r;
  r << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return r;
}

// Rodrigues: I + sin(a) K + (1 - cos(a)) K^2 for the unit axis k.
Eigen::Matrix3d Rodrigues(const Vector3& k, double angle) {
  Eigen::Matrix3d cross;
  cross << 0, -k.z(), k.y(), k.z(), 0, -k.x(), -k.y(), k.x(), 0;
  return Eigen::Matrix3d::Identity() + std::sin(angle) * cross +
         (1 - std::cos(angle)) * cross * cross;
}

Matrix4 Homogeneous(const Eigen::Matrix3d& r, const Vector3& t) {
  Matrix4 m = Matrix4::Identity();
  m.topLeftCorner<3, 3>() = r;
  m.topRightCorner<3, 1>() = t;
  return m;
}

// The child link's frame in the parent's for joint value `value`, from the joint as written.
Matrix4 HandJoint(const UrdfJoint& joint, double value) {
  const Matrix4 origin = Homogeneous(HandRpy(joint.origin.rpy), joint.origin.xyz);
  const Vector3 axis = joint.axis.normalized();
  switch (joint.type) {
    case UrdfJointType::kRevolute:
    case UrdfJointType::kContinuous:
      return origin * Homogeneous(Rodrigues(axis, value), Vector3::Zero());
    case UrdfJointType::kPrismatic:
      return origin * Homogeneous(Eigen::Matrix3d::Identity(), value * axis);
    default:
      return origin;
  }
}

UrdfJoint Joint(const std::string& name, UrdfJointType type, const std::string& parent,
                const std::string& child) {
  UrdfJoint joint;
  joint.name = name;
  joint.type = type;
  joint.parent = parent;
  joint.child = child;
  joint.lower = -1.0;
  joint.upper = 1.0;
  return joint;
}

UrdfRobot Links(int count) {
  UrdfRobot robot;
  for (int i = 0; i < count; ++i) {
    UrdfLink link;
    link.name = "l" + std::to_string(i);
    robot.links.push_back(link);
  }
  return robot;
}

double MaxDifference(const Eigen::Isometry3d& pose, const Matrix4& expected) {
  return (pose.matrix() - expected).cwiseAbs().maxCoeff();
}

TEST(Kinematics, PosesMatchHandComposedMatricesOnRandomTrees) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);  // test input only
  const UrdfJointType kTypes[] = {UrdfJointType::kFixed,      UrdfJointType::kRevolute,
                                  UrdfJointType::kContinuous, UrdfJointType::kPrismatic,
                                  UrdfJointType::kFloating,   UrdfJointType::kPlanar};
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 2 + static_cast<int>(random() % 12);
    UrdfRobot robot = Links(n);
    // Links in a shuffled order so that the root is not always link 0 and parents may come
    // after their children in the file.
    std::vector<int> order(n);
    for (int i = 0; i < n; ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), random);
    std::vector<int> parent(n, -1);
    for (int k = 1; k < n; ++k) {
      const int child = order[k], up = order[random() % k];
      parent[child] = up;
      UrdfJoint joint = Joint("j" + std::to_string(child), kTypes[random() % 6],
                              robot.links[up].name, robot.links[child].name);
      joint.origin.xyz = Vector3(unit(random), unit(random), unit(random));
      joint.origin.rpy = 3.0 * Vector3(unit(random), unit(random), unit(random));
      joint.axis = Vector3(unit(random), unit(random), unit(random)).normalized();
      robot.joints.push_back(joint);
    }
    std::shuffle(robot.joints.begin(), robot.joints.end(), random);
    const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
    ASSERT_TRUE(kinematics.ok()) << kinematics.status();
    ASSERT_EQ(kinematics->root(), order[0]);
    std::vector<double> q(kinematics->variables().size());
    for (double& value : q) value = 3.0 * unit(random);

    // The hand computation: climb from each link to the root, multiplying joint matrices.
    const absl::StatusOr<std::vector<Eigen::Isometry3d>> poses = kinematics->LinkPoses(q);
    ASSERT_TRUE(poses.ok()) << poses.status();
    for (int link = 0; link < n; ++link) {
      Matrix4 expected = Matrix4::Identity();
      for (int at = link; parent[at] >= 0; at = parent[at]) {
        const UrdfJoint* joint = nullptr;
        for (const UrdfJoint& j : robot.joints) {
          if (j.child == robot.links[at].name) joint = &j;
        }
        ASSERT_NE(joint, nullptr);
        const int variable = kinematics->variable(joint->name);
        expected = HandJoint(*joint, variable < 0 ? 0.0 : q[variable]) * expected;
        EXPECT_EQ(kinematics->parent(at), parent[at]);
      }
      EXPECT_LT(MaxDifference((*poses)[link], expected), 1e-12) << "trial " << trial;
    }
  }
}

TEST(Kinematics, EveryJointTypeMovesAsUrdfSays) {
  UrdfRobot robot = Links(7);
  robot.joints.push_back(Joint("rev", UrdfJointType::kRevolute, "l0", "l1"));
  robot.joints.back().axis = Vector3::UnitZ();
  robot.joints.back().origin.xyz = Vector3(1, 0, 0);
  robot.joints.push_back(Joint("pri", UrdfJointType::kPrismatic, "l1", "l2"));
  robot.joints.back().axis = Vector3::UnitX();
  robot.joints.push_back(Joint("con", UrdfJointType::kContinuous, "l2", "l3"));
  robot.joints.back().axis = Vector3::UnitY();
  robot.joints.push_back(Joint("fix", UrdfJointType::kFixed, "l3", "l4"));
  robot.joints.back().origin.xyz = Vector3(0, 0, 2);
  robot.joints.push_back(Joint("flo", UrdfJointType::kFloating, "l4", "l5"));
  robot.joints.push_back(Joint("pla", UrdfJointType::kPlanar, "l4", "l6"));
  const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status();
  ASSERT_EQ(kinematics->variables().size(), 3u);
  EXPECT_EQ(kinematics->variables()[0].joint, "rev");
  EXPECT_EQ(kinematics->variables()[1].type, UrdfJointType::kPrismatic);
  EXPECT_EQ(kinematics->variables()[2].lower, -M_PI);  // continuous: one turn
  EXPECT_EQ(kinematics->variables()[2].upper, M_PI);
  EXPECT_EQ(kinematics->variable("fix"), -1);
  EXPECT_EQ(kinematics->parent_joint(4), 3);
  EXPECT_EQ(kinematics->parent_joint(0), -1);
  EXPECT_EQ(kinematics->link_name(6), "l6");

  const absl::StatusOr<std::vector<Eigen::Isometry3d>> poses =
      kinematics->LinkPoses({M_PI / 2, 0.5, M_PI});
  ASSERT_TRUE(poses.ok()) << poses.status();
  // l1 at (1,0,0) turned a quarter about z; l2 then 0.5 along l1's x, which is world y.
  EXPECT_TRUE((*poses)[1].translation().isApprox(Vector3(1, 0, 0), 1e-15));
  EXPECT_TRUE(((*poses)[1].linear() * Vector3::UnitX()).isApprox(Vector3::UnitY(), 1e-15));
  EXPECT_TRUE((*poses)[2].translation().isApprox(Vector3(1, 0.5, 0), 1e-15));
  // l3 half a turn about its y (world x after the quarter turn): z flips; l4 2 up l3's z.
  EXPECT_TRUE((*poses)[4].translation().isApprox(Vector3(1, 0.5, -2), 1e-14));
  // Floating and planar joints stay at their origins.
  EXPECT_TRUE((*poses)[5].isApprox((*poses)[4], 1e-15));
  EXPECT_TRUE((*poses)[6].isApprox((*poses)[4], 1e-15));
}

TEST(Kinematics, MimicChainsResolveToTheVariableAtTheirEnd) {
  UrdfRobot robot = Links(4);
  robot.joints.push_back(Joint("a", UrdfJointType::kRevolute, "l0", "l1"));
  robot.joints.push_back(Joint("b", UrdfJointType::kPrismatic, "l0", "l2"));
  robot.joints.back().mimic = UrdfMimic{"c", -2.0, 0.25};  // b = -2 c + 0.25
  robot.joints.push_back(Joint("c", UrdfJointType::kRevolute, "l0", "l3"));
  robot.joints.back().mimic = UrdfMimic{"a", 3.0, -1.0};  // c = 3 a - 1
  robot.joints[1].axis = robot.joints[2].axis = Vector3::UnitZ();
  const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status();
  ASSERT_EQ(kinematics->variables().size(), 1u);
  const double a = 0.3, c = 3 * a - 1, b = -2 * c + 0.25;
  const absl::StatusOr<std::vector<Eigen::Isometry3d>> poses = kinematics->LinkPoses({a});
  ASSERT_TRUE(poses.ok());
  EXPECT_LT(MaxDifference((*poses)[1], HandJoint(robot.joints[0], a)), 1e-15);
  EXPECT_LT(MaxDifference((*poses)[2], HandJoint(robot.joints[1], b)), 1e-15);
  EXPECT_LT(MaxDifference((*poses)[3], HandJoint(robot.joints[2], c)), 1e-15);
}

TEST(Kinematics, ConfigurationsOfTheWrongSizeOrNotFiniteAreRefused) {
  UrdfRobot robot = Links(2);
  robot.joints.push_back(Joint("a", UrdfJointType::kRevolute, "l0", "l1"));
  const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  ASSERT_TRUE(kinematics.ok());
  EXPECT_THAT(kinematics->LinkPoses({}).status().message(),
              HasSubstr("configuration has 0 values; the robot has 1 variables"));
  EXPECT_THAT(kinematics->LinkPoses({NAN}).status().message(),
              HasSubstr("value 0 (joint 'a') is not finite"));
  UrdfRobot huge = robot;
  huge.links.push_back(UrdfLink{"l2", 0, {}, false});
  huge.joints.push_back(Joint("m", UrdfJointType::kRevolute, "l1", "l2"));
  huge.joints.back().mimic = UrdfMimic{"a", 1e308, 0};
  const absl::StatusOr<Kinematics> overflowing = Kinematics::Create(huge);
  ASSERT_TRUE(overflowing.ok());
  EXPECT_THAT(overflowing->LinkPoses({10.0}).status().message(),
              HasSubstr("the value of the joint of link 'l2' (1e+308 * 10 + 0) is not finite"));
  // Values outside the limits are used as given.
  EXPECT_TRUE(kinematics->LinkPoses({5.0}).ok());
}

std::string CreateError(const UrdfRobot& robot) {
  const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  EXPECT_FALSE(kinematics.ok());
  if (kinematics.ok()) return "";
  EXPECT_EQ(kinematics.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(kinematics.status().message());
}

TEST(Kinematics, CreateRefusesEveryBrokenTree) {
  EXPECT_THAT(CreateError(Links(0)), HasSubstr("no links"));
  EXPECT_THAT(CreateError(Links(2)), HasSubstr("2 root links"));
  const UrdfRobot base = [] {
    UrdfRobot robot = Links(3);
    robot.joints.push_back(Joint("a", UrdfJointType::kRevolute, "l0", "l1"));
    robot.joints.push_back(Joint("b", UrdfJointType::kRevolute, "l1", "l2"));
    robot.joints[1].line = 9;
    return robot;
  }();
  ASSERT_TRUE(Kinematics::Create(base).ok());
  const auto with = [&](auto edit) {
    UrdfRobot robot = base;
    edit(robot);
    return CreateError(robot);
  };
  EXPECT_THAT(with([](UrdfRobot& r) { r.links[1].name = "l0"; }), HasSubstr("'l0' is used twice"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].name = ""; }), HasSubstr("joint 1"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].name = "a"; }),
              HasSubstr("joint 'a' (URDF line 9): its name is used by an earlier joint"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].parent = "x"; }),
              HasSubstr("parent link 'x' does not exist"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].child = "x"; }),
              HasSubstr("child link 'x' does not exist"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].child = "l1"; }),
              HasSubstr("link 'l1' is already the child of joint 'a'"));
  EXPECT_THAT(
      with([](UrdfRobot& r) { r.joints.push_back(Joint("c", UrdfJointType::kFixed, "l2", "l0")); }),
      HasSubstr("closes a cycle"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.links.push_back(UrdfLink{"l3", 0, {}, false});
                r.joints.push_back(Joint("c", UrdfJointType::kFixed, "l3", "l3"));
              }),
              HasSubstr("joint 'c' (URDF line 0): it closes a cycle through link 'l3'"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].axis = Vector3::Zero(); }),
              HasSubstr("axis is zero"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].axis = Vector3(NAN, 0, 0); }),
              HasSubstr("axis is zero or not finite"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].origin.xyz.x() = INFINITY; }),
              HasSubstr("origin is not finite"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].lower = 2.0; }),
              HasSubstr("lower limit 2 > upper limit 1"));
  EXPECT_THAT(with([](UrdfRobot& r) { r.joints[1].upper = NAN; }),
              HasSubstr("limits are not finite"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.joints[1].mimic = UrdfMimic{"z", 1, 0};
              }),
              HasSubstr("joint 'b' (URDF line 9): mimics joint 'z', which does not exist"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.joints[1].mimic = UrdfMimic{"b", 1, 0};
              }),
              HasSubstr("mimics itself"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.joints[0].type = UrdfJointType::kFixed;
                r.joints[1].mimic = UrdfMimic{"a", 1, 0};
              }),
              HasSubstr("mimics joint 'a', a fixed joint without a value"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.joints[0].mimic = UrdfMimic{"b", 1, 0};
                r.joints[1].mimic = UrdfMimic{"a", 1, 0};
              }),
              HasSubstr("chain of mimics loops"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.joints[1].mimic = UrdfMimic{"a", NAN, 0};
              }),
              HasSubstr("multiplier or offset is not finite"));
  EXPECT_THAT(with([](UrdfRobot& r) {
                r.links.push_back(UrdfLink{"l3", 0, {}, false});
                r.joints.push_back(Joint("c", UrdfJointType::kRevolute, "l2", "l3"));
                r.joints[1].mimic = UrdfMimic{"a", 1e300, 0};
                r.joints[2].mimic = UrdfMimic{"b", 1e300, 0};
              }),
              HasSubstr("joint 'c' (URDF line 0): its chain of mimics overflows"));
  // Continuous joints do not use their limits; a mimic on a fixed joint is ignored.
  UrdfRobot lenient = base;
  lenient.joints[1].type = UrdfJointType::kContinuous;
  lenient.joints[1].lower = 3.0;
  lenient.joints[0].type = UrdfJointType::kFixed;
  lenient.joints[0].mimic = UrdfMimic{"nowhere", 1, 0};
  EXPECT_TRUE(Kinematics::Create(lenient).ok());
  // One link and no joints is a robot.
  const absl::StatusOr<Kinematics> single = Kinematics::Create(Links(1));
  ASSERT_TRUE(single.ok());
  EXPECT_EQ(single->links(), 1);
  EXPECT_TRUE(single->variables().empty());
}

TEST(SampleConfigurations, AreWithinLimitsAndTheSameForASeedOnEveryMachine) {
  UrdfRobot robot = Links(3);
  robot.joints.push_back(Joint("a", UrdfJointType::kRevolute, "l0", "l1"));
  robot.joints.back().lower = -0.5;
  robot.joints.back().upper = 2.0;
  robot.joints.push_back(Joint("b", UrdfJointType::kContinuous, "l1", "l2"));
  const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  ASSERT_TRUE(kinematics.ok());
  const auto samples = SampleConfigurations(*kinematics, 1000, 42);
  ASSERT_EQ(samples.size(), 1000u);
  for (const std::vector<double>& q : samples) {
    ASSERT_EQ(q.size(), 2u);
    EXPECT_GE(q[0], -0.5);
    EXPECT_LT(q[0], 2.0);
    EXPECT_GE(q[1], -M_PI);
    EXPECT_LT(q[1], M_PI);
  }
  EXPECT_EQ(SampleConfigurations(*kinematics, 1000, 42), samples);
  EXPECT_NE(SampleConfigurations(*kinematics, 1000, 43), samples);
  EXPECT_TRUE(SampleConfigurations(*kinematics, 0, 42).empty());
  EXPECT_TRUE(SampleConfigurations(*kinematics, -5, 42).empty());

  // The mapping from the generator is fixed: with one variable on [0, 1) and mt19937_64's
  // default seed, the 10,000th sample is the standard's 10,000th output, 9981545732273789042
  // ([rand.predef]), as (bits >> 11) * 2^-53.
  UrdfRobot unit = Links(2);
  unit.joints.push_back(Joint("u", UrdfJointType::kPrismatic, "l0", "l1"));
  unit.joints.back().lower = 0.0;
  const absl::StatusOr<Kinematics> one = Kinematics::Create(unit);
  ASSERT_TRUE(one.ok());
  const auto draws = SampleConfigurations(*one, 10000, 5489u);
  EXPECT_EQ(draws[9999][0], static_cast<double>(9981545732273789042ull >> 11) * 0x1.0p-53);
  // The sampler continues the same sequence.
  ConfigurationSampler sampler(*kinematics, 42);
  std::vector<double> q(2);
  for (int i = 0; i < 1000; ++i) {
    sampler.Next(absl::MakeSpan(q));
    ASSERT_EQ(q, samples[i]);
  }
}

TEST(DefaultConfiguration, IsZeroWithinTheLimitsElseTheirMiddle) {
  UrdfRobot robot = Links(4);
  robot.joints.push_back(Joint("a", UrdfJointType::kRevolute, "l0", "l1"));
  robot.joints.push_back(Joint("b", UrdfJointType::kPrismatic, "l1", "l2"));
  robot.joints.back().lower = 0.5;
  robot.joints.back().upper = 1.5;
  robot.joints.push_back(Joint("c", UrdfJointType::kContinuous, "l2", "l3"));
  const absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  ASSERT_TRUE(kinematics.ok());
  EXPECT_EQ(DefaultConfiguration(*kinematics), (std::vector<double>{0.0, 1.0, 0.0}));
}

}  // namespace
}  // namespace inscribe::robot
