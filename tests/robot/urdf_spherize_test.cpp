// Per-link spherization of `inscribe urdf` (client/src/cli/urdf_spherize.h) and its writers
// (spherized_urdf.h), on geometry built in code.
#include "inscribe/robot/urdf_spherize.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>
#include <unistd.h>

#include <assimp/Exporter.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>

#include "inscribe/robot/primitive_meshes.h"
#include "inscribe/robot/spherized_urdf.h"
#include "inscribe/solid/mesh_validation.h"
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

// A robot of the given links and no joints.
UrdfRobot RobotOf(std::vector<UrdfLink> links) {
  UrdfRobot robot;
  robot.name = "r";
  robot.links = std::move(links);
  return robot;
}

UrdfLink LinkOf(const char* name, std::vector<UrdfElement> elements) {
  UrdfLink link;
  link.name = name;
  link.elements = std::move(elements);
  return link;
}

LinkSpherizeResult SpherizeOne(const UrdfLink& link, const UrdfSpherizeOptions& options) {
  absl::StatusOr<RobotSpherizeResult> result = SpherizeRobot(RobotOf({link}), options);
  EXPECT_TRUE(result.ok()) << result.status();
  return result.ok() ? result->links.at(0) : LinkSpherizeResult{};
}

UrdfElement Ball(const Vector3& centre, double radius) {
  UrdfElement ball = Element(UrdfShape::kSphere);
  ball.geometry.radius = radius;
  ball.origin.xyz = centre;
  ball.origin.rpy = Vector3(1, 2, 3);  // irrelevant for a sphere
  return ball;
}

UrdfElement BoxAt(const Vector3& size, const Vector3& centre) {
  UrdfElement box = Element(UrdfShape::kBox);
  box.geometry.size = size;
  box.origin.xyz = centre;
  return box;
}

TEST(UrdfSpherizeRobot, SpheresStayAsTheyAreAndBoxesGetInternalSpheresInTheLinkFrame) {
  const UrdfLink link = LinkOf(
      "hand", {Ball(Vector3(0, 0, 0.3), 0.05), BoxAt(Vector3(0.1, 0.2, 0.4), Vector3(1, 0, 0))});
  UrdfSpherizeOptions options;
  options.kind = SphereSetKind::kInternal;
  options.max_spheres_per_link = 12;
  const LinkSpherizeResult result = SpherizeOne(link, options);
  ASSERT_EQ(result.status, LinkStatus::kSpherized) << result.error;
  ASSERT_GE(result.spheres.size(), 2u);
  EXPECT_LE(result.spheres.size(), 12u);
  EXPECT_EQ(result.spheres[0].center, Vector3(0, 0, 0.3));
  EXPECT_EQ(result.spheres[0].radius, 0.05);
  EXPECT_FALSE(result.delta.has_value());
  EXPECT_EQ(result.cores.size(), result.spheres.size());  // internal: the spheres themselves
  for (std::size_t i = 1; i < result.spheres.size(); ++i) {
    const Sphere& s = result.spheres[i];
    const Vector3 lo = s.center - Vector3::Constant(s.radius),
                  hi = s.center + Vector3::Constant(s.radius);
    EXPECT_TRUE((lo.array() >= Vector3(0.95, -0.1, -0.2).array() - 1e-12).all()) << i;
    EXPECT_TRUE((hi.array() <= Vector3(1.05, 0.1, 0.2).array() + 1e-12).all()) << i;
  }
}

void ExpectSameSpheres(const std::vector<Sphere>& a, const std::vector<Sphere>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].center, b[i].center) << i;
    EXPECT_EQ(a[i].radius, b[i].radius) << i;
  }
}

