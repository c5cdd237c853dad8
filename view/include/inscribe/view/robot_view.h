// The page `inscribe view ROBOT.urdf SPHERES` writes: the whole robot posed by forward
// kinematics in the browser, a slider per joint variable (mimic joints follow their leader),
// every link's geometry (translucent) and spheres, coloured per link or by how far each sphere
// reaches outside its link, links shown or hidden one by one. Self-contained like the mesh
// page (view_report_html.h): three.js, the script (robot_view_page.js), style and data inline.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/urdf_robot.h"
#include "inscribe/view/robot_view_link.h"
#include "inscribe/view/robot_view_spheres.h"

namespace inscribe::view {

struct RobotViewOptions {
  std::string title;         // panel heading and tab title
  std::string robot_name;    // the URDF file's name
  std::string spheres_name;  // the sphere file's name
  // Where the link meshes are: package:// search paths and the URDF file's directory.
  robot::PackageSearch packages;
  std::string urdf_dir;
};

// The kinematic part of the page's data, the same conventions as robot::Kinematics (child =
// parent * origin * motion; rpy is Rz(yaw) * Ry(pitch) * Rx(roll)):
//   links: [{name, parent (link index, -1 for the root), joint (index into joints, -1)}],
//   order: link indices, every parent before its children,
//   joints: [{name, type (URDF's name), xyz, rpy, axis, variable, multiplier, offset}] in
//     UrdfRobot::joints order; a joint's value is multiplier * q[variable] + offset (variable
//     -1: no motion; an active joint: itself, 1, 0; a mimic: its chain of leaders composed),
//   variables: [{joint, type, lower, upper, value}] in Kinematics::variables order; value is
//     DefaultConfiguration's (MoveIt's default state), the pose the page opens in.
// Numbers as given (no rounding): the page's poses must equal Kinematics::LinkPoses.
nlohmann::json KinematicsJson(const robot::UrdfRobot& robot, const robot::Kinematics& kinematics);

// The page's data (<script id="inscribe-data">): KinematicsJson's keys and
//   title, robot: {name, file, links, joints}, spheres: {file, format, count, protruding,
//   protrusion_max}, geometry: [per link {meshes: [{vertices, triangles}], shapes: [x, y, z, r,
//   ...], spheres: [x, y, z, r, ...], protrusion: [...] or null, tolerance, problems: [...]}]
// in link order. Coordinates rounded to 7 significant digits (what WebGL draws), protrusions
// to 4. Cost O(total vertices + triangles + spheres).
nlohmann::json RobotViewData(const robot::UrdfRobot& robot, const robot::Kinematics& kinematics,
                             const std::vector<RobotViewLink>& links, const RobotSpheres& spheres,
                             const RobotViewOptions& options);

// The page around `data` (RobotViewData). INTERNAL as ViewPageHtml for a build problem.
absl::StatusOr<std::string> RobotViewPageHtml(const nlohmann::json& data, const std::string& title);

// The whole page for `robot` (a parsed URDF) and `spheres` (read from the sphere file).
// INVALID_ARGUMENT for a robot Kinematics::Create refuses (naming the joint) or spheres for a
// link the robot does not have (CheckRobotSpheres). Links whose geometry cannot be read are
// named on the page, not refused. Cost: MakeRobotViewLink for every link.
absl::StatusOr<std::string> MakeRobotViewPage(const robot::UrdfRobot& robot,
                                              const RobotSpheres& spheres,
                                              const RobotViewOptions& options);

// MakeRobotViewPage for the files at `urdf_path` (ParseUrdf) and `spheres_path`
// (ParseRobotSpheres); options.urdf_dir defaults to the URDF's directory. Every message starts
// with the path of the file at fault: NOT_FOUND for a missing file, INVALID_ARGUMENT for a
// directory, an unreadable file, a file over 256 MB or any error above.
absl::StatusOr<std::string> MakeRobotViewPageFromFiles(const std::string& urdf_path,
                                                       const std::string& spheres_path,
                                                       RobotViewOptions options);

}  // namespace inscribe::view
