#include "pose_file.h"

#include <fstream>
#include <sstream>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace inscribe::cli {

absl::string_view WithoutComment(absl::string_view line) {
  if (const auto hash = line.find('#'); hash != absl::string_view::npos) {
    line = line.substr(0, hash);
  }
  return absl::StripAsciiWhitespace(line);
}

absl::StatusOr<std::vector<RigidPose>> ParsePoses(absl::string_view bytes,
                                                  const std::string& name) {
  std::vector<RigidPose> poses;
  std::int64_t number = 0;
  for (absl::string_view line : absl::StrSplit(bytes, '\n')) {
    ++number;
    auto fail = [&](const std::string& why) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": line ", number, ": ", why));
    };
    const absl::string_view text = WithoutComment(line);
    const std::vector<absl::string_view> tokens =
        absl::StrSplit(text, absl::ByAnyChar(" \t\r,"), absl::SkipEmpty());
    if (tokens.empty()) continue;
    if (tokens.size() != 7) {
      return fail(absl::StrCat("expected 7 numbers qw qx qy qz tx ty tz, found ", tokens.size()));
    }
    double v[7];
    for (int k = 0; k < 7; ++k) {
      if (!absl::SimpleAtod(tokens[static_cast<std::size_t>(k)], &v[k])) {
        return fail(absl::StrCat("'", tokens[static_cast<std::size_t>(k)], "' is not a number"));
      }
    }
    if (static_cast<std::int64_t>(poses.size()) >= kMaxPoses) {
      return fail(absl::StrCat("more than ", kMaxPoses, " poses; split the file"));
    }
    RigidPose pose{Eigen::Quaterniond(v[0], v[1], v[2], v[3]), Vector3(v[4], v[5], v[6])};
    // Checked here, normalised once, by the service that uses it (normalising twice can move
    // the last bit).
    if (absl::Status usable = NormalizedPose(pose).status(); !usable.ok()) {
      return fail(std::string(usable.message()));
    }
    poses.push_back(pose);
  }
  if (poses.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": no poses (one per line: qw qx qy qz tx ty tz)"));
  }
  return poses;
}

absl::StatusOr<std::vector<RigidPose>> ReadPoseFile(const std::string& path) {
  std::ifstream in(path, std::ios::in | std::ios::binary);
  if (!in) return absl::NotFoundError(absl::StrCat(path, ": cannot open the pose file"));
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::InvalidArgumentError(absl::StrCat(path, ": read error"));
  return ParsePoses(contents.str(), path);
}

}  // namespace inscribe::cli
