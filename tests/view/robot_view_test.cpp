// The robot page's pieces: reading a spherized URDF or cuRobo YAML back as spheres per link,
// each link's geometry and its spheres' protrusion (against exact figures on boxes and balls),
// the joint data the page's forward kinematics reads, and the page around it.
#include "inscribe/view/robot_view.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "inscribe/mesh/mesh_io.h"
#include "inscribe/view/robot_view_link.h"
#include "inscribe/view/robot_view_spheres.h"
#include "support/synthetic_meshes.h"

namespace inscribe::view {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

robot::UrdfElement BoxElement(const Vector3& size, const Vector3& xyz) {
  robot::UrdfElement element;
  element.geometry.shape = robot::UrdfShape::kBox;
  element.geometry.size = size;
  element.origin.xyz = xyz;
  element.line = 3;
  return element;
}

robot::UrdfElement BallElement(double radius, const Vector3& xyz) {
  robot::UrdfElement element;
  element.geometry.shape = robot::UrdfShape::kSphere;
  element.geometry.radius = radius;
  element.origin.xyz = xyz;
  element.line = 4;
  return element;
}

robot::UrdfElement MeshElement(const std::string& filename) {
  robot::UrdfElement element;
  element.geometry.shape = robot::UrdfShape::kMesh;
  element.geometry.filename = filename;
  element.line = 5;
  return element;
}

TEST(RobotViewSpheres, ReadsTheSphereCollisionsOfASpherizedUrdf) {
  const std::string urdf = R"(<robot name="r">
    <link name="a"><collision><origin xyz="0.1 0.2 0.3"/><geometry><sphere radius="0.5"/>
      </geometry></collision><collision><origin xyz="1 2 3"/><geometry><sphere radius="0.25"/>
      </geometry></collision></link>
    <link name="skipped"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
    <link name="visual"><visual><geometry><sphere radius="1"/></geometry></visual></link>
    <link name="none"/></robot>)";
  for (const std::string path : {"spheres.urdf", "spheres.txt", "spheres"}) {
    SCOPED_TRACE(path);
    const absl::StatusOr<RobotSpheres> spheres = ParseRobotSpheres(urdf, path);
    ASSERT_TRUE(spheres.ok()) << spheres.status();
    EXPECT_EQ(spheres->format, RobotSpheresFormat::kSpherizedUrdf);
    ASSERT_EQ(spheres->links.size(), 1u);
    EXPECT_EQ(spheres->links[0].link, "a");
    ASSERT_EQ(spheres->links[0].spheres.size(), 2u);
    EXPECT_EQ(spheres->links[0].spheres[0].center, Vector3(0.1, 0.2, 0.3));
    EXPECT_EQ(spheres->links[0].spheres[0].radius, 0.5);
    EXPECT_EQ(spheres->links[0].spheres[1].radius, 0.25);
  }
}

TEST(RobotViewSpheres, ReadsCuroboYamlByExtensionOrContent) {
  const std::string yaml =
      "robot: r\ncollision_spheres:\n  a:\n    - center: [1, 2, 3]\n      radius: 0.5\n"
      "  b: []\n";
  for (const std::string path : {"spheres.yml", "spheres.yaml", "spheres.txt"}) {
    SCOPED_TRACE(path);
    const absl::StatusOr<RobotSpheres> spheres = ParseRobotSpheres(yaml, path);
    ASSERT_TRUE(spheres.ok()) << spheres.status();
    EXPECT_EQ(spheres->format, RobotSpheresFormat::kCuroboYaml);
    ASSERT_EQ(spheres->links.size(), 2u);
    EXPECT_EQ(spheres->links[0].spheres[0].center, Vector3(1, 2, 3));
    EXPECT_TRUE(spheres->links[1].spheres.empty());
  }
}