// Whether `spheres` hold every point of the box [lo, hi] (checked on a fine grid of it, faces
// included) and stay within `delta` of it.
void ExpectBoxCovered(const std::vector<Sphere>& spheres, const Vector3& lo, const Vector3& hi,
                      double delta) {
  const int n = 12;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      for (int k = 0; k <= n; ++k) {
        const Vector3 p = lo + (hi - lo).cwiseProduct(Vector3(i, j, k) / n);
        bool held = false;
        for (const Sphere& s : spheres) held = held || (p - s.center).norm() <= s.radius;
        EXPECT_TRUE(held) << p.transpose();
      }
    }
  }
  // Points of each sphere's surface in 26 directions are within delta of the box.
  for (const Sphere& s : spheres) {
    for (int x = -1; x <= 1; ++x) {
      for (int y = -1; y <= 1; ++y) {
        for (int z = -1; z <= 1; ++z) {
          if (x == 0 && y == 0 && z == 0) continue;
          const Vector3 p = s.center + s.radius * Vector3(x, y, z).normalized();
          EXPECT_LE((p - p.cwiseMax(lo).cwiseMin(hi)).norm(), delta * (1 + 1e-9) + 1e-12);
        }
      }
    }
  }
}

TEST(UrdfSpherizeRobot, CoversByDefaultHoldTheLinkAndPaddingGrowsThemAndTheirDelta) {
  const Vector3 size(0.2, 0.1, 0.3), centre(0.5, -0.2, 0.1);
  const UrdfLink link = LinkOf("arm", {BoxAt(size, centre), Ball(Vector3(0, 0, 1), 0.05)});
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 10;
  const LinkSpherizeResult bare = SpherizeOne(link, options);
  ASSERT_EQ(bare.status, LinkStatus::kSpherized) << bare.error;
  EXPECT_EQ(bare.kind, SphereSetKind::kCover);
  ASSERT_TRUE(bare.delta.has_value());
  EXPECT_GT(*bare.delta, 0.0);
  EXPECT_LE(bare.spheres.size(), 10u);
  EXPECT_EQ(bare.spheres.back().center, Vector3(0, 0, 1));  // the <sphere>, as it is
  EXPECT_EQ(bare.spheres.back().radius, 0.05);
  ExpectBoxCovered({bare.spheres.begin(), bare.spheres.end() - 1}, centre - size / 2,
                   centre + size / 2, *bare.delta);
  EXPECT_FALSE(bare.cores.empty());
  for (const Sphere& core : bare.cores) {  // inside the box or the ball element
    const bool in_ball = (core.center - Vector3(0, 0, 1)).norm() + core.radius <= 0.05 + 1e-12;
    const bool in_box =
        ((core.center - centre).cwiseAbs().array() + core.radius <= (size / 2).array() + 1e-12)
            .all();
    EXPECT_TRUE(in_ball || in_box) << core.center.transpose() << " r " << core.radius;
  }

  options.padding = 0.01;
  const LinkSpherizeResult padded = SpherizeOne(link, options);
  ASSERT_EQ(padded.spheres.size(), bare.spheres.size());
  for (std::size_t i = 0; i < bare.spheres.size(); ++i) {
    EXPECT_EQ(padded.spheres[i].center, bare.spheres[i].center);
    EXPECT_EQ(padded.spheres[i].radius, bare.spheres[i].radius + 0.01);
  }
  EXPECT_DOUBLE_EQ(*padded.delta, *bare.delta + 0.01);
  ExpectSameSpheres(padded.cores, bare.cores);  // still inside: padding does not touch them
}

