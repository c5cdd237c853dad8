// The MJCF reader (mjcf_robot.h): what it makes of a model (links, chains of joints, classes,
// which geoms are the solid), and every refusal naming the file, line, element and attribute.
#include "inscribe/robot/mjcf_robot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/robot/mjcf_orientation.h"
#include "inscribe/robot/primitive_meshes.h"
#include "inscribe/solid/mesh_validation.h"
#include "mjcf_test_models.h"

namespace inscribe::robot {
namespace {

using mjcf_models::FreshFolder;
using mjcf_models::WriteArm;
using mjcf_models::WriteText;
using ::testing::AllOf;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

int LinkIndex(const UrdfRobot& robot, const std::string& name) {
  for (std::size_t l = 0; l < robot.links.size(); ++l) {
    if (robot.links[l].name == name) return static_cast<int>(l);
  }
  return -1;
}

TEST(MjcfRead, ArmBodiesJointsAndSolidGeoms) {
  const std::string folder = FreshFolder("mjcf_read_arm");
  absl::StatusOr<MjcfModel> model = ReadMjcf(WriteArm(folder));
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->robot.name, "arm");
  // world, base, shoulder, upper, fore, hand, camera_mount.
  ASSERT_EQ(model->bodies.size(), 7u);
  EXPECT_EQ(model->bodies[0].name, "world");
  EXPECT_EQ(model->bodies[1].name, "base");
  EXPECT_EQ(model->bodies[6].name, "camera_mount");
  // upper has a hinge and a slide: one link between them; fore's ball: two.
  EXPECT_GE(LinkIndex(model->robot, "upper/shoulder_lift"), 0);
  EXPECT_GE(LinkIndex(model->robot, "fore/elbow/x"), 0);
  EXPECT_GE(LinkIndex(model->robot, "fore/elbow/y"), 0);
  EXPECT_EQ(model->robot.links.size(), 7u + 1u + 2u);
  const MjcfJoint& pan = model->joints[0];
  EXPECT_EQ(pan.name, "shoulder_pan");
  EXPECT_NEAR(pan.ref, 10 * M_PI / 180, 1e-15);
  const UrdfJoint& pan_coordinate =
      model->robot.joints[static_cast<std::size_t>(pan.coordinates[0])];
  // The class's range (-90, 90) degrees, less ref; the joint's anchor.
  EXPECT_EQ(pan_coordinate.type, UrdfJointType::kRevolute);
  EXPECT_NEAR(pan_coordinate.lower, -100 * M_PI / 180, 1e-15);
  EXPECT_NEAR(pan_coordinate.upper, 80 * M_PI / 180, 1e-15);
  EXPECT_EQ(pan_coordinate.anchor, Vector3(0.01, 0, 0));
  const MjcfJoint& wrist = model->joints.back();
  EXPECT_EQ(wrist.name, "wrist");
  EXPECT_EQ(model->robot.joints[static_cast<std::size_t>(wrist.coordinates[0])].type,
            UrdfJointType::kContinuous);
  // The base's solid is its collision cylinder, not its visual mesh; the floor is no solid;
  // camera_mount has visual geoms only, which stand in with a warning.
  const UrdfLink& base = model->robot.links[static_cast<std::size_t>(model->bodies[1].link)];
  ASSERT_EQ(base.elements.size(), 1u);
  EXPECT_EQ(base.elements[0].geometry.shape, UrdfShape::kCylinder);
  EXPECT_FALSE(base.from_visual);
  const UrdfLink& mount = model->robot.links[static_cast<std::size_t>(model->bodies[6].link)];
  EXPECT_TRUE(mount.from_visual);
  EXPECT_EQ(mount.elements.size(), 1u);
  EXPECT_THAT(model->warnings, ::testing::Contains(HasSubstr("'camera_mount'")));
  EXPECT_THAT(model->warnings, ::testing::Contains(HasSubstr("'floor'")));
  // The shell mesh: its class's scale, its path under meshdir.
  for (const MjcfGeom& geom : model->geoms) {
    if (geom.name == "shoulder_shell") {
      EXPECT_EQ(geom.element.geometry.scale, Vector3(1.5, 0.75, 2));
      EXPECT_EQ(fs::path(geom.element.geometry.filename).filename(), "shell.stl");
      EXPECT_EQ(geom.class_name, "visual");
      EXPECT_FALSE(geom.solid);
    }
    if (geom.name == "pad") {
      EXPECT_EQ(geom.element.geometry.shape, UrdfShape::kBox);
      EXPECT_EQ(geom.element.geometry.size, Vector3(0.02, 0.04, 0.06));  // pad's half sizes x2
      EXPECT_EQ(geom.group, 3);
      EXPECT_TRUE(geom.solid);
    }
  }
}

TEST(MjcfRead, SelectionByClassOrGroupOverridesContacts) {
  const std::string folder = FreshFolder("mjcf_read_select");
  MjcfReadOptions visual;
  visual.solid.classes = {"visual"};
  absl::StatusOr<MjcfModel> model = ReadMjcf(WriteArm(folder), visual);
  ASSERT_TRUE(model.ok()) << model.status();
  const UrdfLink& base = model->robot.links[static_cast<std::size_t>(model->bodies[1].link)];
  ASSERT_EQ(base.elements.size(), 1u);
  EXPECT_EQ(base.elements[0].geometry.shape, UrdfShape::kMesh);
  // By group 3 the pad (class pad, inheriting collision's group) is chosen in the hand.
  MjcfReadOptions group;
  group.solid.groups = {3};
  model = ReadMjcf(folder + "/arm.xml", group);
  ASSERT_TRUE(model.ok()) << model.status();
  const UrdfLink& hand = model->robot.links[static_cast<std::size_t>(model->bodies[5].link)];
  ASSERT_EQ(hand.elements.size(), 1u);
  EXPECT_EQ(hand.elements[0].name, "pad");
  // A class inherited from counts: "arm" holds every geom below the base.
  MjcfReadOptions arm;
  arm.solid.classes = {"arm"};
  model = ReadMjcf(folder + "/arm.xml", arm);
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->robot.links[static_cast<std::size_t>(model->bodies[1].link)].elements.size(),
            2u);
}

