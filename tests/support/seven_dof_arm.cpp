#include "support/seven_dof_arm.h"

#include <cmath>

#include "absl/strings/str_cat.h"
#include "inscribe/robot/primitive_meshes.h"

namespace inscribe::testing {

SevenDofArm BuildSevenDofArm() {
  SevenDofArm arm;
  arm.robot.name = "seven_dof_arm";
  const double lengths[8] = {0.2, 0.12, 0.25, 0.12, 0.25, 0.12, 0.1, 0.08};
  const double radii[8] = {0.08, 0.07, 0.065, 0.06, 0.055, 0.05, 0.045, 0.04};
  const int counts[8] = {6, 8, 8, 8, 8, 8, 7, 7};
  const double limits[7] = {2.9, 1.76, 2.9, 3.0, 2.9, 3.7, 2.9};
  for (int i = 0; i < 8; ++i) {
    robot::UrdfLink link;
    link.name = i == 0 ? "base" : absl::StrCat("link", i);
    arm.robot.links.push_back(link);
    arm.radius.push_back(radii[i]);
    arm.length.push_back(lengths[i]);
    LinkSpheres spheres{link.name, {}};
    // n spheres spaced s apart from z = 0 to z = L: radius sqrt(R^2 + (s/2)^2) covers the
    // cylinder between neighbours; the end ones at the ends, radius >= R, cover the caps.
    const int n = counts[i];
    const double s = lengths[i] / (n - 1);
    const double r = std::sqrt(radii[i] * radii[i] + 0.25 * s * s);
    for (int k = 0; k < n; ++k) spheres.spheres.push_back({Vector3(0, 0, k * s), r});
    arm.spheres.links.push_back(spheres);
  }
  for (int j = 1; j <= 7; ++j) {
    robot::UrdfJoint joint;
    joint.name = absl::StrCat("joint", j);
    joint.type = robot::UrdfJointType::kRevolute;
    joint.parent = arm.robot.links[j - 1].name;
    joint.child = arm.robot.links[j].name;
    joint.origin.xyz = Vector3(0, 0, lengths[j - 1]);
    joint.axis = j % 2 == 1 ? Vector3::UnitZ() : Vector3::UnitY();
    joint.lower = -limits[j - 1];
    joint.upper = limits[j - 1];
    arm.robot.joints.push_back(joint);
    arm.spheres.self_collision_ignore[{arm.robot.links[j - 1].name, arm.robot.links[j].name}] =
        "Adjacent";
  }
  // MoveIt's "Default" pairs: links whose spheres overlap with every joint at 0 (the arm
  // straight up along z, link i's frame at the sum of the lengths below it).
  std::vector<double> height(8, 0.0);
  for (int i = 1; i < 8; ++i) height[i] = height[i - 1] + lengths[i - 1];
  for (int a = 0; a < 8; ++a) {
    for (int b = a + 2; b < 8; ++b) {
      bool overlap = false;
      for (const Sphere& sa : arm.spheres.links[a].spheres) {
        for (const Sphere& sb : arm.spheres.links[b].spheres) {
          const double gap = std::abs((sb.center.z() + height[b]) - (sa.center.z() + height[a]));
          overlap = overlap || gap <= sa.radius + sb.radius;
        }
      }
      if (overlap) {
        arm.spheres.self_collision_ignore[{arm.robot.links[a].name, arm.robot.links[b].name}] =
            "Default";
      }
    }
  }
  return arm;
}

std::vector<Mesh> SevenDofArmMeshes(const SevenDofArm& arm) {
  std::vector<Mesh> meshes;
  for (std::size_t i = 0; i < arm.radius.size(); ++i) {
    Mesh mesh = robot::CapsuleMesh(arm.radius[i], arm.length[i], 24, 6);
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
      mesh.vertices(v, 2) += 0.5 * arm.length[i];
    }
    meshes.push_back(std::move(mesh));
  }
  return meshes;
}

}  // namespace inscribe::testing