TEST(UrdfSpherizeRobot, ClipPlanesCutTheMeshBeforeItIsSpherized) {
  // A 0.4 m cube on a table at z = 0 in its link frame, half of it below.
  const UrdfLink link = LinkOf(
      "base", {BoxAt(Vector3(0.4, 0.4, 0.4), Vector3::Zero()), Ball(Vector3(0, 0, -1), 0.1)});
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 16;
  options.clip_planes = {ClipPlane{"base", Vector3(0, 0, -2), 0.0}};  // keeps z >= 0
  const LinkSpherizeResult clipped = SpherizeOne(link, options);
  ASSERT_EQ(clipped.status, LinkStatus::kSpherized) << clipped.error;
  ASSERT_TRUE(clipped.delta.has_value());
  // The ball below the table is gone; the spheres reach below z = 0 by at most delta.
  for (const Sphere& s : clipped.spheres) {
    EXPECT_GE(s.center.z() - s.radius, -*clipped.delta - 1e-12) << s.center.transpose();
  }
  ExpectBoxCovered(clipped.spheres, Vector3(-0.2, -0.2, 0), Vector3(0.2, 0.2, 0.2), *clipped.delta);

  options.kind = SphereSetKind::kInternal;
  const LinkSpherizeResult inside = SpherizeOne(link, options);
  ASSERT_EQ(inside.status, LinkStatus::kSpherized) << inside.error;
  for (const Sphere& s : inside.spheres) EXPECT_GE(s.center.z() - s.radius, -1e-9);

  // Everything beyond the plane: nothing left to spherize, said so.
  options.clip_planes = {ClipPlane{"base", Vector3(0, 0, 1), -5.0}};
  const LinkSpherizeResult gone = SpherizeOne(link, options);
  EXPECT_EQ(gone.status, LinkStatus::kNoGeometry);
  EXPECT_THAT(gone.error, HasSubstr("clip planes"));
}

TEST(UrdfSpherizeRobot, ARobotBudgetGoesWhereTheEstimatedDeltaIsLargest) {
  // Curves made up: element 0 gains little per sphere, element 1 a lot at first.
  EXPECT_THAT(RobotSphereBudgets(2, {{1.0, 0.9}, {2.0, 0.5}}), ElementsAre(1, 1));
  EXPECT_THAT(RobotSphereBudgets(3, {{1.0, 0.9, 0.8}, {2.0, 0.5, 0.4}}), ElementsAre(1, 2));
  EXPECT_THAT(RobotSphereBudgets(4, {{1.0, 0.9, 0.8}, {2.0, 0.5, 0.4}}), ElementsAre(2, 2));
  EXPECT_THAT(RobotSphereBudgets(5, {{1.0, 0.9, 0.8}, {2.0, 0.5, 0.4}}), ElementsAre(3, 2));
  // Ties go to the lower index; a curve's end stops its element.
  EXPECT_THAT(RobotSphereBudgets(3, {{1.0, 0.5}, {1.0, 0.5}}), ElementsAre(2, 1));
  EXPECT_THAT(RobotSphereBudgets(10, {{1.0}, {1.0, 0.5}}), ElementsAre(1, 2));
  EXPECT_TRUE(RobotSphereBudgets(1, {{1.0}, {1.0}}).empty());

  // On a robot: two boxes, one 8x the other's volume, share 12 spheres.
  const UrdfRobot robot =
      RobotOf({LinkOf("big", {BoxAt(Vector3(0.4, 0.4, 0.4), Vector3::Zero())}),
               LinkOf("small", {BoxAt(Vector3(0.2, 0.2, 0.2), Vector3::Zero())})});
  UrdfSpherizeOptions options;
  options.max_spheres = 12;
  absl::StatusOr<RobotSpherizeResult> result = SpherizeRobot(robot, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->links[0].budget + result->links[1].budget, 12);
  EXPECT_GT(result->links[0].budget, result->links[1].budget);
  for (const LinkSpherizeResult& link : result->links) {
    EXPECT_LE(static_cast<std::int64_t>(link.spheres.size()), link.budget);
    ASSERT_TRUE(link.delta.has_value());
  }
  // Deterministic, bit for bit.
  absl::StatusOr<RobotSpherizeResult> again = SpherizeRobot(robot, options);
  ASSERT_TRUE(again.ok());
  for (std::size_t l = 0; l < 2; ++l) {
    ExpectSameSpheres(again->links[l].spheres, result->links[l].spheres);
    EXPECT_EQ(again->links[l].delta, result->links[l].delta);
  }

  options.link_max_spheres = {{"small", 2}};
  result = SpherizeRobot(robot, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->links[0].budget, 12);
  EXPECT_EQ(result->links[1].budget, 2);

  options.max_spheres.reset();
  options.link_max_spheres.clear();
  options.max_protrusion = 0.03;
  result = SpherizeRobot(robot, options);
  ASSERT_TRUE(result.ok()) << result.status();
  for (const LinkSpherizeResult& link : result->links) EXPECT_LE(*link.delta, 0.03);
}

