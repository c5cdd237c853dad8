// URDF parsing, rpy rotations, mesh filename resolution and the primitive meshes of
// `inscribe urdf` (client/src/cli/urdf_robot.h, primitive_meshes.h).
#include "inscribe/robot/urdf_robot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "inscribe/robot/primitive_meshes.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::robot {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

// URDF's rpy written out by hand: R = Rz(yaw) Ry(pitch) Rx(roll), element by element.
Eigen::Matrix3d HandRpy(double roll, double pitch, double yaw) {
  const double cr = std::cos(roll), sr = std::sin(roll), cp = std::cos(pitch), sp = std::sin(pitch),
               cy = std::cos(yaw), sy = std::sin(yaw);
  Eigen::Matrix3d r;
  r << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return r;
}

TEST(UrdfRpy, SingleAxesAreTheRightHandedElementaryRotations) {
  const double a = 0.4, c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d rx, ry, rz;
  rx << 1, 0, 0, 0, c, -s, 0, s, c;
  ry << c, 0, s, 0, 1, 0, -s, 0, c;
  rz << c, -s, 0, s, c, 0, 0, 0, 1;
  EXPECT_TRUE(RotationFromRpy(Vector3(a, 0, 0)).isApprox(rx, 1e-15));
  EXPECT_TRUE(RotationFromRpy(Vector3(0, a, 0)).isApprox(ry, 1e-15));
  EXPECT_TRUE(RotationFromRpy(Vector3(0, 0, a)).isApprox(rz, 1e-15));
  // Yaw a quarter turn takes the element's x axis to the link's y axis.
  EXPECT_TRUE((RotationFromRpy(Vector3(0, 0, M_PI / 2)) * Vector3::UnitX())
                  .isApprox(Vector3::UnitY(), 1e-15));
}

TEST(UrdfRpy, CombinedAnglesMatchTheHandComputedFixedAxisProduct) {
  for (const Vector3& rpy :
       {Vector3(0.3, -0.5, 1.1), Vector3(-2.0, 1.2, 3.0), Vector3(M_PI, M_PI / 2, -M_PI / 4)}) {
    const Eigen::Matrix3d r = RotationFromRpy(rpy);
    EXPECT_LT((r - HandRpy(rpy.x(), rpy.y(), rpy.z())).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
  }
}

constexpr char kRobot[] = R"(<?xml version="1.0"?>
<robot name="r">
  <link name="base">
    <visual><geometry><mesh filename="package://p/v.stl"/></geometry></visual>
    <collision name="hull">
      <origin xyz="1 2 3" rpy="0.1 0.2 0.3"/>
      <geometry><mesh filename="package://p/m.off" scale="2 -1 0.5"/></geometry>
    </collision>
    <collision><geometry><box size="1 2 3"/></geometry></collision>
  </link>
  <link name="eye"><visual><origin xyz="0 0 1"/>
    <geometry><cylinder radius="0.5" length="2"/></geometry></visual></link>
  <link name="ball"><collision><geometry><sphere radius="0.25"/></geometry></collision></link>
  <link name="cone"><collision><geometry><cone radius="1" length="2"/></geometry>
    </collision></link>
  <link name="empty"/>
  <link name="capsules"><collision><geometry><capsule radius="0.1" length="0.4"/></geometry>
    </collision><collision><geometry><drake:capsule radius="0.2" length="0.3"/></geometry>
    </collision></link>
  <joint name="j" type="fixed"><parent link="base"/><child link="eye"/></joint>
</robot>
)";

