// Private to robot_spheres*.cpp: one reader and writer per robot sphere format. Writers take a
// model CheckRobotSpheres accepted; messages carry no file name (ReadRobotSpheresFile adds it).
#pragma once

#include <tinyxml2.h>

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/robot/robot_spheres.h"

namespace inscribe::robot::internal {

// robot_spheres_yaml.cpp: cuRobo's fragment and XRDF.
absl::StatusOr<RobotSpheres> ParseCuroboRobotSpheres(absl::string_view bytes);
absl::StatusOr<std::string> FormatCuroboRobotSpheres(const RobotSpheres& model,
                                                     const RobotSpheresWriteOptions& options);
absl::StatusOr<RobotSpheres> ParseXrdfRobotSpheres(absl::string_view bytes);
absl::StatusOr<std::string> FormatXrdfRobotSpheres(const RobotSpheres& model,
                                                   const RobotSpheresWriteOptions& options);
// Whether a YAML document's top level has `format: xrdf` (false for anything else).
bool IsXrdfDocument(absl::string_view bytes);

// robot_spheres_srdf.cpp
absl::StatusOr<RobotSpheres> ParseSrdfRobotSpheres(absl::string_view bytes);
absl::StatusOr<std::string> FormatSrdfRobotSpheres(const RobotSpheres& model,
                                                   const RobotSpheresWriteOptions& options);

// robot_spheres_urdf.cpp: both URDF layouts are read by one reader (a link's own sphere
// collisions, then its MorphIt children's).
absl::StatusOr<RobotSpheres> ParseUrdfRobotSpheres(absl::string_view bytes);
absl::StatusOr<std::string> FormatUrdfRobotSpheres(const RobotSpheres& model, bool morphit,
                                                   const RobotSpheresWriteOptions& options);
// Whether the URDF has a link "P_sphere<k>" joined to its parent P by a fixed joint.
bool HasMorphitSphereLinks(absl::string_view bytes);

// What the comment a writer leaves in a spherized link says, so a later write finds and
// replaces it: "... N spheres in place of the link's collision geometry".
inline constexpr char kSphereCommentMark[] = "spheres in place of the link's collision geometry";

// In `link`, every <collision> and every comment holding kSphereCommentMark replaced by an XML
// comment and one sphere <collision> per sphere (origin xyz = centre, rpy 0), where the first
// collision was, else after the last <visual>.
void ReplaceLinkCollisions(tinyxml2::XMLDocument& document, tinyxml2::XMLElement& link,
                           const std::vector<Sphere>& spheres, const std::string& comment);

// `text` made safe inside <!-- -->: no "--", no '-' at the end, a space either side.
std::string XmlCommentText(const std::string& text);

// "P_sphere<k>" -> "P" when the name has that form and k is decimal digits; "" otherwise.
std::string MorphitParentName(const std::string& link);

}  // namespace inscribe::robot::internal
