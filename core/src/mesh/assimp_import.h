// Private: meshes from scene formats (COLLADA, glTF) through assimp, for ReadMesh and ParseMesh.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/mesh/mesh_io.h"

namespace inscribe::internal {

// True for the lowercase extensions read here: "dae", "gltf", "glb".
bool IsSceneFormat(const std::string& format);

// Every triangle of every mesh instance in the scene, in one mesh: each node's meshes with the
// node's transform composed from the root (so a mesh placed by several nodes appears once per
// node), polygons triangulated, points and lines left out, vertices as stored (not welded).
// Frame and units: the file's own coordinates (no up-axis conversion: a COLLADA <up_axis>
// other than Y_UP is not rotated, as ROS's loaders do), in metres: COLLADA's
// <unit meter="..."> is applied; glTF is metres by its specification. assimp stores
// coordinates as floats, so about 7 significant digits survive. `what` names the source in
// errors (INVALID_ARGUMENT): what assimp could not read (with its message), a scene with no
// triangles, a non-finite coordinate, more vertices than int32 indices reach.
absl::StatusOr<Mesh> ImportSceneFile(const std::string& path, ReadMeshInfo* info);
// The same from bytes; a .gltf whose buffers are separate files cannot be read from bytes.
absl::StatusOr<Mesh> ImportSceneBytes(const std::string& bytes, const std::string& format,
                                      const std::string& what, ReadMeshInfo* info);

}  // namespace inscribe::internal
