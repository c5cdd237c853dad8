// One MJCF <geom>: its type, shape and pose in its body's frame. Private to the MJCF reader.
#pragma once

#include <map>
#include <string>

#include "absl/status/statusor.h"
#include "inscribe/robot/mjcf_robot.h"
#include "mjcf_attributes.h"

namespace inscribe::robot::mjcf {

// A <mesh> asset: where its file is and how it is scaled.
struct MeshAsset {
  std::string path;  // canonical
  Vector3 scale = Vector3::Ones();
};

// The geom `node` with attributes `a` (its own over its class's): name, type, group, contype,
// conaffinity and the element (shape from size or fromto as MuJoCo's half sizes, pose from pos
// and orientation or fromto, a mesh from `meshes`). body, class_name and solid are the caller's.
// INVALID_ARGUMENT as ParseMjcf says.
absl::StatusOr<MjcfGeom> ReadGeom(const Node& node, const Attributes& a,
                                  const AngleSettings& angles,
                                  const std::map<std::string, MeshAsset>& meshes);

}  // namespace inscribe::robot::mjcf