TEST(MjcfRead, UnnamedBodiesAndJointsGetNamesNoOtherHas) {
  const std::string folder = FreshFolder("mjcf_read_names");
  WriteText(folder + "/m.xml", R"(<mujoco>
  <worldbody>
    <body name="body2"><joint/><geom size="0.1"/>
      <body><joint/><joint/><geom size="0.1"/></body>
    </body>
  </worldbody>
</mujoco>)");
  absl::StatusOr<MjcfModel> model = ReadMjcf(folder + "/m.xml");
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->bodies.size(), 3u);
  EXPECT_EQ(model->bodies[1].name, "body2");
  EXPECT_EQ(model->bodies[2].name, "body2_2");  // "body2" is taken by the written name
  EXPECT_EQ(model->joints[1].name, "body2_2_joint0");
  EXPECT_EQ(model->joints[2].name, "body2_2_joint1");
  std::set<std::string> links;
  for (const UrdfLink& link : model->robot.links) EXPECT_TRUE(links.insert(link.name).second);
}

TEST(MjcfOrientation, ZAxisIsTheSmallestTurnAndAHalfTurnAboutXForMinusZ) {
  absl::StatusOr<Eigen::Matrix3d> down = MjcfZAxisRotation(Vector3(0, 0, -2));
  ASSERT_TRUE(down.ok());
  EXPECT_TRUE(down->isApprox(Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix(), 1e-15));
  absl::StatusOr<Eigen::Matrix3d> tilted = MjcfZAxisRotation(Vector3(1, 0, 1));
  ASSERT_TRUE(tilted.ok());
  EXPECT_TRUE(tilted->isApprox(Eigen::AngleAxisd(M_PI / 4, Vector3::UnitY()).toRotationMatrix()));
  EXPECT_FALSE(MjcfZAxisRotation(Vector3::Zero()).ok());
}

