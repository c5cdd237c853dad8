// Reading and writing mesh files (OFF, OBJ, STL, PLY) through CGAL's IO; reading COLLADA and
// glTF scenes through assimp.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe {

struct ReadMeshInfo {
  std::int64_t polygons = 0;               // faces in the file (an instanced mesh's once)
  std::int64_t polygons_triangulated = 0;  // faces with more than 3 corners, split into triangles
};

// Reads `path`, choosing the format by its extension (case-insensitive): .off, .obj, .stl,
// .ply through CGAL (faces with more than three corners triangulated by CGAL's hole filling,
// so non-convex polygons are fine), or .dae (COLLADA), .gltf and .glb (glTF 2) through assimp.
// A scene gives one mesh of every triangle of every node's meshes, each placed by the node's
// transform composed from the root (an instanced mesh appears once per node), polygons
// triangulated, points and lines left out. Its frame and units: the file's own axes (a
// COLLADA <up_axis> is not applied, as ROS's loaders do not; glTF is Y-up by its
// specification and left so), in metres (COLLADA's <unit meter="..."> is applied; glTF is
// metres by its specification). assimp holds coordinates as floats: about 7 significant
// digits. Vertices are as the file gives them, often one per face corner: validation welds
// them. No geometric validation happens here: see ValidateMesh.
// Errors (all INVALID_ARGUMENT or NOT_FOUND, with the path in the message): missing or
// unreadable file, empty file, unsupported extension, a file CGAL or assimp cannot parse
// (assimp's message quoted), a scene without triangles, a face with fewer than three corners,
// a face index out of range, a non-finite coordinate.
absl::StatusOr<Mesh> ReadMesh(const std::string& path, ReadMeshInfo* info = nullptr);

// The same, from bytes already in memory; `format` is "off", "obj", "stl", "ply", "dae",
// "gltf" or "glb". A .gltf whose buffers are separate files cannot be read from bytes
// (INVALID_ARGUMENT saying so): send a .glb or embed the buffers.
absl::StatusOr<Mesh> ParseMesh(const std::string& bytes, const std::string& format,
                               ReadMeshInfo* info = nullptr);

// Writes `mesh` to `path` as text, the format chosen by the extension (.off, .obj, .ply, .stl;
// case-insensitive), through CGAL's writers with 17 significant digits, so ReadMesh gives back
// the same doubles. The file is replaced atomically (a temporary sibling, then rename).
// Errors: INVALID_ARGUMENT for another extension or a mesh with out-of-range indices or
// non-finite coordinates; NOT_FOUND, PERMISSION_DENIED or INTERNAL from the file system.
absl::Status WriteMesh(const std::string& path, const Mesh& mesh);

}  // namespace inscribe