TEST(UrdfParse, ReadsCollisionsVisualFallbackOriginsAndEveryShape) {
  const absl::StatusOr<UrdfRobot> robot = ParseUrdf(kRobot);
  ASSERT_TRUE(robot.ok()) << robot.status();
  EXPECT_EQ(robot->name, "r");
  ASSERT_EQ(robot->links.size(), 6u);

  const UrdfLink& base = robot->links[0];
  EXPECT_EQ(base.name, "base");
  EXPECT_FALSE(base.from_visual);  // collisions win over the visual
  ASSERT_EQ(base.elements.size(), 2u);
  const UrdfElement& hull = base.elements[0];
  EXPECT_EQ(hull.name, "hull");
  EXPECT_EQ(hull.line, 5);
  EXPECT_EQ(hull.geometry.shape, UrdfShape::kMesh);
  EXPECT_EQ(hull.geometry.filename, "package://p/m.off");
  EXPECT_EQ(hull.geometry.scale, Vector3(2, -1, 0.5));
  EXPECT_EQ(hull.origin.xyz, Vector3(1, 2, 3));
  EXPECT_EQ(hull.origin.rpy, Vector3(0.1, 0.2, 0.3));
  EXPECT_EQ(base.elements[1].geometry.shape, UrdfShape::kBox);
  EXPECT_EQ(base.elements[1].geometry.size, Vector3(1, 2, 3));
  EXPECT_EQ(base.elements[1].origin.xyz, Vector3::Zero());

  const UrdfLink& eye = robot->links[1];
  EXPECT_TRUE(eye.from_visual);
  ASSERT_EQ(eye.elements.size(), 1u);
  EXPECT_EQ(eye.elements[0].geometry.shape, UrdfShape::kCylinder);
  EXPECT_EQ(eye.elements[0].geometry.radius, 0.5);
  EXPECT_EQ(eye.elements[0].geometry.length, 2.0);
  EXPECT_EQ(eye.elements[0].origin.xyz, Vector3(0, 0, 1));

  EXPECT_EQ(robot->links[2].elements.at(0).geometry.shape, UrdfShape::kSphere);
  EXPECT_EQ(robot->links[2].elements.at(0).geometry.radius, 0.25);
  EXPECT_EQ(robot->links[3].elements.at(0).geometry.shape, UrdfShape::kUnsupported);
  EXPECT_EQ(robot->links[3].elements.at(0).geometry.unsupported, "cone");
  EXPECT_TRUE(robot->links[4].elements.empty());
  // Capsules as urdfdom and Drake write them: the cylinder's length between the caps' centres.
  const UrdfLink& capsules = robot->links.at(5);
  ASSERT_EQ(capsules.elements.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(capsules.elements[i].geometry.shape, UrdfShape::kCapsule) << i;
  }
  EXPECT_EQ(capsules.elements[0].geometry.radius, 0.1);
  EXPECT_EQ(capsules.elements[0].geometry.length, 0.4);
  EXPECT_EQ(capsules.elements[1].geometry.radius, 0.2);
  EXPECT_EQ(capsules.elements[1].geometry.length, 0.3);
}

