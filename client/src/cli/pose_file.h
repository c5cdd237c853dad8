// Pose files: one rigid pose per line, `qw qx qy qz tx ty tz` (a unit quaternion, then a
// translation in mesh units), blank lines and `#` comments ignored.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/geometry/rigid_pose.h"

namespace inscribe::cli {

// More poses than this in one file are refused (the results of one call stay in memory).
inline constexpr std::int64_t kMaxPoses = 2'000'000;

// A line of a pose file or pose log without its `#` comment and surrounding whitespace.
absl::string_view WithoutComment(absl::string_view line);

// Parses the bytes of a whole pose file; `name` (the path) starts every error message.
// Quaternions within 1e-3 of unit length (rounded values such as 0.7071) are returned as
// written, for the service to normalise (NormalizedPose accepts each); others are refused.
// INVALID_ARGUMENT naming the line:
// `poses.txt: line 4: expected 7 numbers qw qx qy qz tx ty tz, found 6`. Cost O(bytes); no
// memory is sized from the input beyond the poses it holds.
absl::StatusOr<std::vector<RigidPose>> ParsePoses(absl::string_view bytes, const std::string& name);

// Reads `path` whole and parses it with ParsePoses; NOT_FOUND when it cannot be opened.
absl::StatusOr<std::vector<RigidPose>> ReadPoseFile(const std::string& path);

}  // namespace inscribe::cli
