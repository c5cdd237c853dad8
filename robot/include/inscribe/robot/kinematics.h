// A robot's kinematic tree and forward kinematics: where every link's frame is, in the root
// link's frame, for a joint configuration.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::robot {

// One coordinate of a configuration: an actuated joint that is not a mimic (revolute,
// continuous, prismatic). Floating and planar joints have no variable and stay at their
// origins.
struct JointVariable {
  std::string joint;          // its name
  UrdfJointType type = UrdfJointType::kRevolute;
  double lower = 0.0;         // radians or metres; continuous joints: -pi
  double upper = 0.0;         // continuous joints: pi
};

// The tree of a parsed URDF, immutable once made. Links keep UrdfRobot::links' order and
// indices.
class Kinematics {
 public:
  // INVALID_ARGUMENT naming the joint (and its line) for: a joint without a name or with a
  // name used before, a parent or child that is no link, a link that is the child of two
  // joints, a cycle, a robot with several root links (links no joint names as child), a zero
  // axis, lower > upper on a revolute or prismatic joint, a mimic of a joint that does not
  // exist, of itself, of a fixed/floating/planar joint, or a chain of mimics that loops.
  // A mimic of a mimic resolves to the variable at its end. A robot without joints has one
  // link as its root (several links and no joints: several roots, refused). O(#joints).
  static absl::StatusOr<Kinematics> Create(const UrdfRobot& robot);

  int links() const;                                   // number of links
  const std::string& link_name(int link) const;
  int root() const;                                    // the root link's index
  // The link's parent link (through its joint) and that joint's index in UrdfRobot::joints;
  // -1 for the root.
  int parent(int link) const;
  int parent_joint(int link) const;
  // The configuration's coordinates, in UrdfRobot::joints order.
  const std::vector<JointVariable>& variables() const;
  // Index of the named variable, or -1.
  int variable(const std::string& joint) const;

  // Every link's frame in the root link's frame at configuration q (one value per variable,
  // radians or metres; values outside the limits are used as given). INVALID_ARGUMENT for a
  // wrong size or a non-finite value. O(#links).
  absl::StatusOr<std::vector<Eigen::Isometry3d>> LinkPoses(const std::vector<double>& q) const;

  // Implementation detail, public for the factory.
  struct Tree;
  explicit Kinematics(std::shared_ptr<const Tree> tree);

 private:
  std::shared_ptr<const Tree> tree_;
};

// `count` configurations drawn uniformly within every variable's limits by a generator
// seeded with `seed`: the same seed gives the same configurations on every machine.
std::vector<std::vector<double>> SampleConfigurations(const Kinematics& kinematics,
                                                      std::int64_t count, std::uint64_t seed);

}  // namespace inscribe::robot
