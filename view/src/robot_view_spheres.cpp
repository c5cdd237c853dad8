#include "inscribe/view/robot_view_spheres.h"

#include <filesystem>
#include <set>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace inscribe::view {
namespace {

RobotSpheresFormat FormatOf(absl::string_view bytes, const std::string& path) {
  const std::string extension =
      absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  if (extension == ".urdf" || extension == ".xml") return RobotSpheresFormat::kSpherizedUrdf;
  if (extension == ".yaml" || extension == ".yml") return RobotSpheresFormat::kCuroboYaml;
  const absl::string_view text = absl::StripLeadingAsciiWhitespace(bytes);
  return !text.empty() && text.front() == '<' ? RobotSpheresFormat::kSpherizedUrdf
                                              : RobotSpheresFormat::kCuroboYaml;
}

absl::StatusOr<std::vector<LinkSpheres>> SpheresOfUrdf(absl::string_view bytes) {
  absl::StatusOr<robot::UrdfRobot> urdf = robot::ParseUrdf(bytes);
  if (!urdf.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("not a spherized URDF: ", urdf.status().message()));
  }
  std::vector<LinkSpheres> links;
  for (const robot::UrdfLink& link : urdf->links) {
    LinkSpheres spheres{link.name, {}};
    if (!link.from_visual) {
      for (const robot::UrdfElement& element : link.elements) {
        if (element.geometry.shape != robot::UrdfShape::kSphere) continue;
        spheres.spheres.push_back(Sphere{element.origin.xyz, element.geometry.radius});
      }
    }
    if (!spheres.spheres.empty()) links.push_back(std::move(spheres));
  }
  return links;
}

}  // namespace

const char* RobotSpheresFormatName(RobotSpheresFormat format) {
  return format == RobotSpheresFormat::kSpherizedUrdf ? "urdf" : "yaml";
}

absl::StatusOr<RobotSpheres> ParseRobotSpheres(absl::string_view bytes, const std::string& path) {
  RobotSpheres result;
  result.format = FormatOf(bytes, path);
  absl::StatusOr<std::vector<LinkSpheres>> links;
  if (result.format == RobotSpheresFormat::kSpherizedUrdf) {
    links = SpheresOfUrdf(bytes);
  } else {
    links = ParseCuroboYaml(bytes);
    if (!links.ok()) {
      return absl::InvalidArgumentError(
          absl::StrCat("neither a spherized URDF nor a cuRobo YAML with collision_spheres: ",
                       links.status().message()));
    }
  }
  if (!links.ok()) return links.status();
  std::set<std::string> seen;
  std::size_t spheres = 0;
  for (const LinkSpheres& link : *links) {
    if (!seen.insert(link.link).second) {
      return absl::InvalidArgumentError(absl::StrCat("link '", link.link, "' is listed twice"));
    }
    for (std::size_t i = 0; i < link.spheres.size(); ++i) {
      if (absl::Status ok = CheckSphere(link.spheres[i], i); !ok.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("link '", link.link, "': ", ok.message()));
      }
    }
    spheres += link.spheres.size();
  }
  if (spheres == 0) {
    return absl::InvalidArgumentError(
        result.format == RobotSpheresFormat::kSpherizedUrdf
            ? "no <collision> with <sphere> geometry: not a spherized URDF (inscribe urdf -o)"
            : "no spheres in collision_spheres");
  }
  result.links = *std::move(links);
  return result;
}

absl::Status CheckRobotSpheres(const RobotSpheres& spheres, const robot::UrdfRobot& robot) {
  std::set<std::string> names;
  for (const robot::UrdfLink& link : robot.links) names.insert(link.name);
  for (const LinkSpheres& link : spheres.links) {
    if (names.count(link.link) == 0) {
      return absl::InvalidArgumentError(absl::StrCat(
          "spheres for link '", link.link, "', which robot '", robot.name,
          "' does not have (its links: ",
          absl::StrJoin(robot.links, ", ",
                        [](std::string* out, const robot::UrdfLink& l) { out->append(l.name); }),
          ")"));
    }
  }
  return absl::OkStatus();
}

}  // namespace inscribe::view
