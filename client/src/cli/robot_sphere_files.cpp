#include "robot_sphere_files.h"

#include <filesystem>
#include <iostream>
#include <system_error>

#include "absl/strings/ascii.h"
#include "absl/strings/str_join.h"
#include "command_outcome.h"
#include "inscribe/base/atomic_file.h"
#include "inscribe/robot/robot_file.h"

namespace inscribe::cli {

using robot::RobotSpheresFormat;

std::optional<RobotSpheresFormat> RobotFormatNamed(const std::string& name) {
  const std::string lower = absl::AsciiStrToLower(name);
  // "yaml" and "yml" stay the single-set cuRobo YAML of one link; "curobo" is the robot's.
  if (lower.empty() || lower == "yaml" || lower == "yml") return std::nullopt;
  absl::StatusOr<RobotSpheresFormat> format = robot::ParseRobotSpheresFormat(lower);
  if (!format.ok()) return std::nullopt;
  return *format;
}

std::optional<RobotSpheresFormat> RobotFormatOfPath(const std::string& path) {
  absl::StatusOr<RobotSpheresFormat> format = robot::RobotSpheresFormatFromPath(path);
  if (!format.ok() || *format == RobotSpheresFormat::kCurobo) return std::nullopt;
  return *format;
}

absl::StatusOr<RobotSpheresFormat> RobotOutputFormat(const std::string& to,
                                                     const std::string& path) {
  if (!to.empty()) {
    absl::StatusOr<RobotSpheresFormat> named = robot::ParseRobotSpheresFormat(to);
    if (!named.ok()) return UsageError(named.status().message());
    return *named;
  }
  if (path.empty()) return UsageError("name the output format with --to (stdout has no extension)");
  absl::StatusOr<RobotSpheresFormat> by_extension = robot::RobotSpheresFormatFromPath(path);
  if (!by_extension.ok())
    return UsageError(std::string(by_extension.status().message()) + "; or give --to");
  return *by_extension;
}

absl::Status WriteRobotSpheres(const robot::RobotSpheres& model, RobotSpheresFormat format,
                               const std::string& path, const std::string& base_urdf,
                               const std::string& comment, bool* merged) {
  robot::RobotSpheresWriteOptions options;
  options.comment = comment;
  if (format == RobotSpheresFormat::kUrdf || format == RobotSpheresFormat::kMorphit) {
    if (base_urdf.empty()) {
      return UsageError(std::string(robot::RobotSpheresFormatName(format)) +
                        " output is the robot's URDF with spheres: give the robot with --robot "
                        "URDF");
    }
    absl::StatusOr<std::string> bytes = robot::ReadRobotFileBytes(base_urdf);
    if (!bytes.ok()) return BadInputError(bytes.status().message());
    options.base = *std::move(bytes);
  }
  std::error_code error;
  if (format == RobotSpheresFormat::kSrdf && !path.empty() &&
      std::filesystem::exists(path, error)) {
    absl::StatusOr<std::string> bytes = robot::ReadRobotFileBytes(path);
    if (!bytes.ok()) return BadInputError(bytes.status().message());
    options.base = *std::move(bytes);
    if (merged != nullptr) *merged = true;
  }
  absl::StatusOr<std::string> text = robot::FormatRobotSpheres(model, format, options);
  if (!text.ok()) {
    return BadInputError((path.empty() ? std::string("stdout") : path) + " (" +
                         robot::RobotSpheresFormatName(format) +
                         "): " + std::string(text.status().message()));
  }
  if (path.empty()) {
    std::cout << *text;
    return absl::OkStatus();
  }
  if (absl::Status written = WriteFileAtomically(path, *text); !written.ok()) {
    return BadInputError(written.message());
  }
  return absl::OkStatus();
}

std::vector<std::string> NoteDroppedParts(const robot::RobotSpheres& model,
                                          RobotSpheresFormat format) {
  std::vector<std::string> dropped = robot::RobotSpheresDropped(model, format);
  if (!dropped.empty()) {
    std::cerr << "inscribe: note: " << robot::RobotSpheresFormatName(format)
              << " leaves out: " << absl::StrJoin(dropped, ", ") << "\n";
  }
  return dropped;
}

}  // namespace inscribe::cli
