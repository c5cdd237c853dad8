// Robot sphere files on the command line: which runs of `inscribe convert` are about a whole
// robot's spheres, and writing the robot sphere model (robot_spheres.h) to a file, shared by
// convert and urdf.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "inscribe/robot/robot_spheres.h"

namespace inscribe::cli {

// The robot format a --to/--from name or a path's extension names, when it names one
// (curobo, xrdf, srdf, urdf, morphit, vamp; .xrdf, .srdf, .urdf); unset for the single-set
// formats (json, sph, csv, obj, yaml) and other extensions.
std::optional<robot::RobotSpheresFormat> RobotFormatNamed(const std::string& name);
std::optional<robot::RobotSpheresFormat> RobotFormatOfPath(const std::string& path);

// The format to write `path` in: `to` when given, else by extension (.yml/.yaml: curobo;
// .urdf: urdf, morphit only by name). UsageError when neither says.
absl::StatusOr<robot::RobotSpheresFormat> RobotOutputFormat(const std::string& to,
                                                            const std::string& path);

// Formats `model` and writes it to `path` atomically (stdout when empty). kUrdf and kMorphit
// are written into `base_urdf` (BadInputError when empty). kSrdf into `path` merges with the
// SRDF already there (its groups, states and other pairs are kept; *merged says so). Errors:
// BadInputError for a file that cannot be read or written or a model the format refuses.
absl::Status WriteRobotSpheres(const robot::RobotSpheres& model, robot::RobotSpheresFormat format,
                               const std::string& path, const std::string& base_urdf,
                               const std::string& comment, bool* merged = nullptr);

// "inscribe: note: FORMAT leaves out: A, B" on stderr when writing `model` in `format` drops
// anything; returns what it drops.
std::vector<std::string> NoteDroppedParts(const robot::RobotSpheres& model,
                                          robot::RobotSpheresFormat format);

}  // namespace inscribe::cli