TEST(RobotViewSpheres, GarbageAndEmptyFilesAreRefusedWithTheReason) {
  struct Case {
    std::string bytes, path, message;
  };
  const std::vector<Case> cases = {
      {"\x01\x02 not: [yaml", "s.txt", "neither a spherized URDF nor a cuRobo YAML"},
      {"collision_spheres:\n  a: []\n", "s.yml", "no spheres"},
      {"<robot name=\"r\"><link name=\"a\"/></robot>", "s.urdf", "not a spherized URDF"},
      {"<robot><link name=\"a\"></robot>", "s.urdf", "not a spherized URDF"},
      {"<html/>", "s.xml", "not a spherized URDF"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.bytes);
    const absl::StatusOr<RobotSpheres> spheres = ParseRobotSpheres(c.bytes, c.path);
    ASSERT_FALSE(spheres.ok());
    EXPECT_EQ(spheres.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(spheres.status().message(), HasSubstr(c.message));
  }
}

TEST(RobotViewSpheres, SpheresForALinkTheRobotLacksAreRefused) {
  robot::UrdfRobot robot;
  robot.name = "r";
  robot.links.resize(2);
  robot.links[0].name = "base";
  robot.links[1].name = "arm";
  RobotSpheres spheres;
  spheres.links = {{"arm", {Sphere{Vector3::Zero(), 1.0}}}};
  EXPECT_TRUE(CheckRobotSpheres(spheres, robot).ok());
  spheres.links.push_back({"hand", {Sphere{Vector3::Zero(), 1.0}}});
  const absl::Status checked = CheckRobotSpheres(spheres, robot);
  EXPECT_EQ(checked.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(checked.message(), HasSubstr("'hand'"));
  EXPECT_THAT(checked.message(), HasSubstr("base, arm"));
}

TEST(RobotViewLink, ProtrusionIsExactOnABoxAndABall) {
  robot::UrdfLink link;
  link.name = "l";
  // A box [0.2, 0.6] x [-0.1, 0.1] x [-0.1, 0.1] and a ball of radius 0.2 at the origin.
  link.elements = {BoxElement({0.4, 0.2, 0.2}, {0.4, 0, 0}), BallElement(0.2, Vector3::Zero())};
  const std::vector<Sphere> spheres = {
      {{0.4, 0.0, 0.0}, 0.05},   // inside the box
      {{0.55, 0.0, 0.0}, 0.1},   // 0.05 past the box's x = 0.6 face
      {{0.0, 0.15, 0.0}, 0.1},   // 0.05 past the ball
      {{0.15, 0.0, 0.0}, 0.04},  // inside the ball, 0.09 past the box: 0
      {{0.0, 0.0, 0.5}, 0.1},    // outside both: the least of the two
  };
  const RobotViewLink view = MakeRobotViewLink(link, spheres, {});
  EXPECT_TRUE(view.problems.empty());
  ASSERT_EQ(view.meshes.size(), 1u);
  EXPECT_EQ(view.meshes[0].num_triangles(), 12);
  ASSERT_EQ(view.shapes.size(), 1u);
  ASSERT_EQ(view.protrusion.size(), spheres.size());
  EXPECT_NEAR(view.protrusion[0], 0.0, 1e-12);
  EXPECT_NEAR(view.protrusion[1], 0.05, 1e-12);
  EXPECT_NEAR(view.protrusion[2], 0.05, 1e-12);
  EXPECT_NEAR(view.protrusion[3], 0.0, 1e-12);
  // Ball: 0.5 + 0.1 - 0.2; box: from (0, 0, 0.5) to its nearest point (0.2, 0, 0.1), + 0.1.
  EXPECT_NEAR(view.protrusion[4], std::min(0.4, std::hypot(0.2, 0.4) + 0.1), 1e-12);
  EXPECT_GT(view.protrusion_tolerance, 0.0);
  EXPECT_LT(view.protrusion_tolerance, 1e-8);
}

TEST(RobotViewLink, UnreadableGeometryIsNamedAndProtrusionUnknown) {
  const fs::path dir =
      fs::temp_directory_path() / ("robot_view_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  robot::UrdfSpherizeOptions options;
  options.urdf_dir = dir.string();
  robot::UrdfLink link;
  link.name = "hand";
  link.from_visual = true;
  link.elements = {BoxElement({1, 1, 1}, Vector3::Zero()), MeshElement("hand.dae"),
                   MeshElement("missing.stl")};
  const RobotViewLink view = MakeRobotViewLink(link, {Sphere{Vector3::Zero(), 0.1}}, options);
  EXPECT_EQ(view.meshes.size(), 1u);  // the box is still shown
  ASSERT_EQ(view.problems.size(), 2u);
  EXPECT_THAT(view.problems[0], HasSubstr("line 5 (<visual>): "));
  EXPECT_THAT(view.problems[0], HasSubstr("hand.dae"));
  EXPECT_THAT(view.problems[1], HasSubstr("missing.stl"));
  EXPECT_TRUE(view.protrusion.empty());

  // An open mesh is shown, but cannot measure the spheres.
  Mesh open = testing::Box(Vector3::Zero(), Vector3::Ones());
  open.triangles.conservativeResize(open.triangles.rows() - 1, 3);
  ASSERT_TRUE(WriteMesh((dir / "open.off").string(), open).ok());
  link.elements = {MeshElement("open.off")};
  const RobotViewLink opened = MakeRobotViewLink(link, {Sphere{Vector3::Zero(), 0.1}}, options);
  EXPECT_EQ(opened.meshes.size(), 1u);
  ASSERT_EQ(opened.problems.size(), 1u);
  EXPECT_THAT(opened.problems[0], HasSubstr("not a closed solid"));
  EXPECT_TRUE(opened.protrusion.empty());

  // No geometry at all.
  link.elements.clear();
  const RobotViewLink bare = MakeRobotViewLink(link, {Sphere{Vector3::Zero(), 0.1}}, options);
  ASSERT_EQ(bare.problems.size(), 1u);
  EXPECT_THAT(bare.problems[0], HasSubstr("no geometry"));
  EXPECT_TRUE(bare.protrusion.empty());
  fs::remove_all(dir);
}

// base -revolute-> a -prismatic-> b, c mimics the revolute (2x + 0.5), d mimics c (-x + 1).
robot::UrdfRobot ChainRobot() {
  robot::UrdfRobot robot;
  robot.name = "chain";
  for (const char* name : {"base", "a", "b", "c", "d"}) {
    robot.links.emplace_back();
    robot.links.back().name = name;
  }
  robot.links[1].elements = {BoxElement({0.1, 0.1, 0.1}, Vector3::Zero())};
  const auto joint = [&](const char* name, robot::UrdfJointType type, const char* parent,
                         const char* child) {
    robot::UrdfJoint j;
    j.name = name;
    j.type = type;
    j.parent = parent;
    j.child = child;
    j.origin.xyz = {0.1, 0.2, 0.3};
    j.origin.rpy = {0.3, -0.2, 0.1};
    j.axis = Vector3(0, 0.6, 0.8);
    j.lower = -1.0;
    j.upper = 2.0;
    robot.joints.push_back(j);
  };
  joint("ja", robot::UrdfJointType::kRevolute, "base", "a");
  joint("jb", robot::UrdfJointType::kPrismatic, "a", "b");
  robot.joints.back().lower = 0.5;  // home is then the middle, 1.25
  joint("jc", robot::UrdfJointType::kRevolute, "a", "c");
  robot.joints.back().mimic = robot::UrdfMimic{"ja", 2.0, 0.5};
  joint("jd", robot::UrdfJointType::kContinuous, "c", "d");
  robot.joints.back().mimic = robot::UrdfMimic{"jc", -1.0, 1.0};
  return robot;
}

TEST(RobotViewData, JointsCarryTheirVariableAndComposedMimics) {
  const robot::UrdfRobot robot = ChainRobot();
  absl::StatusOr<robot::Kinematics> kinematics = robot::Kinematics::Create(robot);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status();
  const nlohmann::json data = KinematicsJson(robot, *kinematics);
  ASSERT_EQ(data.at("variables").size(), 2u);
  EXPECT_EQ(data.at("variables")[0].at("joint"), "ja");
  EXPECT_EQ(data.at("variables")[0].at("value"), 0.0);
  EXPECT_EQ(data.at("variables")[1].at("value"), 1.25);
  const nlohmann::json& joints = data.at("joints");
  ASSERT_EQ(joints.size(), 4u);
  EXPECT_EQ(joints[0].at("variable"), 0);
  EXPECT_EQ(joints[1].at("variable"), 1);
  EXPECT_EQ(joints[1].at("type"), "prismatic");
  EXPECT_EQ(joints[2].at("variable"), 0);
  EXPECT_EQ(joints[2].at("multiplier"), 2.0);
  EXPECT_EQ(joints[2].at("offset"), 0.5);
  // value(jd) = -(2 q0 + 0.5) + 1.
  EXPECT_EQ(joints[3].at("variable"), 0);
  EXPECT_EQ(joints[3].at("multiplier"), -2.0);
  EXPECT_EQ(joints[3].at("offset"), 0.5);
  EXPECT_EQ(joints[3].at("mimic"), "jc");
  // Every parent before its children.
  const std::vector<int> order = data.at("order").get<std::vector<int>>();
  ASSERT_EQ(order.size(), 5u);
  std::vector<int> position(5);
  for (int i = 0; i < 5; ++i) position[order[i]] = i;
  for (int l = 0; l < 5; ++l) {
    const int parent = data.at("links")[l].at("parent");
    if (parent >= 0) {
      EXPECT_LT(position[parent], position[l]);
    }
  }
}

TEST(RobotViewData, PageInlinesTheRobotScriptAndRefusesStrangeLinks) {
  const robot::UrdfRobot robot = ChainRobot();
  RobotSpheres spheres;
  spheres.links = {{"a", {Sphere{Vector3::Zero(), 0.01}, Sphere{{0.06, 0, 0}, 0.02}}}};
  RobotViewOptions options;
  options.title = "chain </script>";
  const absl::StatusOr<std::string> page = MakeRobotViewPage(robot, spheres, options);
  ASSERT_TRUE(page.ok()) << page.status();
  EXPECT_THAT(*page, HasSubstr("function linkPoses("));  // robot_view_page.js
  EXPECT_THAT(*page, HasSubstr("<title>chain &lt;/script&gt; - inscribe view</title>"));
  EXPECT_THAT(*page, HasSubstr("\"protruding\":1"));  // the second sphere: 0.03 past x = 0.05

  spheres.links.push_back({"z", {Sphere{Vector3::Zero(), 0.01}}});
  const absl::StatusOr<std::string> refused = MakeRobotViewPage(robot, spheres, options);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(refused.status().message(), HasSubstr("'z'"));
}

}  // namespace
}  // namespace inscribe::view
