// Reading and writing mesh files (OFF, OBJ, STL, PLY) through CGAL's IO.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/mesh.h"

namespace inscribe {

struct ReadMeshInfo {
  std::int64_t polygons = 0;               // faces in the file
  std::int64_t polygons_triangulated = 0;  // faces with more than 3 corners, split into triangles
};

// Reads `path`, choosing the format by its extension (.off, .obj, .stl, .ply; case-insensitive).
// Faces with more than three corners are triangulated (CGAL hole filling, so non-convex
// polygons are fine). No geometric validation happens here: see ValidateMesh.
// Errors (all INVALID_ARGUMENT or NOT_FOUND, with the path in the message): missing or
// unreadable file, empty file, unsupported extension, a file CGAL cannot parse, a face with
// fewer than three corners, a face index out of range, a non-finite coordinate.
absl::StatusOr<Mesh> ReadMesh(const std::string& path, ReadMeshInfo* info = nullptr);

// The same, from bytes already in memory; `format` is "off", "obj", "stl" or "ply".
absl::StatusOr<Mesh> ParseMesh(const std::string& bytes, const std::string& format,
                               ReadMeshInfo* info = nullptr);

// Writes `mesh` to `path` as text, the format chosen by the extension (.off, .obj, .ply, .stl;
// case-insensitive), through CGAL's writers with 17 significant digits, so ReadMesh gives back
// the same doubles. The file is replaced atomically (a temporary sibling, then rename).
// Errors: INVALID_ARGUMENT for another extension or a mesh with out-of-range indices or
// non-finite coordinates; NOT_FOUND, PERMISSION_DENIED or INTERNAL from the file system.
absl::Status WriteMesh(const std::string& path, const Mesh& mesh);

}  // namespace inscribe
