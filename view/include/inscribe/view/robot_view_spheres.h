// The sphere file `inscribe view ROBOT.urdf SPHERES` shows: what `inscribe urdf` writes, either
// the spherized URDF (each link's <collision> elements are <sphere>s in the link's frame) or
// cuRobo's `collision_spheres` YAML, read back as spheres per link and checked against the
// robot they are for.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/urdf_robot.h"

namespace inscribe::view {

enum class RobotSpheresFormat {
  kSpherizedUrdf,  // a URDF whose <collision> elements with <sphere> geometry are the spheres
  kCuroboYaml,     // `collision_spheres: {link: [{center: [x, y, z], radius: r}, ...]}`
};

const char* RobotSpheresFormatName(RobotSpheresFormat format);  // "urdf", "yaml"

// Spheres per link, link frames, metres; links in file order, each named once.
struct RobotSpheres {
  RobotSpheresFormat format = RobotSpheresFormat::kSpherizedUrdf;
  std::vector<LinkSpheres> links;
};

// The format of a sphere file: from the extension of `path` (.urdf, .xml; .yaml, .yml), else
// from the bytes (XML starts with '<' after blanks). Then parsed: a spherized URDF by
// ParseUrdf, taking every <collision> with <sphere> geometry (its origin's xyz is the centre;
// collisions with other geometry, e.g. a link `inscribe urdf` skipped, are not spheres, and a
// link's <visual>s never are); YAML by ParseCuroboYaml. INVALID_ARGUMENT with the parser's
// message (line numbers) for garbage, and for a file with no sphere at all. O(size).
absl::StatusOr<RobotSpheres> ParseRobotSpheres(absl::string_view bytes, const std::string& path);

// OK when every link of `spheres` is a link of `robot`; else INVALID_ARGUMENT naming the first
// link that is not (and the robot). O(#links log #links).
absl::Status CheckRobotSpheres(const RobotSpheres& spheres, const robot::UrdfRobot& robot);

}  // namespace inscribe::view
