// A robot description file read by its content: URDF (root <robot>) or MJCF (root <mujoco>),
// the one place the two are told apart for `inscribe urdf` and the Python bindings.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/robot/mjcf_robot.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::robot {

enum class RobotFormat { kUrdf, kMjcf };
const char* RobotFormatName(RobotFormat format);  // "urdf", "mjcf"

struct RobotFile {
  RobotFormat format = RobotFormat::kUrdf;
  std::string path;               // as given
  std::string directory;          // absolute: where relative mesh paths start
  std::string bytes;              // the file's contents (the spherized URDF's writer edits them)
  UrdfRobot urdf;                 // kUrdf
  std::optional<MjcfModel> mjcf;  // kMjcf: bodies, joints, geoms and warnings too
  const UrdfRobot& robot() const { return mjcf ? mjcf->robot : urdf; }
  // MJCF's warnings (bodies whose visual geoms stand in, geoms that are no solid); none for URDF.
  const std::vector<std::string>& warnings() const;
  // Whether link `link` of robot() is one the description names (a URDF link, an MJCF body),
  // rather than one of the links MJCF's multi-coordinate joints add.
  bool IsDescribedLink(int link) const;
};

// The format of `bytes` by their root element: kMjcf for <mujoco>, kUrdf otherwise (ParseUrdf
// then names what is wrong with anything else). O(size).
RobotFormat DetectRobotFormat(absl::string_view bytes);

// The bytes of the file at `path`, at most 256 MiB (robot descriptions and the sphere files
// made for them). NOT_FOUND for a missing file; INVALID_ARGUMENT ("PATH: why") for a directory,
// a larger or unreadable file.
absl::StatusOr<std::string> ReadRobotFileBytes(const std::string& path);

// Reads the file at `path` (at most 256 MiB): ParseUrdf or ParseMjcf (with `mjcf`) by content.
// NOT_FOUND for a missing file; INVALID_ARGUMENT for a directory, an unreadable file or one the
// parser refuses (its message after "PATH: ").
absl::StatusOr<RobotFile> ReadRobotFile(const std::string& path, const MjcfReadOptions& mjcf = {});

}  // namespace inscribe::robot
