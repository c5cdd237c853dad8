// Per-link spherization of `inscribe urdf` (client/src/cli/urdf_spherize.h) and its writers
// (spherized_urdf.h), on geometry built in code.
#include "inscribe/robot/urdf_spherize.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>
#include <unistd.h>

#include <assimp/Exporter.hpp>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>

#include "inscribe/mesh_validation.h"
#include "inscribe/robot/primitive_meshes.h"
#include "inscribe/robot/spherized_urdf.h"
#include "support/assimp_scenes.h"
#include "support/synthetic_meshes.h"

namespace inscribe::robot {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(UrdfTransformMesh, ScalesThenRotatesThenTranslatesAndKeepsMirroredMeshesOutward) {
  const Mesh cube = testing::UnitCube();
  const Eigen::Matrix3d quarter_turn_z = RotationFromRpy(Vector3(0, 0, M_PI / 2));
  const Mesh moved = TransformMesh(cube, Vector3(2, 3, 4), quarter_turn_z, Vector3(10, 0, 0));
  // Vertex (1, 1, 1): scaled (2, 3, 4), turned (-3, 2, 4), moved (7, 2, 4).
  for (Eigen::Index i = 0; i < cube.vertices.rows(); ++i) {
    if (cube.vertices.row(i) == Eigen::RowVector3d(1, 1, 1)) {
      EXPECT_TRUE(moved.vertices.row(i).isApprox(Eigen::RowVector3d(7, 2, 4), 1e-15));
    }
  }
  EXPECT_NEAR(SignedVolume(moved), 24.0, 1e-12);

