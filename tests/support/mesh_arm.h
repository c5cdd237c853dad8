// A 7-link arm assembled from CGAL's demo meshes, for the self-collision tests and the
// robot_matrix benchmark: each link's mesh fitted to 0.1-0.25 m in its link frame, joints
// along the arm, and per link a certified cover (GenerateCover) with its cores.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/robot/self_collision.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/solid/solid.h"

namespace inscribe::testing {

// The demo meshes the arm's links are made of, link by link (7 names, data/<name>).
const std::vector<std::string>& MeshArmModels();

enum class MeshArmJoints {
  kRevolute,  // six revolute joints, alternately about z and y
  kMixed,     // continuous, revolute, revolute, fixed, prismatic, and a prismatic mimic of it
};

struct MeshArm {
  robot::UrdfRobot robot;     // links "link0".."link6" (no elements) and the joints
  std::vector<Solid> solids;  // per link, its mesh in its link frame, metres
};

// `meshes`: 7 closed meshes (any size and frame), link by link.
absl::StatusOr<MeshArm> BuildMeshArm(std::vector<Mesh> meshes, MeshArmJoints joints);

struct MeshArmCovers {
  std::vector<robot::LinkCollisionGeometry> links;  // spheres padded, certified delta, cores
  std::vector<std::vector<Sphere>> covers;          // the unpadded covers
  double seconds = 0.0;
};

// A certified cover of at most `max_spheres_per_link` spheres per link (coarse settings, for
// speed), its radii grown by `padding` (metres) and its delta by the same; the cores as inner
// spheres.
absl::StatusOr<MeshArmCovers> CoverMeshArm(const MeshArm& arm, std::int64_t max_spheres_per_link,
                                           double padding);

}  // namespace inscribe::testing