TEST(MjcfOrientation, EulerLowerCaseTurnsAboutMovedAxesUpperCaseAboutFixedOnes) {
  const Vector3 a(0.3, -0.7, 1.1);
  const Eigen::Matrix3d x = Eigen::AngleAxisd(a[0], Vector3::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d y = Eigen::AngleAxisd(a[1], Vector3::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d z = Eigen::AngleAxisd(a[2], Vector3::UnitZ()).toRotationMatrix();
  EXPECT_TRUE(MjcfEulerRotation(a, "xyz")->isApprox(x * y * z, 1e-14));
  EXPECT_TRUE(MjcfEulerRotation(a, "XYZ")->isApprox(z * y * x, 1e-14));
  EXPECT_TRUE(MjcfEulerRotation(a, "xYz")->isApprox(y * x * z, 1e-14));
  EXPECT_FALSE(MjcfEulerRotation(a, "xyw").ok());
  EXPECT_FALSE(MjcfEulerRotation(a, "xy").ok());
}

// Capsules and ellipsoids: closed, outward, every vertex on the true surface, the volume just
// under the true one (the mesh is inscribed).
TEST(MjcfPrimitives, CapsuleAndEllipsoidMeshesAreInscribedClosedSolids) {
  for (const auto& [radius, length] : {std::pair{0.03, 0.2}, std::pair{0.5, 0.01}}) {
    const Mesh mesh = CapsuleMesh(radius, length);
    const ValidatedMesh capsule = ValidateMesh(mesh);
    ASSERT_TRUE(capsule.report.usable()) << capsule.report.first_error();
    EXPECT_EQ(capsule.report.flipped_triangles, 0);
    EXPECT_EQ(mesh.vertices.rows(), 2 * kQuarterBands * kCylinderSides + 2);
    const double h = length / 2;
    for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
      const Vector3 v = mesh.vertices.row(i).transpose();
      const Vector3 axis_point(0, 0, std::clamp(v.z(), -h, h));
      EXPECT_NEAR((v - axis_point).norm(), radius, 1e-15);
    }
    const double truth = M_PI * radius * radius * (length + 4.0 / 3.0 * radius);
    EXPECT_LT(capsule.report.volume, truth);
    EXPECT_GT(capsule.report.volume, 0.995 * truth);
  }
  const Vector3 radii(0.3, 0.1, 0.2);
  const Mesh mesh = EllipsoidMesh(radii);
  const ValidatedMesh ellipsoid = ValidateMesh(mesh);
  ASSERT_TRUE(ellipsoid.report.usable()) << ellipsoid.report.first_error();
  EXPECT_EQ(ellipsoid.report.flipped_triangles, 0);
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    EXPECT_NEAR(mesh.vertices.row(i).transpose().cwiseQuotient(radii).norm(), 1.0, 1e-15);
  }
  const double truth = 4.0 / 3.0 * M_PI * radii.prod();
  EXPECT_LT(ellipsoid.report.volume, truth);
  EXPECT_GT(ellipsoid.report.volume, 0.995 * truth);
}

// A model file `text` in a fresh folder, read; the error's message.
std::string ErrorOf(const std::string& name, const std::string& text) {
  const std::string folder = FreshFolder(absl::StrCat("mjcf_error_", name));
  WriteText(folder + "/model.xml", text);
  absl::StatusOr<MjcfModel> model = ReadMjcf(folder + "/model.xml");
  EXPECT_FALSE(model.ok()) << name;
  if (model.ok()) return "";
  EXPECT_EQ(model.status().code(), absl::StatusCode::kInvalidArgument) << model.status();
  return std::string(model.status().message());
}

std::string InBody(const std::string& inner) {
  return absl::StrCat("<mujoco>\n<worldbody>\n<body name=\"b\">\n", inner,
                      "\n</body>\n</worldbody>\n</mujoco>\n");
}