// The message of ParseUrdf's error for `urdf`, which must fail with INVALID_ARGUMENT.
std::string ParseError(const std::string& urdf) {
  const absl::StatusOr<UrdfRobot> robot = ParseUrdf(urdf);
  EXPECT_FALSE(robot.ok()) << urdf;
  if (robot.ok()) return "";
  EXPECT_EQ(robot.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(robot.status().message());
}

std::string OneLink(const std::string& body) {
  return "<robot name=\"r\">\n<link name=\"a\">\n" + body + "\n</link>\n</robot>\n";
}

std::string MeshCollision(const std::string& attributes, const std::string& origin = "") {
  return "<collision>" + origin + "<geometry><mesh " + attributes + "/></geometry></collision>";
}

TEST(UrdfParse, ErrorsNameTheLineTheLinkAndTheProblem) {
  EXPECT_THAT(ParseError("<robot>\n<link name=\"a\">\n</robot>"), HasSubstr("not well-formed XML"));
  EXPECT_THAT(ParseError(std::string("\x89PNG\r\n\x1a\n\0\0garbage", 16)), HasSubstr("NUL"));
  EXPECT_THAT(ParseError("\x01\x02garbage<<<"), HasSubstr("XML"));
  EXPECT_THAT(ParseError(""), HasSubstr("XML"));
  EXPECT_THAT(ParseError("<sdf version=\"1.6\"/>"), HasSubstr("<sdf>, not <robot>"));
  // tinyxml2 alone takes text and elements beside the root (found by fuzz_urdf).
  EXPECT_THAT(ParseError("<robot name=\"r\"/>\n\"/></geometry>"),
              HasSubstr("line 2: not well-formed XML: text '\"/>' outside the root element"));
  EXPECT_THAT(ParseError("junk\n<robot name=\"r\"/>"), HasSubstr("line 1: not well-formed XML"));
  // tinyxml2 alone turns an unknown entity into stale bytes (found by fuzz_urdf).
  EXPECT_THAT(ParseError("<robot name=\"r\">\n<link name=\"a&amp;b&gp;c\"/>\n</robot>"),
              HasSubstr("line 2: <link name>: '&gp;' is not an XML entity"));
  EXPECT_THAT(ParseError("<robot name=\"r\">\n<joint name=\"R & D\"/>\n</robot>"),
              HasSubstr("line 2: <joint name>: '& D' is not an XML entity"));
  EXPECT_THAT(ParseError("<robot name=\"r\">\n<material>A &copy; B</material>\n</robot>"),
              HasSubstr("line 2: text in <material>: '&copy;'"));
  const absl::StatusOr<UrdfRobot> entities = ParseUrdf(
      "<robot name=\"&lt;&gt;&amp;&quot;&apos;&#49;&#x32;\"><link name=\"a\">"
      "<!-- & --><![CDATA[ & ]]></link></robot>");
  ASSERT_TRUE(entities.ok()) << entities.status();
  EXPECT_EQ(entities->name, "<>&\"'12");
  EXPECT_THAT(ParseError("<robot name=\"r\"/>\n<robot name=\"s\"/>"),
              HasSubstr("line 2: not well-formed XML: a second top-level element <robot>"));
  EXPECT_THAT(ParseError("<robot>\n<xacro:include filename=\"x.xacro\"/>\n</robot>"),
              HasSubstr("line 2: <xacro:include> is unexpanded xacro"));
  // A robot.urdf.xacro as distributed: the namespace declared on <robot>, xacro elements inside.
  EXPECT_THAT(ParseError("<?xml version=\"1.0\"?>\n"
                         "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\" name=\"arm\">\n"
                         "  <xacro:property name=\"width\" value=\"0.2\"/>\n"
                         "  <xacro:macro name=\"leg\" params=\"prefix\"><link name=\"${prefix}\"/>"
                         "</xacro:macro>\n"
                         "  <xacro:leg prefix=\"right\"/>\n</robot>"),
              AllOf(HasSubstr("line 3: <xacro:property> is unexpanded xacro"),
                    HasSubstr("xacro robot.urdf.xacro > robot.urdf")));
  EXPECT_THAT(
      ParseError("<robot xmlns:x=\"http://ros.org/wiki/xacro\">\n<x:include filename=\"a\"/>"
                 "\n</robot>"),
      AllOf(HasSubstr("line 2: <x:include> is unexpanded xacro"),
            HasSubstr("xacro robot.urdf.xacro > robot.urdf")));
  EXPECT_THAT(ParseError("<robot>\n<link/>\n</robot>"),
              HasSubstr("line 2: <link> has no name attribute"));
  EXPECT_THAT(ParseError("<robot>\n<link name=\"a\"/>\n<link name=\"a\"/>\n</robot>"),
              HasSubstr("line 3: link name 'a' is used twice"));
  EXPECT_THAT(ParseError(OneLink(MeshCollision("filename=\"m.off\"", "<origin xyz=\"nan 0 0\"/>"))),
              HasSubstr("line 3: <origin xyz=\"nan 0 0\">: 'nan' is not finite (link 'a')"));
  EXPECT_THAT(ParseError(OneLink(MeshCollision("filename=\"m.off\"", "<origin rpy=\"0 1\"/>"))),
              HasSubstr("expected 3 numbers, found 2"));
  EXPECT_THAT(
      ParseError(OneLink(MeshCollision("filename=\"m.off\"", "<origin xyz=\"0 ${l} 0\"/>"))),
      AllOf(HasSubstr("unexpanded xacro expression"), HasSubstr("xacro robot.urdf.xacro")));
  EXPECT_THAT(ParseError(OneLink(MeshCollision("filename=\"m.off\" scale=\"1 0 1\""))),
              HasSubstr("zero component"));
  EXPECT_THAT(ParseError(OneLink(MeshCollision("filename=\"m.off\" scale=\"1 x 1\""))),
              HasSubstr("'x' is not a number"));
  EXPECT_THAT(ParseError(OneLink(MeshCollision("scale=\"1 1 1\""))),
              HasSubstr("line 3: <mesh> has no filename attribute (link 'a')"));
  EXPECT_THAT(
      ParseError(OneLink("<collision><geometry><box size=\"1 -2 3\"/></geometry></collision>")),
      HasSubstr("<box size> must be 3 positive numbers"));
  EXPECT_THAT(ParseError(OneLink("<visual><geometry>\n<cylinder radius=\"1\"/></geometry>"
                                 "</visual>")),
              HasSubstr("line 4: <cylinder> has no length attribute"));
  EXPECT_THAT(ParseError(OneLink("<collision><geometry><sphere radius=\"0\"/></geometry>"
                                 "</collision>")),
              HasSubstr("radius 0 is not positive"));
  EXPECT_THAT(ParseError(OneLink(MeshCollision("filename=\"m.off\" scale=\"1e999 1 1\""))),
              HasSubstr("not"));
}

constexpr char kJoints[] = R"(<robot name="arm">
  <link name="base"/><link name="a"/><link name="b"/><link name="c"/><link name="d"/>
  <link name="e"/><link name="f"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1" rpy="0 0.5 0"/>
    <axis xyz="0 0 2"/>
    <limit lower="-1.5" upper="2" effort="10" velocity="1"/>
    <dynamics damping="0.1"/><safety_controller k_velocity="1"/>
  </joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <axis xyz="3 4 0"/><limit lower="0" upper="0.2"/></joint>
  <joint name="wrist" type="continuous"><parent link="b"/><child link="c"/>
    <axis xyz="0 1 0"/><limit effort="1" velocity="1"/></joint>
  <joint name="finger" type="revolute"><parent link="c"/><child link="d"/>
    <mimic joint="shoulder" multiplier="-2" offset="0.25"/></joint>
  <joint name="finger2" type="revolute"><parent link="c"/><child link="e"/>
    <mimic joint="finger"/></joint>
  <joint name="tool" type="fixed"><parent link="c"/><child link="f"/><axis xyz="0 0 0"/></joint>
</robot>
)";

