// A 7-DOF arm built in code, for the robot-state tests and bench/robot_world: a base and seven
// links joined by revolute joints about z, y, z, y, z, y, z, each link a capsule along its z
// from its frame's origin to the next joint, and a sphere model of 60 spheres (6 on the base,
// 8, 8, 8, 8, 8, 7, 7 on the links) that covers the capsules: spheres on each capsule's axis,
// radius grown so that consecutive ones cover the cylinder between them and the end caps.
#pragma once

#include <vector>

#include "inscribe/geometry/mesh.h"
#include "inscribe/robot/robot_spheres.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::testing {

struct SevenDofArm {
  robot::UrdfRobot robot;  // links "base", "link1".."link7"; joints "joint1".."joint7"
  // Per link (robot order), its capsule: radius, and length along +z from the link origin.
  std::vector<double> radius, length;
  // The sphere model: in self_collision_ignore the adjacent links ("Adjacent") and the links
  // whose spheres overlap with every joint at 0 ("Default"); no buffers.
  robot::RobotSpheres spheres;
};

SevenDofArm BuildSevenDofArm();

// Per link, its capsule as a closed mesh (robot::CapsuleMesh, kInside: inside the capsule, so
// inside the spheres) in the link frame.
std::vector<Mesh> SevenDofArmMeshes(const SevenDofArm& arm);

}  // namespace inscribe::testing