TEST(MjcfErrors, NameFileLineElementAndAttribute) {
  EXPECT_THAT(ErrorOf("type", InBody(R"(<geom type="cone" size="1"/>)")),
              AllOf(HasSubstr("model.xml line 4"), HasSubstr("<geom type=\"cone\">"),
                    HasSubstr("not a MuJoCo geom type")));
  EXPECT_THAT(ErrorOf("joint_type", InBody(R"(<joint type="screw"/>)")),
              HasSubstr("not a MuJoCo joint type"));
  EXPECT_THAT(ErrorOf("number", InBody(R"(<geom size="0.1" pos="0 zero 0"/>)")),
              AllOf(HasSubstr("line 4"), HasSubstr("pos=\"0 zero 0\""), HasSubstr("'zero'")));
  EXPECT_THAT(ErrorOf("count", InBody(R"(<geom size="0.1" pos="0 0"/>)")),
              HasSubstr("expected 3 numbers, found 2"));
  EXPECT_THAT(ErrorOf("nan", InBody(R"(<geom size="0.1" pos="0 nan 0"/>)")),
              HasSubstr("not finite"));
  EXPECT_THAT(
      ErrorOf("two_orientations", InBody(R"(<geom size="0.1" quat="1 0 0 0" euler="0 0 1"/>)")),
      HasSubstr("several orientations (quat, euler)"));
  EXPECT_THAT(ErrorOf("zero_quat", InBody(R"(<geom size="0.1" quat="0 0 0 0"/>)")),
              HasSubstr("quaternion is zero"));
  EXPECT_THAT(ErrorOf("size", InBody(R"(<geom type="box" size="0.1 0.2"/>)")),
              HasSubstr("needs 3 positive sizes"));
  EXPECT_THAT(
      ErrorOf("fromto_pos",
              InBody(R"(<geom type="capsule" size="0.1" pos="0 0 0" fromto="0 0 0 1 0 0"/>)")),
      HasSubstr("both pos and fromto"));
  EXPECT_THAT(ErrorOf("fromto_sphere", InBody(R"(<geom size="0.1" fromto="0 0 0 1 0 0"/>)")),
              HasSubstr("not a sphere"));
  EXPECT_THAT(
      ErrorOf("fromto_same", InBody(R"(<geom type="capsule" size="0.1" fromto="1 0 0 1 0 0"/>)")),
      HasSubstr("coincide"));
  EXPECT_THAT(ErrorOf("class", InBody(R"(<geom class="nothing" size="0.1"/>)")),
              HasSubstr("no <default class=\"nothing\">"));
  EXPECT_THAT(
      ErrorOf("childclass", "<mujoco><worldbody><body childclass=\"x\"/></worldbody></mujoco>"),
      HasSubstr("<body childclass=\"x\">"));
  EXPECT_THAT(ErrorOf("mesh_missing", InBody(R"(<geom type="mesh" mesh="m"/>)")),
              HasSubstr("no <mesh> asset has that name"));
  EXPECT_THAT(ErrorOf("range", InBody(R"(<joint range="10 -10"/>)")),
              HasSubstr("lower limit is above the upper"));
  EXPECT_THAT(ErrorOf("limited", InBody(R"(<joint limited="yes"/>)")),
              HasSubstr("expected true, false or auto"));
  EXPECT_THAT(ErrorOf("axis", InBody(R"(<joint axis="0 0 0"/>)")), HasSubstr("the axis is zero"));
  EXPECT_THAT(ErrorOf("free", R"(<mujoco><worldbody><body name="a"><body name="b"><freejoint/>
</body></body></worldbody></mujoco>)"),
              HasSubstr("not a child of the world body"));
  EXPECT_THAT(
      ErrorOf("body_twice",
              "<mujoco><worldbody><body name=\"a\"/><body name=\"a\"/></worldbody></mujoco>"),
      HasSubstr("body name 'a' is used twice"));
  EXPECT_THAT(ErrorOf("joint_twice", InBody("<joint name=\"j\"/><joint name=\"j\"/>")),
              HasSubstr("joint name 'j' is used twice"));
  EXPECT_THAT(ErrorOf("frame", InBody("<frame/>")), HasSubstr("<frame> (MuJoCo 3) is not read"));
  EXPECT_THAT(ErrorOf("fitted", R"(<mujoco><asset><mesh file="a.stl"/></asset><worldbody>
<geom type="box" mesh="a" size="1 1 1"/></worldbody></mujoco>)"),
              HasSubstr("a primitive fitted to a mesh is not read"));
}

TEST(MjcfErrors, DefaultsAndCompiler) {
  EXPECT_THAT(ErrorOf("class_twice", R"(<mujoco><default><default class="a"/>
<default class="a"/></default></mujoco>)"),
              AllOf(HasSubstr("line 2"), HasSubstr("default class 'a' is defined twice")));
  EXPECT_THAT(ErrorOf("nested_nameless", "<mujoco><default><default/></default></mujoco>"),
              HasSubstr("nested <default> has no class"));
  EXPECT_THAT(ErrorOf("top_class", "<mujoco><default class=\"x\"/></mujoco>"),
              HasSubstr("always \"main\""));
  EXPECT_THAT(ErrorOf("angle", "<mujoco><compiler angle=\"grad\"/></mujoco>"),
              HasSubstr("expected degree or radian"));
  EXPECT_THAT(ErrorOf("eulerseq", "<mujoco><compiler eulerseq=\"xyq\"/></mujoco>"),
              HasSubstr("eulerseq"));
  EXPECT_THAT(ErrorOf("global", "<mujoco><compiler coordinate=\"global\"/></mujoco>"),
              HasSubstr("only local coordinates"));
  EXPECT_THAT(
      ErrorOf("inline_mesh", "<mujoco><asset><mesh name=\"m\" vertex=\"0 0 0\"/></asset></mujoco>"),
      HasSubstr("meshes written inline are not read"));
  EXPECT_THAT(
      ErrorOf("refpos", "<mujoco><asset><mesh file=\"a.stl\" refpos=\"1 0 0\"/></asset></mujoco>"),
      HasSubstr("refpos"));
  EXPECT_THAT(ErrorOf("mesh_twice", R"(<mujoco><asset><mesh file="a.stl"/><mesh file="b/a.stl"/>
</asset></mujoco>)"),
              HasSubstr("mesh name 'a' is used twice"));
  EXPECT_THAT(
      ErrorOf("scale", "<mujoco><asset><mesh file=\"a.stl\" scale=\"1 0 1\"/></asset></mujoco>"),
      HasSubstr("zero component"));
}

