#include "scene_files.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "nlohmann/json.hpp"
#include "pose_file.h"

namespace inscribe::cli {
namespace {

using nlohmann::json;

constexpr int kPoseNumbers = 7;

// The whole of a file, or NOT_FOUND naming it and what it was for.
absl::StatusOr<std::string> ReadWhole(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::in | std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open the ", what));
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::InvalidArgumentError(absl::StrCat(path, ": read error"));
  return contents.str();
}

// 1-based line of byte offset `byte` in `bytes`.
std::size_t LineOf(absl::string_view bytes, std::size_t byte) {
  const absl::string_view before = bytes.substr(0, std::min(byte, bytes.size()));
  return 1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
}

// A pose from 7 numbers qw qx qy qz tx ty tz, kept as written when its quaternion is within
// 1e-3 of unit length (the service normalises it once); the check's error otherwise.
absl::StatusOr<RigidPose> PoseOf(const double (&v)[kPoseNumbers]) {
  RigidPose pose{Eigen::Quaterniond(v[0], v[1], v[2], v[3]), Vector3(v[4], v[5], v[6])};
  if (absl::Status usable = NormalizedPose(pose).status(); !usable.ok()) return usable;
  return pose;
}

// The value of `key` in `object` as T, or INVALID_ARGUMENT "<where>: <key> must be <what>".
template <typename T>
absl::StatusOr<T> Field(const json& object, const char* key, const std::string& where,
                        const char* what) {
  const json& value = object.at(key);
  bool ok = false;
  if constexpr (std::is_same_v<T, std::string>) {
    ok = value.is_string();
  } else if constexpr (std::is_unsigned_v<T>) {
    ok = value.is_number_unsigned() &&
         value.template get<std::uint64_t>() <= std::numeric_limits<T>::max();
  } else if constexpr (std::is_integral_v<T>) {
    ok = value.is_number_integer();
  } else {
    ok = value.is_number();
  }
  if (!ok) return absl::InvalidArgumentError(absl::StrCat(where, ": ", key, " must be ", what));
  return value.template get<T>();
}

absl::StatusOr<RigidPose> PoseField(const json& object, const std::string& where) {
  const json& value = object.at("pose");
  if (!value.is_array() || value.size() != kPoseNumbers) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, ": pose must be 7 numbers [qw, qx, qy, qz, tx, ty, tz]"));
  }
  double v[kPoseNumbers];
  for (int k = 0; k < kPoseNumbers; ++k) {
    if (!value[static_cast<std::size_t>(k)].is_number()) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ": pose must be 7 numbers [qw, qx, qy, qz, tx, ty, tz]"));
    }
    v[k] = value[static_cast<std::size_t>(k)].get<double>();
  }
  absl::StatusOr<RigidPose> pose = PoseOf(v);
  if (!pose.ok())
    return absl::InvalidArgumentError(absl::StrCat(where, ": pose: ", pose.status().message()));
  return pose;
}

// `relative` against the scene file's folder (absolute paths as they are).
std::string Resolve(const std::string& scene_path, const std::string& relative) {
  const std::filesystem::path p(relative);
  if (p.is_absolute()) return relative;
  return (std::filesystem::path(scene_path).parent_path() / p).lexically_normal().string();
}

absl::StatusOr<SceneFileObject> ParseObject(const json& j, std::size_t index,
                                            const std::string& path) {
  std::string where = absl::StrCat(path, ": objects[", index, "]");
  if (!j.is_object()) return absl::InvalidArgumentError(absl::StrCat(where, " must be an object"));
  for (const auto& [key, value] : j.items()) {
    if (key != "id" && key != "spheres" && key != "mesh" && key != "voxel_size" &&
        key != "max_spheres" && key != "cover" && key != "pose" && key != "group" &&
        key != "mask") {
      return absl::InvalidArgumentError(absl::StrCat(where, ": unknown field \"", key, "\""));
    }
  }
  SceneFileObject out;
  if (!j.contains("id")) return absl::InvalidArgumentError(absl::StrCat(where, ": no id"));
  absl::StatusOr<std::uint64_t> id =
      Field<std::uint64_t>(j, "id", where, "an integer from 0 to 2^64-1");
  if (!id.ok()) return id.status();
  out.object.id = *id;
  where = absl::StrCat(where, " (id ", *id, ")");
  for (const char* key : {"spheres", "mesh", "cover"}) {
    if (!j.contains(key)) continue;
    absl::StatusOr<std::string> value = Field<std::string>(j, key, where, "a path");
    if (!value.ok()) return value.status();
    std::string& field = key[0] == 's'   ? out.spheres_path
                         : key[0] == 'm' ? out.mesh_path
                                         : out.cover_path;
    field = Resolve(path, *value);
  }
  if (out.spheres_path.empty() && out.mesh_path.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(where, ": give spheres (a sphere file) or mesh (to generate them from)"));
  }
  const bool generated = out.spheres_path.empty();
  if (j.contains("voxel_size") || j.contains("max_spheres")) {
    if (!generated) {
      return absl::InvalidArgumentError(
          absl::StrCat(where,
                       ": voxel_size and max_spheres generate spheres from mesh; this "
                       "object has a sphere file"));
    }
    if (j.contains("voxel_size") == j.contains("max_spheres")) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, ": give voxel_size or max_spheres, not both"));
    }
  }
  if (j.contains("voxel_size")) {
    absl::StatusOr<double> v = Field<double>(j, "voxel_size", where, "a number");
    if (!v.ok()) return v.status();
    out.generate.voxel_size = *v;
  }
  if (j.contains("max_spheres")) {
    absl::StatusOr<std::int64_t> n = Field<std::int64_t>(j, "max_spheres", where, "an integer");
    if (!n.ok()) return n.status();
    out.generate.max_spheres = *n;
  }
  if (generated) {
    out.generate.evaluate = false;
    if (absl::Status s = CheckSphereSetParameters(out.generate); !s.ok()) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": ", s.message()));
    }
  }
  if (j.contains("pose")) {
    absl::StatusOr<RigidPose> pose = PoseField(j, where);
    if (!pose.ok()) return pose.status();
    out.object.pose = *pose;
  }
  for (const char* key : {"group", "mask"}) {
    if (!j.contains(key)) continue;
    absl::StatusOr<std::uint32_t> bits =
        Field<std::uint32_t>(j, key, where, "an integer from 0 to 2^32-1");
    if (!bits.ok()) return bits.status();
    (key[0] == 'g' ? out.object.group : out.object.mask) = *bits;
  }
  return out;
}

