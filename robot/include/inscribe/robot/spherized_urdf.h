// Writing what `inscribe urdf` made: the robot's URDF with spheres for collision geometry, and
// cuRobo's collision_spheres YAML.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/robot/self_collision.h"
#include "inscribe/robot/urdf_spherize.h"

namespace inscribe::robot {

// `urdf_bytes` (a document ParseUrdf accepted) edited with tinyxml2: in every link whose
// result is kSpherized, all <collision> elements are replaced, where the first of them was
// (after the last <visual> when the spheres stand for visual geometry), by an XML comment and
// one <collision> per sphere: <origin xyz="cx cy cz" rpy="0 0 0"/> and <geometry><sphere
// radius="r"/></geometry>, link frame, metres, each number the shortest decimal that reads back
// as the same double. A kSkipped link keeps its collisions and gets, as its first child, a
// comment with the reason. Joints, visuals, inertials, materials, other links and comments are
// untouched (the document is re-indented by tinyxml2's printer), but for where the result is
// to be written: given both directories (absolute), every relative <mesh filename> (plain or
// file://) of a link's visuals and kept collisions is rewritten relative to
// `output_directory` instead of `source_directory` (the URDF's own), so it names the same file
// from the output; package:// and absolute paths stay. Links are matched by name; results
// naming no link are ignored. INVALID_ARGUMENT if the bytes are not XML.
absl::StatusOr<std::string> SpherizedUrdf(absl::string_view urdf_bytes,
                                          const std::vector<LinkSpherizeResult>& links,
                                          const std::string& source_directory = "",
                                          const std::string& output_directory = "");

// cuRobo's `collision_spheres` YAML (FormatCuroboYaml) with the spheres of every kSpherized
// link, in the order given; skipped links and links without geometry are left out, and so are
// links whose names cuRobo's YAML cannot carry as keys (FormatCuroboYaml allows letters,
// digits and _ - . /): their names are appended to *left_out. Cost O(#spheres).
std::string SpherizedCuroboYaml(const std::vector<LinkSpherizeResult>& links,
                                const std::string& robot_name, std::vector<std::string>* left_out);

// cuRobo's robot configuration fragment (FormatRobotSpheres, kCurobo) of the links
// SpherizedCuroboYaml writes: collision_link_names, collision_spheres and
//   self_collision_ignore: the pairs of written links `matrix` disables (every class but
//     Sometimes), each pair once under its first link by name ({} when none is left). cuRobo
//     skips a pair listed in either direction.
//   self_collision_buffer: every written link's value in `buffers` (metres, 0 when absent),
//     which cuRobo adds to that link's sphere radii in self-collision checks only.
// Pairs are matched by link name. INVALID_ARGUMENT for a buffer that is not finite.
absl::StatusOr<std::string> SpherizedCuroboYaml(const std::vector<LinkSpherizeResult>& links,
                                                const std::string& robot_name,
                                                const SelfCollisionMatrix& matrix,
                                                const std::map<std::string, double>& buffers,
                                                std::vector<std::string>* left_out);

// The shortest decimal that std::from_chars reads back as exactly `value` (finite).
std::string ShortestDecimal(double value);

}  // namespace inscribe::robot
