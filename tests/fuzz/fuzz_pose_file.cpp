// libFuzzer target: the pose-file reader of `inscribe distance --poses` (ParsePoses, which
// ReadPoseFile uses on the file's bytes). A file that parses must give at least one pose and
// only poses NormalizedPose accepts (finite, a quaternion within 1e-3 of unit length, which the
// service normalises); anything else aborts.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "pose_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const absl::string_view bytes(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<std::vector<inscribe::RigidPose>> poses =
      inscribe::cli::ParsePoses(bytes, "poses.txt");
  if (!poses.ok()) {
    if (poses.status().message().empty()) {
      std::fprintf(stderr, "fuzz_pose_file: a refused file has an empty error message\n");
      std::abort();
    }
    return 0;
  }
  if (poses->empty()) {
    std::fprintf(stderr, "fuzz_pose_file: a file that parsed has no poses\n");
    std::abort();
  }
  for (const inscribe::RigidPose& pose : *poses) {
    if (const absl::Status valid = inscribe::NormalizedPose(pose).status(); !valid.ok()) {
      std::fprintf(stderr, "fuzz_pose_file: a parsed pose fails NormalizedPose: %s\n",
                   std::string(valid.message()).c_str());
      std::abort();
    }
  }
  return 0;
}