absl::Status ParseQuery(const json& j, const std::string& path, SceneFile* out) {
  const std::string where = path;
  if (j.contains("threshold")) {
    absl::StatusOr<double> v = Field<double>(j, "threshold", where, "a number");
    if (!v.ok()) return v.status();
    out->query.threshold = *v;
  }
  if (j.contains("abs_err")) {
    absl::StatusOr<double> v = Field<double>(j, "abs_err", where, "a number");
    if (!v.ok()) return v.status();
    out->query.abs_err = *v;
  }
  if (j.contains("rel_err")) {
    absl::StatusOr<double> v = Field<double>(j, "rel_err", where, "a number");
    if (!v.ok()) return v.status();
    out->query.rel_err = *v;
  }
  if (j.contains("stop_at_first")) {
    if (!j["stop_at_first"].is_boolean()) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": stop_at_first must be true or false"));
    }
    out->query.stop_at_first = j["stop_at_first"].get<bool>();
  }
  if (j.contains("max_pairs")) {
    absl::StatusOr<std::uint64_t> v =
        Field<std::uint64_t>(j, "max_pairs", where, "a positive integer");
    if (!v.ok()) return v.status();
    out->query.max_pairs = static_cast<std::size_t>(*v);
  }
  if (absl::Status s = CheckSceneQuery(out->query); !s.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", s.message()));
  }
  if (j.contains("hierarchy")) {
    absl::StatusOr<std::string> name =
        Field<std::string>(j, "hierarchy", where, "\"sphere\" or \"rss\"");
    if (!name.ok()) return name.status();
    if (*name != "sphere" && *name != "rss") {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": hierarchy must be \"sphere\" or \"rss\", got \"", *name, "\""));
    }
    out->volume = *name == "rss" ? HierarchyVolume::kRss : HierarchyVolume::kSphere;
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<SceneFile> ParseSceneFile(absl::string_view bytes, const std::string& path) {
  json j;
  try {
    j = json::parse(bytes.begin(), bytes.end());
  } catch (const json::parse_error& e) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": line ",
                                                   LineOf(bytes, e.byte > 0 ? e.byte - 1 : 0),
                                                   ": not JSON (", e.what(), ")"));
  }
  if (!j.is_object()) return absl::InvalidArgumentError(absl::StrCat(path, ": not a JSON object"));
  for (const auto& [key, value] : j.items()) {
    if (key != "format" && key != "version" && key != "objects" && key != "ignore" &&
        key != "threshold" && key != "abs_err" && key != "rel_err" && key != "max_pairs" &&
        key != "stop_at_first" && key != "hierarchy") {
      return absl::InvalidArgumentError(absl::StrCat(path, ": unknown field \"", key, "\""));
    }
  }
  if (!j.contains("format") || j["format"] != "inscribe.scene" || !j.contains("version") ||
      j["version"] != 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        path, ": not a scene file (expected \"format\": \"inscribe.scene\", \"version\": 1)"));
  }
  SceneFile out;
  if (absl::Status s = ParseQuery(j, path, &out); !s.ok()) return s;
  if (!j.contains("objects") || !j["objects"].is_array()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": objects must be an array"));
  }
  absl::flat_hash_set<SceneObjectId> ids;
  for (std::size_t i = 0; i < j["objects"].size(); ++i) {
    absl::StatusOr<SceneFileObject> object = ParseObject(j["objects"][i], i, path);
    if (!object.ok()) return object.status();
    if (!ids.insert(object->object.id).second) {
      return absl::InvalidArgumentError(
          absl::StrCat(path, ": objects[", i, "]: id ", object->object.id, " is used twice"));
    }
    out.objects.push_back(*std::move(object));
  }
  if (j.contains("ignore")) {
    const json& ignore = j["ignore"];
    if (!ignore.is_array()) {
      return absl::InvalidArgumentError(absl::StrCat(path, ": ignore must be an array of [a, b]"));
    }
    for (std::size_t i = 0; i < ignore.size(); ++i) {
      const json& pair = ignore[i];
      if (!pair.is_array() || pair.size() != 2 || !pair[0].is_number_unsigned() ||
          !pair[1].is_number_unsigned()) {
        return absl::InvalidArgumentError(
            absl::StrCat(path, ": ignore[", i, "] must be a pair of object ids [a, b]"));
      }
      const SceneObjectId a = pair[0].get<SceneObjectId>(), b = pair[1].get<SceneObjectId>();
      for (SceneObjectId id : {a, b}) {
        if (!ids.contains(id)) {
          return absl::InvalidArgumentError(
              absl::StrCat(path, ": ignore[", i, "]: no object with id ", id));
        }
      }
      if (a == b) {
        return absl::InvalidArgumentError(
            absl::StrCat(path, ": ignore[", i, "]: pairs an object with itself"));
      }
      out.ignored.emplace_back(a, b);
    }
  }
  return out;
}

