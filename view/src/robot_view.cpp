#include "inscribe/view/robot_view.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "page_html.h"
#include "viewer_assets.h"

namespace inscribe::view {
namespace {

nlohmann::json Triple(const Vector3& v) { return {v.x(), v.y(), v.z()}; }

std::vector<double> RoundedXyzr(const std::vector<Sphere>& spheres) {
  std::vector<double> xyzr;
  xyzr.reserve(spheres.size() * 4);
  for (const Sphere& s : spheres) {
    for (int k = 0; k < 3; ++k) xyzr.push_back(RoundSignificant(s.center[k], 7));
    xyzr.push_back(RoundSignificant(s.radius, 7));
  }
  return xyzr;
}

nlohmann::json MeshJson(const Mesh& mesh) {
  std::vector<double> vertices;
  vertices.reserve(static_cast<std::size_t>(mesh.num_vertices()) * 3);
  for (std::int64_t v = 0; v < mesh.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) vertices.push_back(RoundSignificant(mesh.vertices(v, k), 7));
  }
  std::vector<std::int32_t> triangles(mesh.triangles.data(),
                                      mesh.triangles.data() + mesh.triangles.size());
  return {{"vertices", std::move(vertices)}, {"triangles", std::move(triangles)}};
}

// Larger files are refused before reading: URDFs and sphere files are kilobytes to megabytes.
constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{256} << 20;

// The whole file, or why not, the message starting with the path.
absl::StatusOr<std::string> ReadWholeFile(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (!fs::exists(path, error)) return absl::NotFoundError(path + ": no such file");
  if (fs::is_directory(path, error)) return absl::InvalidArgumentError(path + ": is a directory");
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error && size > kMaxFileBytes) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": ", size, " bytes is more than the ", kMaxFileBytes, " read here"));
  }
  std::ifstream in(path, std::ios::in | std::ios::binary);
  if (!in) return absl::InvalidArgumentError(path + ": cannot open it for reading");
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::InvalidArgumentError(path + ": read error");
  return contents.str();
}

absl::Status Prefixed(const std::string& path, const absl::Status& status) {
  return absl::Status(status.code(), absl::StrCat(path, ": ", status.message()));
}

}  // namespace

nlohmann::json KinematicsJson(const robot::UrdfRobot& robot, const robot::Kinematics& kinematics) {
  nlohmann::json links = nlohmann::json::array();
  std::vector<std::vector<int>> children(kinematics.links());
  for (int l = 0; l < kinematics.links(); ++l) {
    links.push_back({{"name", kinematics.link_name(l)},
                     {"parent", kinematics.parent(l)},
                     {"joint", kinematics.parent_joint(l)}});
    if (kinematics.parent(l) >= 0) children[kinematics.parent(l)].push_back(l);
  }
  std::vector<int> order = {kinematics.root()};
  for (std::size_t i = 0; i < order.size(); ++i) {
    for (int child : children[order[i]]) order.push_back(child);
  }

  std::map<std::string, int> link_index;
  for (int l = 0; l < kinematics.links(); ++l) link_index.emplace(kinematics.link_name(l), l);
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < robot.joints.size(); ++j) {
    const robot::UrdfJoint& joint = robot.joints[j];
    // Kinematics::Create accepted the tree: every joint's child is a link.
    const robot::Kinematics::JointDrive resolved = kinematics.drive(link_index.at(joint.child));
    joints.push_back({{"name", joint.name},
                      {"type", robot::UrdfJointTypeName(joint.type)},
                      {"xyz", Triple(joint.origin.xyz)},
                      {"rpy", Triple(joint.origin.rpy)},
                      {"axis", Triple(joint.axis)},
                      {"variable", resolved.variable},
                      {"multiplier", resolved.multiplier},
                      {"offset", resolved.offset},
                      {"mimic", joint.mimic ? nlohmann::json(joint.mimic->joint) : nullptr}});
  }
  nlohmann::json variables = nlohmann::json::array();
  const std::vector<double> home = robot::DefaultConfiguration(kinematics);
  for (std::size_t i = 0; i < kinematics.variables().size(); ++i) {
    const robot::JointVariable& v = kinematics.variables()[i];
    variables.push_back({{"joint", v.joint},
                         {"type", robot::UrdfJointTypeName(v.type)},
                         {"lower", v.lower},
                         {"upper", v.upper},
                         {"value", home[i]}});
  }
  return {{"links", std::move(links)},
          {"order", std::move(order)},
          {"joints", std::move(joints)},
          {"variables", std::move(variables)}};
}

