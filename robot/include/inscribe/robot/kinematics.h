// A robot's kinematic tree and forward kinematics: where every link's frame is, in the root
// link's frame, for a joint configuration.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::robot {

// One coordinate of a configuration: an actuated joint that is not a mimic (revolute,
// continuous, prismatic). Floating and planar joints have no variable and stay at their
// origins.
struct JointVariable {
  std::string joint;  // its name
  UrdfJointType type = UrdfJointType::kRevolute;
  double lower = 0.0;  // radians or metres; continuous joints: -pi
  double upper = 0.0;  // continuous joints: pi
};

// The tree of a parsed URDF, immutable once made. Links keep UrdfRobot::links' order and
// indices.
class Kinematics {
 public:
  // INVALID_ARGUMENT naming the joint (and its line) for: a joint without a name or with a
  // name used before, a parent or child that is no link, a link that is the child of two
  // joints, a cycle, a robot with several root links (links no joint names as child), a zero
  // or non-finite axis (except fixed and floating joints), a non-finite origin, non-finite
  // limits or lower > upper on a revolute or prismatic joint, a mimic of a joint that does not
  // exist, of itself, of a fixed/floating/planar joint, a non-finite multiplier or offset, or
  // a chain of mimics that loops; and for a robot without links, a link without a name or
  // with a name used before. A mimic of a mimic resolves to the variable at its end; a
  // <mimic> on a fixed, floating or planar joint is ignored (the joint has no value). A robot
  // without joints has one link as its root (several links and no joints: several roots,
  // refused). O(#joints log #joints).
  static absl::StatusOr<Kinematics> Create(const UrdfRobot& robot);

  int links() const;  // number of links
  const std::string& link_name(int link) const;
  int root() const;  // the root link's index
  // The link's parent link (through its joint) and that joint's index in UrdfRobot::joints;
  // -1 for the root.
  int parent(int link) const;
  int parent_joint(int link) const;
  // How the joint into `link` moves: its value is multiplier * q[variable] + offset, a mimic's
  // chain resolved to the variable at its end. variable -1 (value 0) for the root and for
  // fixed, floating and planar joints. The one place mimics are resolved.
  struct JointDrive {
    int variable = -1;
    double multiplier = 1.0;
    double offset = 0.0;
  };
  JointDrive drive(int link) const;
  // The configuration's coordinates, in UrdfRobot::joints order.
  const std::vector<JointVariable>& variables() const;
  // Index of the named variable, or -1.
  int variable(const std::string& joint) const;

  // Every link's frame in the root link's frame at configuration q (one value per variable,
  // radians or metres; values outside the limits are used as given). INVALID_ARGUMENT for a
  // wrong size, a non-finite value, or a mimic's value that overflows. O(#links).
  absl::StatusOr<std::vector<Eigen::Isometry3d>> LinkPoses(const std::vector<double>& q) const;
  // The same into *poses (resized to links()), without allocating once it has the size: for
  // loops over many configurations.
  absl::Status LinkPoses(absl::Span<const double> q, std::vector<Eigen::Isometry3d>* poses) const;

  // Implementation detail, public for the factory.
  struct Tree;
  explicit Kinematics(std::shared_ptr<const Tree> tree);

 private:
  std::shared_ptr<const Tree> tree_;
};

// Configurations drawn uniformly within every variable's limits, [lower, upper): std::mt19937_64
// seeded with `seed`, one draw per variable in order, mapped as
// lower + (draw >> 11) * 2^-53 * (upper - lower). The same seed gives the same sequence on every
// machine (std::uniform_real_distribution is not used: its output is implementation-defined).
// Holds no reference to `kinematics` after construction.
class ConfigurationSampler {
 public:
  ConfigurationSampler(const Kinematics& kinematics, std::uint64_t seed);
  // The next configuration into q (one value per variable).
  void Next(absl::Span<double> q);
  int variables() const { return static_cast<int>(lower_.size()); }

 private:
  std::mt19937_64 generator_;
  std::vector<double> lower_, width_;
};

// The first `count` configurations of ConfigurationSampler(kinematics, seed) (none when
// count <= 0). O(count * #variables) time and memory.
std::vector<std::vector<double>> SampleConfigurations(const Kinematics& kinematics,
                                                      std::int64_t count, std::uint64_t seed);

// MoveIt's default state (RobotState::setToDefaultValues): per variable 0 when 0 is within its
// limits, else the middle of the limits.
std::vector<double> DefaultConfiguration(const Kinematics& kinematics);

}  // namespace inscribe::robot