TEST(MjcfErrors, GarbageAndOtherRoots) {
  EXPECT_THAT(ErrorOf("garbage", "\x01\x02 not xml <<<"), HasSubstr("not well-formed XML"));
  EXPECT_THAT(ErrorOf("urdf", "<robot name=\"r\"/>"), HasSubstr("the root element is <robot>"));
  EXPECT_THAT(ErrorOf("unclosed", "<mujoco><worldbody>"), HasSubstr("not well-formed XML"));
  absl::StatusOr<MjcfModel> nul = ParseMjcf(std::string("<mujoco>\0</mujoco>", 18), "/tmp/x.xml");
  ASSERT_FALSE(nul.ok());
  EXPECT_THAT(nul.status().message(), HasSubstr("NUL"));
}

TEST(MjcfIncludes, PathsStayInsideTheModelsFolder) {
  const std::string folder = FreshFolder("mjcf_include_paths");
  WriteText(fs::path(folder).parent_path().string() + "/inscribe_outside.xml", "<mujoco/>");
  for (const std::string& file :
       {std::string("../inscribe_outside.xml"), std::string("sub/../../inscribe_outside.xml"),
        fs::path(folder).parent_path().string() + "/inscribe_outside.xml",
        std::string("/etc/passwd")}) {
    SCOPED_TRACE(file);
    WriteText(folder + "/model.xml",
              absl::StrCat("<mujoco>\n  <include file=\"", file, "\"/>\n</mujoco>"));
    absl::StatusOr<MjcfModel> model = ReadMjcf(folder + "/model.xml");
    ASSERT_FALSE(model.ok());
    EXPECT_THAT(model.status().message(),
                AllOf(HasSubstr("line 2"), HasSubstr("leads outside the model's folder")));
  }
  // A symbolic link out of the folder is followed before the check.
  fs::create_symlink("/etc", folder + "/etc_link");
  WriteText(folder + "/model.xml", "<mujoco><include file=\"etc_link/passwd\"/></mujoco>");
  EXPECT_THAT(ReadMjcf(folder + "/model.xml").status().message(),
              HasSubstr("leads outside the model's folder"));
  // Meshes too, through meshdir.
  WriteText(folder + "/model.xml", R"(<mujoco><compiler meshdir="../"/>
<asset><mesh file="x.stl"/></asset></mujoco>)");
  EXPECT_THAT(ReadMjcf(folder + "/model.xml").status().message(),
              AllOf(HasSubstr("<mesh file=\"x.stl\">"), HasSubstr("leads outside")));
}

TEST(MjcfIncludes, CyclesRepeatsMissingFilesAndOtherRoots) {
  const std::string folder = FreshFolder("mjcf_include_cycles");
  WriteText(folder + "/a.xml", "<mujoco>\n<include file=\"b.xml\"/>\n</mujoco>");
  WriteText(folder + "/b.xml", "<mujoco>\n\n<include file=\"a.xml\"/>\n</mujoco>");
  EXPECT_THAT(ReadMjcf(folder + "/a.xml").status().message(),
              AllOf(HasSubstr("b.xml line 3"), HasSubstr("includes itself")));
  WriteText(folder + "/twice.xml",
            "<mujoco><include file=\"c.xml\"/><include file=\"./c.xml\"/></mujoco>");
  WriteText(folder + "/c.xml", "<mujoco/>");
  EXPECT_THAT(ReadMjcf(folder + "/twice.xml").status().message(), HasSubstr("included twice"));
  WriteText(folder + "/missing.xml", "<mujoco><include file=\"none.xml\"/></mujoco>");
  EXPECT_THAT(ReadMjcf(folder + "/missing.xml").status().message(), HasSubstr("does not exist"));
  WriteText(folder + "/robot.xml", "<robot/>");
  WriteText(folder + "/root.xml", "<mujoco><include file=\"robot.xml\"/></mujoco>");
  EXPECT_THAT(ReadMjcf(folder + "/root.xml").status().message(),
              AllOf(HasSubstr("robot.xml line 1"), HasSubstr("must be <mujoco>")));
  WriteText(folder + "/bad.xml", "<mujoco>\n<geom type=\"x\"/>\n</mujoco>");
  WriteText(folder + "/inner.xml",
            "<mujoco><worldbody><include file=\"bad.xml\"/></worldbody></mujoco>");
  EXPECT_THAT(ReadMjcf(folder + "/inner.xml").status().message(),
              AllOf(HasSubstr("bad.xml line 2"), HasSubstr("geom type")));
}

}  // namespace
}  // namespace inscribe::robot
