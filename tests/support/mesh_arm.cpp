#include "support/mesh_arm.h"

#include <chrono>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/cover/sphere_cover.h"

namespace inscribe::testing {
namespace {

// The mesh centred on its bounding box, scaled so that its largest side is `side`, then moved
// up by `lift` along z (so that the link grows away from its joint).
Mesh Fitted(Mesh mesh, double side, double lift) {
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const Vector3 centre = 0.5 * (box.min + box.max);
  const double scale = side / box.extent().maxCoeff();
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const Vector3 v = (mesh.vertices.row(i).transpose() - centre) * scale + Vector3(0, 0, lift);
    mesh.vertices.row(i) = v.transpose();
  }
  return mesh;
}

robot::UrdfJoint Joint(int child, robot::UrdfJointType type, const Vector3& xyz,
                       const Vector3& axis, double lower, double upper) {
  robot::UrdfJoint joint;
  joint.name = absl::StrCat("joint", child);
  joint.type = type;
  joint.parent = absl::StrCat("link", child - 1);
  joint.child = absl::StrCat("link", child);
  joint.origin.xyz = xyz;
  joint.axis = axis;
  joint.lower = lower;
  joint.upper = upper;
  return joint;
}

}  // namespace

const std::vector<std::string>& MeshArmModels() {
  static const std::vector<std::string> models = {
      "fandisk.off", "cow.off", "elephant.off", "knot1.off", "cow.off", "eight.off", "eight.off"};
  return models;
}

absl::StatusOr<MeshArm> BuildMeshArm(std::vector<Mesh> meshes, MeshArmJoints joints) {
  if (meshes.size() != 7) return absl::InvalidArgumentError("the arm needs 7 meshes");
  // Per link: largest side and lift (metres); the joint to it sits at the top of its parent.
  const double side[7] = {0.2, 0.15, 0.25, 0.2, 0.15, 0.12, 0.1};
  const double lift[7] = {0.1, 0.07, 0.12, 0.1, 0.07, 0.06, 0.05};
  MeshArm arm;
  arm.robot.name = "mesh_arm";
  for (int i = 0; i < 7; ++i) {
    robot::UrdfLink link;
    link.name = absl::StrCat("link", i);
    arm.robot.links.push_back(link);
    absl::StatusOr<Solid> solid = PrepareSolid(Fitted(std::move(meshes[i]), side[i], lift[i]));
    if (!solid.ok()) return solid.status();
    arm.solids.push_back(*std::move(solid));
  }
  using robot::UrdfJointType;
  const Vector3 x = Vector3::UnitX(), y = Vector3::UnitY(), z = Vector3::UnitZ();
  auto& j = arm.robot.joints;
  if (joints == MeshArmJoints::kRevolute) {
    for (int child = 1; child < 7; ++child) {
      const bool about_z = child % 2 == 1;
      j.push_back(Joint(child, UrdfJointType::kRevolute, Vector3(0, 0, 2 * lift[child - 1] * 0.9),
                        about_z ? z : y, about_z ? -3.0 : -2.2, about_z ? 3.0 : 2.2));
    }
    return arm;
  }
  j.push_back(Joint(1, UrdfJointType::kContinuous, Vector3(0, 0, 0.18), z, 0, 0));
  j.push_back(Joint(2, UrdfJointType::kRevolute, Vector3(0, 0, 0.13), y, -2.2, 2.2));
  j.push_back(Joint(3, UrdfJointType::kRevolute, Vector3(0, 0, 0.22), y, -2.5, 2.5));
  j.push_back(Joint(4, UrdfJointType::kFixed, Vector3(0, 0, 0.18), z, 0, 0));
  j.back().origin.rpy = Vector3(0.3, 0, 0.5);
  j.push_back(Joint(5, UrdfJointType::kPrismatic, Vector3(0.03, 0, 0.12), x, -0.06, 0.0));
  j.push_back(Joint(6, UrdfJointType::kPrismatic, Vector3(-0.03, 0, 0.12), x, 0, 0.06));
  j.back().parent = "link4";
  j.back().mimic = robot::UrdfMimic{"joint5", -1.0, 0.0};
  return arm;
}

absl::StatusOr<MeshArmCovers> CoverMeshArm(const MeshArm& arm, std::int64_t max_spheres_per_link,
                                           double padding) {
  const auto start = std::chrono::steady_clock::now();
  MeshArmCovers covers;
  for (const Solid& solid : arm.solids) {
    CoverParameters parameters;
    parameters.max_spheres = max_spheres_per_link;
    parameters.growth_samples = 4'000;
    parameters.certify.resolution = 1.0 / 512;
    absl::StatusOr<GeneratedCover> cover = GenerateCover(solid, parameters);
    if (!cover.ok()) return cover.status();
    if (!cover->certificate.certified) return absl::InternalError("a cover is not certified");
    absl::StatusOr<std::vector<Sphere>> cores =
        CoverCores(cover->set.spheres, cover->certificate.protrusions);
    if (!cores.ok()) return cores.status();
    robot::LinkCollisionGeometry link;
    link.spheres = cover->set.spheres;
    for (Sphere& s : link.spheres) s.radius += padding;
    link.certified_delta = cover->certificate.delta + padding;
    link.inner = *std::move(cores);
    covers.links.push_back(std::move(link));
    covers.covers.push_back(cover->set.spheres);
  }
  covers.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return covers;
}

}  // namespace inscribe::testing