  for (const Vector3& mirror : {Vector3(-1, 1, 1), Vector3(-1, -1, -2), Vector3(1, 1, -0.5)}) {
    const Mesh mirrored = TransformMesh(cube, mirror, Eigen::Matrix3d::Identity(), Vector3::Zero());
    EXPECT_NEAR(SignedVolume(mirrored), std::abs(mirror.prod()), 1e-12) << mirror.transpose();
  }
  const Mesh twice =
      TransformMesh(cube, Vector3(-1, -1, 1), Eigen::Matrix3d::Identity(), Vector3::Zero());
  EXPECT_EQ(twice.triangles, cube.triangles);  // a rotation by pi, not a mirror
}

TEST(UrdfLinkSphereBudgets, SpheresTakeOneMeshesShareTheRestByVolume) {
  EXPECT_THAT(LinkSphereBudgets(32, {1.0}), ElementsAre(32));
  EXPECT_THAT(LinkSphereBudgets(32, {3.0, 1.0}), ElementsAre(24, 8));
  EXPECT_THAT(LinkSphereBudgets(10, {-1.0, 1.0, 1.0}), ElementsAre(1, 5, 4));
  EXPECT_THAT(LinkSphereBudgets(3, {1000.0, 1e-9, 1e-9}), ElementsAre(1, 1, 1));
  EXPECT_THAT(LinkSphereBudgets(2, {-1.0, -1.0}), ElementsAre(1, 1));
  EXPECT_TRUE(LinkSphereBudgets(2, {1.0, 1.0, 1.0}).empty());
  for (std::int64_t n : {4, 7, 32, 100}) {
    const std::vector<std::int64_t> budgets = LinkSphereBudgets(n, {0.3, 0.2, -1.0, 0.5});
    EXPECT_EQ(std::accumulate(budgets.begin(), budgets.end(), std::int64_t{0}), n);
  }
}

UrdfElement Element(UrdfShape shape) {
  UrdfElement element;
  element.line = 7;
  element.geometry.shape = shape;
  return element;
}

TEST(UrdfSpherizeLink, SpheresStayAsTheyAreAndBoxesGetInternalSpheresInTheLinkFrame) {
  UrdfLink link;
  link.name = "hand";
  UrdfElement ball = Element(UrdfShape::kSphere);
  ball.geometry.radius = 0.05;
  ball.origin.xyz = Vector3(0, 0, 0.3);
  ball.origin.rpy = Vector3(1, 2, 3);  // irrelevant for a sphere
  UrdfElement box = Element(UrdfShape::kBox);
  box.geometry.size = Vector3(0.1, 0.2, 0.4);
  box.origin.xyz = Vector3(1, 0, 0);
  link.elements = {ball, box};
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 12;
  const LinkSpherizeResult result = SpherizeLink(link, options);
  ASSERT_EQ(result.status, LinkStatus::kSpherized) << result.error;
  ASSERT_GE(result.spheres.size(), 2u);
  EXPECT_LE(result.spheres.size(), 12u);
  EXPECT_EQ(result.spheres[0].center, Vector3(0, 0, 0.3));
  EXPECT_EQ(result.spheres[0].radius, 0.05);
  for (std::size_t i = 1; i < result.spheres.size(); ++i) {
    const Sphere& s = result.spheres[i];
    const Vector3 lo = s.center - Vector3::Constant(s.radius),
                  hi = s.center + Vector3::Constant(s.radius);
    EXPECT_TRUE((lo.array() >= Vector3(0.95, -0.1, -0.2).array() - 1e-12).all()) << i;
    EXPECT_TRUE((hi.array() <= Vector3(1.05, 0.1, 0.2).array() + 1e-12).all()) << i;
  }
}

// A link whose collision mesh is COLLADA in centimetres, its box placed by a node: read through
// assimp, welded by validation (the importer gives each face corner its own vertex), spherized
// in the link's frame in metres.
TEST(UrdfSpherizeLink, ColladaMeshesAreReadInMetresWithTheirNodeTransforms) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("inscribe_urdf_dae_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Eigen::Matrix4d node = Eigen::Matrix4d::Identity();
  node(0, 3) = 100.0;  // cm
  const std::unique_ptr<aiScene> scene =
      testing::MakeScene({testing::Box(Vector3::Zero(), Vector3(10, 20, 40))}, {{0, node}});
  const std::string exported = (dir / "exported.dae").string();
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene.get(), "collada", exported), AI_SUCCESS)
      << exporter.GetErrorString();
  std::stringstream dae;
  dae << std::ifstream(exported).rdbuf();
  std::string text = dae.str();
  const std::size_t unit = text.find("<unit ");
  ASSERT_NE(unit, std::string::npos);
  text.replace(unit, text.find("/>", unit) + 2 - unit,
               "<unit name=\"centimeter\" meter=\"0.01\"/>");
  std::ofstream(dir / "box.DAE") << text;

  UrdfLink link;
  link.name = "arm";
  UrdfElement mesh = Element(UrdfShape::kMesh);
  mesh.geometry.filename = "box.DAE";
  mesh.origin.xyz = Vector3(0, 0, 0.5);
  link.elements = {mesh};
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 16;
  options.urdf_dir = dir.string();
  const LinkSpherizeResult result = SpherizeLink(link, options);
  fs::remove_all(dir);
  ASSERT_EQ(result.status, LinkStatus::kSpherized) << result.error;
  ASSERT_FALSE(result.spheres.empty());
  for (const Sphere& s : result.spheres) {
    const Vector3 lo = s.center - Vector3::Constant(s.radius),
                  hi = s.center + Vector3::Constant(s.radius);
    EXPECT_TRUE((lo.array() >= Vector3(1.0, 0.0, 0.5).array() - 1e-6).all()) << lo.transpose();
    EXPECT_TRUE((hi.array() <= Vector3(1.1, 0.2, 0.9).array() + 1e-6).all()) << hi.transpose();
  }
}

TEST(UrdfSpherizeLink, ProblemsSkipTheWholeLinkNamingTheElement) {
  UrdfLink link;
  link.name = "odd";
  UrdfElement box = Element(UrdfShape::kBox);
  box.geometry.size = Vector3::Ones();
  UrdfElement capsule = Element(UrdfShape::kUnsupported);
  capsule.geometry.unsupported = "capsule";
  capsule.name = "cap";
  link.elements = {box, capsule};
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 8;
  LinkSpherizeResult result = SpherizeLink(link, options);
  EXPECT_EQ(result.status, LinkStatus::kSkipped);
  EXPECT_TRUE(result.spheres.empty());
  EXPECT_THAT(result.error, HasSubstr("line 7 (<collision> 'cap'): <capsule> is not"));

  UrdfElement collada = Element(UrdfShape::kMesh);
  collada.geometry.filename = "package://arm/meshes/Link.DAE";
  link.elements = {collada};
  result = SpherizeLink(link, options);
  EXPECT_EQ(result.status, LinkStatus::kSkipped);
  EXPECT_THAT(result.error, HasSubstr("package 'arm'"));  // read like any mesh, once found

  link.elements = {box};
  options.max_spheres_per_link = 0;
  options.voxel_size = 1e-5;  // 1e15 voxels
  result = SpherizeLink(link, options);
  EXPECT_EQ(result.status, LinkStatus::kSkipped);
  EXPECT_THAT(result.error, HasSubstr("voxels"));

  link.elements.clear();
  EXPECT_EQ(SpherizeLink(link, options).status, LinkStatus::kNoGeometry);
}

