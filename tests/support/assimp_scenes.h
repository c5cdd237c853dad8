// Scenes for assimp's exporter, made from inscribe meshes: an independent path for testing the
// COLLADA and glTF readers.
#pragma once

#include <assimp/scene.h>

#include <memory>
#include <vector>

#include "inscribe/geometry/mesh.h"

namespace inscribe::testing {

// A mesh placed by a node: the node's transform relative to its parent, and its parent (-1:
// the root) among the earlier placements.
struct Placement {
  int mesh;
  Eigen::Matrix4d transform;
  int parent = -1;
};

// A scene of `meshes` (triangles, one material) placed by one node per placement, so that a
// mesh placed twice is instanced.
std::unique_ptr<aiScene> MakeScene(const std::vector<Mesh>& meshes,
                                   const std::vector<Placement>& placements);

}  // namespace inscribe::testing