TEST(UrdfParse, ReadsJointsTypesLinksOriginsAxesLimitsAndMimics) {
  const absl::StatusOr<UrdfRobot> robot = ParseUrdf(kJoints);
  ASSERT_TRUE(robot.ok()) << robot.status();
  ASSERT_EQ(robot->joints.size(), 6u);
  const UrdfJoint& shoulder = robot->joints[0];
  EXPECT_EQ(shoulder.name, "shoulder");
  EXPECT_EQ(shoulder.type, UrdfJointType::kRevolute);
  EXPECT_EQ(shoulder.parent, "base");
  EXPECT_EQ(shoulder.child, "a");
  EXPECT_EQ(shoulder.origin.xyz, Vector3(0, 0, 0.1));
  EXPECT_EQ(shoulder.origin.rpy, Vector3(0, 0.5, 0));
  EXPECT_EQ(shoulder.axis, Vector3(0, 0, 1));  // normalised
  EXPECT_EQ(shoulder.lower, -1.5);
  EXPECT_EQ(shoulder.upper, 2.0);
  EXPECT_FALSE(shoulder.mimic.has_value());
  EXPECT_EQ(shoulder.line, 4);
  const UrdfJoint& slide = robot->joints[1];
  EXPECT_EQ(slide.type, UrdfJointType::kPrismatic);
  EXPECT_TRUE(slide.axis.isApprox(Vector3(0.6, 0.8, 0), 1e-15));
  EXPECT_EQ(slide.upper, 0.2);
  EXPECT_EQ(robot->joints[2].type, UrdfJointType::kContinuous);
  EXPECT_EQ(robot->joints[2].lower, 0.0);  // <limit> without lower/upper: URDF's zeros
  // A revolute joint without <limit> is accepted (urdfdom refuses it) and stays at 0.
  const UrdfJoint& finger = robot->joints[3];
  EXPECT_EQ(finger.axis, Vector3::UnitX());  // URDF's default
  EXPECT_EQ(finger.lower, 0.0);
  EXPECT_EQ(finger.upper, 0.0);
  ASSERT_TRUE(finger.mimic.has_value());
  EXPECT_EQ(finger.mimic->joint, "shoulder");
  EXPECT_EQ(finger.mimic->multiplier, -2.0);
  EXPECT_EQ(finger.mimic->offset, 0.25);
  ASSERT_TRUE(robot->joints[4].mimic.has_value());
  EXPECT_EQ(robot->joints[4].mimic->multiplier, 1.0);
  EXPECT_EQ(robot->joints[4].mimic->offset, 0.0);
  // A fixed joint's axis is not read, a zero one included.
  EXPECT_EQ(robot->joints[5].type, UrdfJointType::kFixed);
  EXPECT_EQ(robot->joints[5].axis, Vector3::UnitX());
  for (UrdfJointType type :
       {UrdfJointType::kFixed, UrdfJointType::kRevolute, UrdfJointType::kContinuous,
        UrdfJointType::kPrismatic, UrdfJointType::kFloating, UrdfJointType::kPlanar}) {
    const std::string doc =
        std::string("<robot><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" type=\"") +
        UrdfJointTypeName(type) + "\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>";
    const absl::StatusOr<UrdfRobot> one = ParseUrdf(doc);
    ASSERT_TRUE(one.ok()) << one.status();
    EXPECT_EQ(one->joints.at(0).type, type);
  }
}

