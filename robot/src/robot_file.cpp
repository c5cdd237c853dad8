#include "inscribe/robot/robot_file.h"

#include <tinyxml2.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace inscribe::robot {
namespace {

namespace fs = std::filesystem;

// Larger files are refused before reading: real descriptions are kilobytes to a few megabytes.
constexpr std::uintmax_t kMaxRobotFileBytes = 256u << 20;

}  // namespace

const char* RobotFormatName(RobotFormat format) {
  return format == RobotFormat::kMjcf ? "mjcf" : "urdf";
}

const std::vector<std::string>& RobotFile::warnings() const {
  static const std::vector<std::string> kNone;
  return mjcf ? mjcf->warnings : kNone;
}

bool RobotFile::IsDescribedLink(int link) const {
  if (!mjcf) return true;
  for (const MjcfBody& body : mjcf->bodies) {
    if (body.link == link) return true;
  }
  return false;
}

RobotFormat DetectRobotFormat(absl::string_view bytes) {
  tinyxml2::XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS) {
    return RobotFormat::kUrdf;
  }
  const tinyxml2::XMLElement* root = document.RootElement();
  return root != nullptr && std::string(root->Name()) == "mujoco" ? RobotFormat::kMjcf
                                                                  : RobotFormat::kUrdf;
}

absl::StatusOr<std::string> ReadRobotFileBytes(const std::string& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return absl::NotFoundError(path + ": no such file");
  if (fs::is_directory(path, error)) return absl::InvalidArgumentError(path + ": is a directory");
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error && size > kMaxRobotFileBytes) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", size, " bytes is more than the ",
                                                   kMaxRobotFileBytes,
                                                   " a robot description may have"));
  }
  std::ifstream in(path, std::ios::in | std::ios::binary);
  if (!in) return absl::InvalidArgumentError(path + ": cannot open it for reading");
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::InvalidArgumentError(path + ": read error");
  return contents.str();
}

absl::StatusOr<RobotFile> ReadRobotFile(const std::string& path, const MjcfReadOptions& mjcf) {
  absl::StatusOr<std::string> bytes = ReadRobotFileBytes(path);
  if (!bytes.ok()) return bytes.status();
  RobotFile file;
  file.path = path;
  file.directory = fs::absolute(path).parent_path().string();
  file.bytes = *std::move(bytes);
  file.format = DetectRobotFormat(file.bytes);
  if (file.format == RobotFormat::kMjcf) {
    absl::StatusOr<MjcfModel> model = ParseMjcf(file.bytes, path, mjcf);
    if (!model.ok()) {
      return absl::Status(model.status().code(),
                          absl::StrCat(path, ": ", model.status().message()));
    }
    file.mjcf = *std::move(model);
  } else {
    absl::StatusOr<UrdfRobot> robot = ParseUrdf(file.bytes);
    if (!robot.ok()) {
      return absl::Status(robot.status().code(),
                          absl::StrCat(path, ": ", robot.status().message()));
    }
    file.urdf = *std::move(robot);
  }
  return file;
}

}  // namespace inscribe::robot