absl::StatusOr<SceneFile> ReadSceneFile(const std::string& path) {
  absl::StatusOr<std::string> bytes = ReadWhole(path, "scene file");
  if (!bytes.ok()) return bytes.status();
  return ParseSceneFile(*bytes, path);
}

absl::StatusOr<std::vector<PoseLogFrame>> ParsePoseLog(
    absl::string_view bytes, const std::string& name,
    const absl::flat_hash_set<SceneObjectId>& ids) {
  std::vector<PoseLogFrame> frames;
  absl::flat_hash_set<SceneObjectId> in_frame;  // ids of frames.back()
  std::int64_t number = 0;
  bool content = false;
  for (absl::string_view line : absl::StrSplit(bytes, '\n')) {
    ++number;
    auto fail = [&](const std::string& why) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": line ", number, ": ", why));
    };
    const absl::string_view text = WithoutComment(line);
    if (text.empty()) continue;
    if (!content && absl::StartsWith(text, "frame")) {  // the header
      content = true;
      continue;
    }
    content = true;
    const std::vector<absl::string_view> fields = absl::StrSplit(text, ',');
    if (fields.size() != 9) {
      return fail(
          absl::StrCat("expected 9 fields frame,id,qw,qx,qy,qz,tx,ty,tz, found ", fields.size()));
    }
    std::int64_t frame = 0;
    SceneObjectId id = 0;
    if (!absl::SimpleAtoi(absl::StripAsciiWhitespace(fields[0]), &frame) || frame < 0) {
      return fail(absl::StrCat("frame '", fields[0], "' is not an integer >= 0"));
    }
    if (!absl::SimpleAtoi(absl::StripAsciiWhitespace(fields[1]), &id)) {
      return fail(absl::StrCat("id '", fields[1], "' is not an integer >= 0"));
    }
    double v[kPoseNumbers];
    for (int k = 0; k < kPoseNumbers; ++k) {
      const absl::string_view field =
          absl::StripAsciiWhitespace(fields[static_cast<std::size_t>(k) + 2]);
      if (!absl::SimpleAtod(field, &v[k]))
        return fail(absl::StrCat("'", field, "' is not a number"));
    }
    if (!ids.contains(id)) return fail(absl::StrCat("no object with id ", id, " in the scene"));
    absl::StatusOr<RigidPose> pose = PoseOf(v);
    if (!pose.ok()) return fail(std::string(pose.status().message()));
    if (frames.empty() || frame > frames.back().frame) {
      frames.push_back(PoseLogFrame{frame, {}});
      in_frame.clear();
    } else if (frame < frames.back().frame) {
      return fail(absl::StrCat("frame ", frame, " after frame ", frames.back().frame,
                               "; frames must be in order"));
    }
    if (!in_frame.insert(id).second) {
      return fail(absl::StrCat("object ", id, " moves twice in frame ", frame));
    }
    frames.back().poses.emplace_back(id, *pose);
  }
  if (frames.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        name, ": no frames (one line per moved object: frame,id,qw,qx,qy,qz,tx,ty,tz)"));
  }
  return frames;
}

absl::StatusOr<std::vector<PoseLogFrame>> ReadPoseLog(
    const std::string& path, const absl::flat_hash_set<SceneObjectId>& ids) {
  absl::StatusOr<std::string> bytes = ReadWhole(path, "pose log");
  if (!bytes.ok()) return bytes.status();
  return ParsePoseLog(*bytes, path, ids);
}

}  // namespace inscribe::cli