std::string OneJoint(const std::string& attributes, const std::string& body) {
  return "<robot name=\"r\">\n<link name=\"a\"/><link name=\"b\"/>\n<joint " + attributes + ">\n" +
         body + "\n</joint>\n</robot>\n";
}

TEST(UrdfParse, JointErrorsNameTheLineTheJointAndTheProblem) {
  const std::string links = "<parent link=\"a\"/><child link=\"b\"/>";
  EXPECT_THAT(ParseError(OneJoint("type=\"fixed\"", links)),
              HasSubstr("line 3: <joint> has no name attribute"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\"", links)),
              HasSubstr("line 3: <joint> has no type attribute (joint 'j')"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"ball\"", links)),
              HasSubstr("line 3: <joint type=\"ball\"> is not a URDF joint type"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"fixed\"", "<child link=\"b\"/>")),
              HasSubstr("line 3: <joint> has no <parent> element (joint 'j')"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"fixed\"", "<parent link=\"a\"/>\n<child/>")),
              HasSubstr("line 5: <child> has no link attribute (joint 'j')"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"fixed\"", links + "<origin xyz=\"1 2\"/>")),
              HasSubstr("line 4: <origin xyz=\"1 2\">: expected 3 numbers, found 2 (joint 'j')"));
  for (const char* type : {"revolute", "continuous", "prismatic", "planar"}) {
    EXPECT_THAT(ParseError(OneJoint(std::string("name=\"j\" type=\"") + type + "\"",
                                    links + "\n<axis xyz=\"0 0 0\"/>")),
                HasSubstr("line 5: <axis xyz> of a " + std::string(type) + " joint is zero"));
  }
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"revolute\"", links + "<axis xyz=\"1 x 0\"/>")),
              HasSubstr("'x' is not a number (joint 'j')"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"prismatic\"",
                                  links + "\n<limit lower=\"1\" upper=\"0.5\"/>")),
              HasSubstr("line 5: <limit lower=\"1\" upper=\"0.5\">: lower > upper (joint 'j')"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"revolute\"",
                                  links + "<limit lower=\"inf\" upper=\"1\"/>")),
              HasSubstr("'inf' is not finite"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"revolute\"", links + "\n<mimic/>")),
              HasSubstr("line 5: <mimic> has no joint attribute (joint 'j')"));
  EXPECT_THAT(ParseError(OneJoint("name=\"j\" type=\"revolute\"",
                                  links + "<mimic joint=\"k\" multiplier=\"two\"/>")),
              HasSubstr("'two' is not a number"));
  // Continuous joints do not use their limits: lower > upper there is no error.
  EXPECT_TRUE(ParseUrdf(OneJoint("name=\"j\" type=\"continuous\"",
                                 links + "<limit lower=\"1\" upper=\"0\"/>"))
                  .ok());
}