TEST(SpherizedUrdf, ReplacesCollisionsOfSpherizedLinksAndAnnotatesSkippedOnes) {
  const std::string urdf = R"(<robot name="r">
  <link name="a"><visual><geometry><box size="1 1 1"/></geometry></visual>
    <collision><geometry><mesh filename="a.stl"/></geometry></collision>
    <collision><geometry><mesh filename="a2.stl"/></geometry></collision>
    <inertial><mass value="1"/></inertial></link>
  <link name="b"><visual><geometry><mesh filename="b.stl"/></geometry></visual></link>
  <link name="c"><collision><geometry><mesh filename="c.dae"/></geometry></collision></link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>)";
  // Results as SpherizeLink makes them, written by hand.
  const auto result = [](const char* link, LinkStatus status) {
    LinkSpherizeResult made;
    made.link = link;
    made.status = status;
    return made;
  };
  LinkSpherizeResult a = result("a", LinkStatus::kSpherized);
  a.spheres = {{Vector3(0.1, 0.2, 1.0 / 3.0), 0.25}, {Vector3(-1e-7, 0, 5), 1e-3}};
  LinkSpherizeResult b = result("b", LinkStatus::kSpherized);
  b.from_visual = true;
  b.spheres = {{Vector3(1, 2, 3), 0.5}};
  LinkSpherizeResult c = result("c", LinkStatus::kSkipped);
  c.error = "line 7: bad -- really";
  const absl::StatusOr<std::string> written = SpherizedUrdf(urdf, {a, b, c});
  ASSERT_TRUE(written.ok()) << written.status();

  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.Parse(written->c_str()), tinyxml2::XML_SUCCESS) << *written;
  const tinyxml2::XMLElement* link_a = document.RootElement()->FirstChildElement("link");
  int collisions = 0;
  for (const tinyxml2::XMLElement* e = link_a->FirstChildElement("collision"); e != nullptr;
       e = e->NextSiblingElement("collision"), ++collisions) {
    const tinyxml2::XMLElement* sphere = e->FirstChildElement("geometry")->FirstChildElement();
    EXPECT_STREQ(sphere->Name(), "sphere");
    double x, y, z;
    ASSERT_EQ(
        std::sscanf(e->FirstChildElement("origin")->Attribute("xyz"), "%lf %lf %lf", &x, &y, &z),
        3);
    EXPECT_EQ(Vector3(x, y, z), a.spheres[collisions].center);  // bit-exact round trip
    EXPECT_EQ(sphere->DoubleAttribute("radius"), a.spheres[collisions].radius);
  }
  EXPECT_EQ(collisions, 2);
  EXPECT_NE(link_a->FirstChildElement("visual"), nullptr);
  EXPECT_NE(link_a->FirstChildElement("inertial"), nullptr);
  const tinyxml2::XMLElement* link_b = link_a->NextSiblingElement("link");
  EXPECT_NE(link_b->FirstChildElement("visual"), nullptr);
  EXPECT_NE(link_b->FirstChildElement("collision"), nullptr);
  EXPECT_THAT(*written, HasSubstr("inscribe urdf: 1 spheres in place of the link's visual"));
  const tinyxml2::XMLElement* link_c = link_b->NextSiblingElement("link");
  EXPECT_STREQ(link_c->FirstChildElement("collision")
                   ->FirstChildElement("geometry")
                   ->FirstChildElement("mesh")
                   ->Attribute("filename"),
               "c.dae");
  EXPECT_THAT(*written,
              HasSubstr("not spherized, geometry kept as it was: line 7: bad - - really"));
  EXPECT_NE(document.RootElement()->FirstChildElement("joint"), nullptr);

  LinkSpherizeResult colon = result("d:e", LinkStatus::kSpherized);
  colon.spheres = {{Vector3(1, 2, 3), 0.5}};
  std::vector<std::string> left_out;
  const std::string yaml = SpherizedCuroboYaml({a, b, c, colon}, "r", &left_out);
  EXPECT_THAT(yaml, HasSubstr("collision_spheres:\n  \"a\":\n"));
  EXPECT_THAT(yaml, HasSubstr("\n  \"b\":\n"));
  EXPECT_THAT(yaml, ::testing::Not(HasSubstr("  c:")));
  EXPECT_THAT(left_out, ElementsAre("d:e"));
}

}  // namespace
}  // namespace inscribe::robot