// A link whose collision mesh is COLLADA in centimetres, its box placed by a node: read through
// assimp, welded by validation (the importer gives each face corner its own vertex), spherized
// in the link's frame in metres.
TEST(UrdfSpherizeRobot, ColladaMeshesAreReadInMetresWithTheirNodeTransforms) {
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
  options.kind = SphereSetKind::kInternal;
  options.max_spheres_per_link = 16;
  options.urdf_dir = dir.string();
  const LinkSpherizeResult result = SpherizeOne(link, options);
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

TEST(UrdfSpherizeRobot, BadOptionsAreRefusedNamingTheProblem) {
  const UrdfRobot robot = RobotOf({LinkOf("a", {BoxAt(Vector3::Ones(), Vector3::Zero())})});
  const auto refused = [&](const UrdfSpherizeOptions& options, const char* what) {
    const absl::StatusOr<RobotSpherizeResult> result = SpherizeRobot(robot, options);
    ASSERT_FALSE(result.ok()) << what;
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(result.status().message(), HasSubstr(what));
  };
  UrdfSpherizeOptions options;
  options.max_spheres = 4;
  options.max_spheres_per_link = 4;
  refused(options, "at most one of");
  options = {};
  options.voxel_size = 0.01;
  refused(options, "covers take no voxel_size");
  options = {};
  options.kind = SphereSetKind::kInternal;
  options.max_protrusion = 0.01;
  refused(options, "max_protrusion is for covers");
  options = {};
  options.padding = -0.01;
  refused(options, "padding");
  options = {};
  options.padding = std::nan("");
  refused(options, "padding");
  options = {};
  options.max_spheres = 0;
  refused(options, "max_spheres must lie in 1..");
  options = {};
  options.link_max_spheres = {{"b", 3}};
  refused(options, "'b'");
  options = {};
  options.clip_planes = {ClipPlane{"a", Vector3::Zero(), 0.0}};
  refused(options, "non-zero finite normal");
  options = {};
  options.clip_planes = {ClipPlane{"c", Vector3::UnitZ(), 0.0}};
  refused(options, "'c'");
  options = {};
  options.max_protrusion = 0.01;
  options.padding = 0.02;
  refused(options, "beyond the padding");

  // Links that cannot be done are skipped with the reason; the rest go on.
  UrdfLink odd = LinkOf("odd", {BoxAt(Vector3::Ones(), Vector3::Zero())});
  UrdfElement capsule = Element(UrdfShape::kUnsupported);
  capsule.geometry.unsupported = "capsule";
  capsule.name = "cap";
  odd.elements.push_back(capsule);
  absl::StatusOr<RobotSpherizeResult> result =
      SpherizeRobot(RobotOf({odd, LinkOf("empty", {})}), UrdfSpherizeOptions{});
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->links[0].status, LinkStatus::kSkipped);
  EXPECT_TRUE(result->links[0].spheres.empty());
  EXPECT_THAT(result->links[0].error, HasSubstr("line 7 (<collision> 'cap'): <capsule> is not"));
  EXPECT_EQ(result->links[1].status, LinkStatus::kNoGeometry);

  UrdfSpherizeOptions voxels;
  voxels.kind = SphereSetKind::kInternal;
  voxels.voxel_size = 1e-5;  // 1e15 voxels
  result = SpherizeRobot(robot, voxels);
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->links[0].status, LinkStatus::kSkipped);
  EXPECT_THAT(result->links[0].error, HasSubstr("voxels"));

  UrdfLink collada = LinkOf("arm", {});
  UrdfElement dae = Element(UrdfShape::kMesh);
  dae.geometry.filename = "package://arm/meshes/Link.DAE";
  collada.elements = {dae};
  result = SpherizeRobot(RobotOf({collada}), UrdfSpherizeOptions{});
  ASSERT_TRUE(result.ok());
  EXPECT_EQ(result->links[0].status, LinkStatus::kSkipped);
  EXPECT_THAT(result->links[0].error,
              HasSubstr("package 'arm'"));  // read like any mesh, once found
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