class UrdfResolve : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("inscribe_urdf_resolve_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    for (const char* file : {"ws/arm/meshes/link.stl", "solo/meshes/s.off",
                             "install/share/ament_pkg/m.obj", "robot/local.off"}) {
      fs::create_directories((root_ / file).parent_path());
      std::ofstream(root_ / file) << "x";
    }
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string Path(const std::string& relative) const {
    return (root_ / relative).lexically_normal().string();
  }
  std::string UrdfDir() const { return Path("robot"); }

  fs::path root_;
};

TEST_F(UrdfResolve, PackageUrisAreFoundInPackagePathsRosPackagePathAndAmentPrefixes) {
  PackageSearch search;
  search.package_paths = {Path("nowhere"), Path("ws")};
  EXPECT_EQ(*ResolveMeshFilename("package://arm/meshes/link.stl", UrdfDir(), search),
            Path("ws/arm/meshes/link.stl"));
  // A directory that is itself the package.
  search.package_paths = {Path("solo") + "/"};
  EXPECT_EQ(*ResolveMeshFilename("package://solo/meshes/s.off", UrdfDir(), search),
            Path("solo/meshes/s.off"));

  ::setenv("ROS_PACKAGE_PATH", (Path("nowhere") + "::" + Path("ws")).c_str(), 1);
  ::setenv("AMENT_PREFIX_PATH", Path("install").c_str(), 1);
  const PackageSearch from_environment = PackageSearchFromEnvironment({});
  ::unsetenv("ROS_PACKAGE_PATH");
  ::unsetenv("AMENT_PREFIX_PATH");
  EXPECT_EQ(from_environment.ros_package_path.size(), 2u);  // the empty entry is dropped
  EXPECT_EQ(*ResolveMeshFilename("package://arm/meshes/link.stl", UrdfDir(), from_environment),
            Path("ws/arm/meshes/link.stl"));
  EXPECT_EQ(*ResolveMeshFilename("package://ament_pkg/m.obj", UrdfDir(), from_environment),
            Path("install/share/ament_pkg/m.obj"));
}

TEST_F(UrdfResolve, FileUrisAndPlainPathsAreAbsoluteOrRelativeToTheUrdf) {
  const PackageSearch none;
  EXPECT_EQ(*ResolveMeshFilename("file://" + Path("solo/meshes/s.off"), UrdfDir(), none),
            Path("solo/meshes/s.off"));
  EXPECT_EQ(*ResolveMeshFilename("file://local.off", UrdfDir(), none), Path("robot/local.off"));
  EXPECT_EQ(*ResolveMeshFilename("local.off", UrdfDir(), none), Path("robot/local.off"));
  EXPECT_EQ(*ResolveMeshFilename("../solo/meshes/s.off", UrdfDir(), none),
            Path("solo/meshes/s.off"));
  EXPECT_EQ(*ResolveMeshFilename(Path("ws/arm/meshes/link.stl"), UrdfDir(), none),
            Path("ws/arm/meshes/link.stl"));
}