nlohmann::json RobotViewData(const robot::UrdfRobot& robot, const robot::Kinematics& kinematics,
                             const std::vector<RobotViewLink>& links, const RobotSpheres& spheres,
                             const RobotViewOptions& options) {
  nlohmann::json data = KinematicsJson(robot, kinematics);
  nlohmann::json geometry = nlohmann::json::array();
  std::size_t count = 0, protruding = 0;
  double protrusion_max = 0.0;
  for (const RobotViewLink& link : links) {
    nlohmann::json meshes = nlohmann::json::array();
    for (const Mesh& mesh : link.meshes) meshes.push_back(MeshJson(mesh));
    nlohmann::json protrusion = nullptr;
    if (!link.protrusion.empty()) {
      protrusion = nlohmann::json::array();
      for (double p : link.protrusion) {
        protrusion.push_back(RoundSignificant(p, 4));
        protruding += p > link.protrusion_tolerance;
        protrusion_max = std::max(protrusion_max, p);
      }
    }
    count += link.spheres.size();
    geometry.push_back({{"meshes", std::move(meshes)},
                        {"shapes", RoundedXyzr(link.shapes)},
                        {"spheres", RoundedXyzr(link.spheres)},
                        {"protrusion", std::move(protrusion)},
                        {"tolerance", link.protrusion_tolerance},
                        {"problems", link.problems}});
  }
  data["title"] = options.title;
  data["robot"] = {{"name", robot.name},
                   {"file", options.robot_name},
                   {"links", robot.links.size()},
                   {"joints", robot.joints.size()}};
  data["spheres"] = {{"file", options.spheres_name},
                     {"format", RobotSpheresFormatName(spheres.format)},
                     {"count", count},
                     {"protruding", protruding},
                     {"protrusion_max", protrusion_max}};
  data["geometry"] = std::move(geometry);
  return data;
}

absl::StatusOr<std::string> RobotViewPageHtml(const nlohmann::json& data,
                                              const std::string& title) {
  return SelfContainedPage(data, title, "robot_view_page.js", RobotViewPageJs());
}

absl::StatusOr<std::string> MakeRobotViewPage(const robot::UrdfRobot& robot,
                                              const RobotSpheres& spheres,
                                              const RobotViewOptions& options) {
  absl::StatusOr<robot::Kinematics> kinematics = robot::Kinematics::Create(robot);
  if (!kinematics.ok()) return kinematics.status();
  if (absl::Status checked = CheckRobotSpheres(spheres, robot); !checked.ok()) return checked;
  std::map<std::string, std::vector<Sphere>> by_link;
  for (const LinkSpheres& link : spheres.links) by_link[link.link] = link.spheres;
  robot::UrdfSpherizeOptions geometry;
  geometry.packages = options.packages;
  geometry.urdf_dir = options.urdf_dir;
  std::vector<RobotViewLink> links;
  links.reserve(robot.links.size());
  // Kinematics keeps UrdfRobot::links' order and indices.
  for (const robot::UrdfLink& link : robot.links) {
    const auto found = by_link.find(link.name);
    links.push_back(MakeRobotViewLink(
        link, found == by_link.end() ? std::vector<Sphere>{} : found->second, geometry));
  }
  return RobotViewPageHtml(RobotViewData(robot, *kinematics, links, spheres, options),
                           options.title);
}

absl::StatusOr<std::string> MakeRobotViewPageFromFiles(const std::string& urdf_path,
                                                       const std::string& spheres_path,
                                                       RobotViewOptions options) {
  absl::StatusOr<std::string> urdf_bytes = ReadWholeFile(urdf_path);
  if (!urdf_bytes.ok()) return urdf_bytes.status();
  absl::StatusOr<robot::UrdfRobot> robot = robot::ParseUrdf(*urdf_bytes);
  if (!robot.ok()) return Prefixed(urdf_path, robot.status());
  absl::StatusOr<std::string> sphere_bytes = ReadWholeFile(spheres_path);
  if (!sphere_bytes.ok()) return sphere_bytes.status();
  absl::StatusOr<RobotSpheres> spheres = ParseRobotSpheres(*sphere_bytes, spheres_path);
  if (!spheres.ok()) return Prefixed(spheres_path, spheres.status());
  if (absl::Status checked = CheckRobotSpheres(*spheres, *robot); !checked.ok()) {
    return Prefixed(spheres_path, checked);
  }
  if (options.urdf_dir.empty()) {
    options.urdf_dir = std::filesystem::absolute(urdf_path).parent_path().string();
  }
  // The spheres passed their check: what MakeRobotViewPage refuses now is the robot's tree.
  absl::StatusOr<std::string> page = MakeRobotViewPage(*robot, *spheres, options);
  if (page.status().code() == absl::StatusCode::kInvalidArgument) {
    return Prefixed(urdf_path, page.status());
  }
  return page;
}

}  // namespace inscribe::view
