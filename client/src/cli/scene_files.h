// The files of `inscribe scene`: the scene file (objects, ignored pairs, query; JSON) and the
// pose log (CSV `frame,id,qw,qx,qy,qz,tx,ty,tz`). Formats: docs/formats.md.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/container/flat_hash_set.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/scene/scene.h"

namespace inscribe::cli {

// One object as the scene file gives it; paths resolved against the scene file's folder.
struct SceneFileObject {
  // Id, pose, group and mask (core's defaults where the file leaves them out).
  SceneObject object;
  // A sphere file (.json, .sph, .csv, .yml) or, when empty, spheres generated from mesh_path
  // with `generate` (a voxel_size or max_spheres).
  std::string spheres_path;
  std::string mesh_path;
  SphereSetParameters generate;
  // Optional: a cover of the solid, making the object certified. Its file records the
  // certificate of its spheres (UsableCoverCertificate), or mesh_path names the mesh the
  // service certifies it against.
  std::string cover_path;
};

struct SceneFile {
  std::vector<SceneFileObject> objects;
  std::vector<std::pair<SceneObjectId, SceneObjectId>> ignored;
  SceneQuery query;  // threshold, abs_err, rel_err, max_pairs (core's defaults)
  HierarchyVolume volume = HierarchyVolume::kSphere;
};

// Parses a scene file's bytes; `path` starts every error message and its folder resolves
// relative paths. INVALID_ARGUMENT naming the line of a JSON syntax error, or the object
// (`objects[2] (id 7): ...`) or field otherwise: a wrong format tag, a missing or repeated
// id, neither spheres nor mesh, a pose not of 7 numbers or not near unit, a bad query,
// ignored pairs naming unknown objects.
absl::StatusOr<SceneFile> ParseSceneFile(absl::string_view bytes, const std::string& path);
// Reads `path` whole and parses it; NOT_FOUND when it cannot be opened.
absl::StatusOr<SceneFile> ReadSceneFile(const std::string& path);

// One frame of a pose log: the objects that moved and their new world poses.
struct PoseLogFrame {
  std::int64_t frame = 0;
  std::vector<std::pair<SceneObjectId, RigidPose>> poses;
};

// Parses a pose log: one line per moved object per frame, `frame,id,qw,qx,qy,qz,tx,ty,tz`,
// frames in nondecreasing order, an optional header line starting with `frame`, blank lines
// and `#` comments ignored. `ids` are the scene's objects. INVALID_ARGUMENT naming `name` and
// the line: a wrong field count, a field that is not a number, a frame number going back, an
// id not in the scene or repeated within a frame, a quaternion not within 1e-3 of unit length.
absl::StatusOr<std::vector<PoseLogFrame>> ParsePoseLog(
    absl::string_view bytes, const std::string& name,
    const absl::flat_hash_set<SceneObjectId>& ids);
// Reads `path` whole and parses it; NOT_FOUND when it cannot be opened.
absl::StatusOr<std::vector<PoseLogFrame>> ReadPoseLog(
    const std::string& path, const absl::flat_hash_set<SceneObjectId>& ids);

}  // namespace inscribe::cli