TEST_F(UrdfResolve, FailuresSayWhatWasLookedFor) {
  PackageSearch search;
  search.package_paths = {Path("ws")};
  const absl::StatusOr<std::string> unknown =
      ResolveMeshFilename("package://leg/m.stl", UrdfDir(), search);
  EXPECT_EQ(unknown.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(unknown.status().message(), HasSubstr("package 'leg'"));
  EXPECT_THAT(unknown.status().message(), HasSubstr(Path("ws")));
  EXPECT_THAT(ResolveMeshFilename("package://leg/m.stl", UrdfDir(), {}).status().message(),
              HasSubstr("--package-path"));

  const absl::StatusOr<std::string> missing =
      ResolveMeshFilename("package://arm/meshes/gone.stl", UrdfDir(), search);
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr(Path("ws/arm/meshes/gone.stl")));
  EXPECT_EQ(ResolveMeshFilename("gone.off", UrdfDir(), search).status().code(),
            absl::StatusCode::kNotFound);
  // A directory is not a mesh file.
  EXPECT_EQ(ResolveMeshFilename("package://arm/meshes", UrdfDir(), search).status().code(),
            absl::StatusCode::kNotFound);

  EXPECT_THAT(ResolveMeshFilename("model://arm/m.stl", UrdfDir(), search).status().message(),
              HasSubstr("URI scheme 'model' is not supported"));
  EXPECT_EQ(ResolveMeshFilename("package://arm", UrdfDir(), search).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(ResolveMeshFilename("file://", UrdfDir(), search).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(PrimitiveMeshes, BoxIsAnExactValidSolid) {
  const Vector3 size(0.2, 0.5, 1.5);
  const ValidatedMesh box = ValidateMesh(BoxMesh(size));
  EXPECT_TRUE(box.report.usable()) << box.report.first_error();
  EXPECT_EQ(box.report.flipped_triangles, 0);  // outward as built
  EXPECT_EQ(box.report.triangles, 12);
  EXPECT_NEAR(box.report.volume, size.prod(), 1e-15);
  EXPECT_TRUE(box.report.bbox.max.isApprox(size / 2, 1e-15));
  EXPECT_TRUE(box.report.bbox.min.isApprox(-size / 2, 1e-15));
}

TEST(PrimitiveMeshes, CylinderIsAValidPrismInsideTheCylinder) {
  for (int sides : {3, 7, kCylinderSides}) {
    SCOPED_TRACE(sides);
    const double radius = 0.3, length = 1.2;
    const ValidatedMesh cylinder = ValidateMesh(CylinderMesh(radius, length, sides));
    EXPECT_TRUE(cylinder.report.usable()) << cylinder.report.first_error();
    EXPECT_EQ(cylinder.report.flipped_triangles, 0);
    EXPECT_EQ(cylinder.report.triangles, 4 * sides);
    // The regular n-gon's area is n r^2 sin(2 pi / n) / 2.
    const double prism = 0.5 * sides * radius * radius * std::sin(2 * M_PI / sides) * length;
    EXPECT_NEAR(cylinder.report.volume, prism, 1e-12);
    EXPECT_LT(cylinder.report.volume, M_PI * radius * radius * length);
    EXPECT_NEAR(cylinder.report.bbox.max.z(), length / 2, 1e-15);
    EXPECT_LE(cylinder.report.bbox.max.head<2>().norm(), radius * std::sqrt(2.0));
  }
  // 64 sides: within 0.11% of the true cylinder's volume.
  const double ratio = ValidateMesh(CylinderMesh(1.0, 1.0)).report.volume / M_PI;
  EXPECT_GT(ratio, 0.998);
}

}  // namespace
}  // namespace inscribe::robot
