// `inscribe urdf`, run as users run it, on a small robot made from CGAL's demo meshes: frames
// and scales are checked by recomputing every link's spheres here, in its own frame, through the
// core alone, and by the spheres' signed distances to the transformed meshes.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "client/cli_run.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

constexpr int kMaxSpheres = 32;

// One link of the test robot as the test itself understands it: where its geometry comes
// from and how it is placed (element frame -> link frame: scale, then rpy, then xyz).
struct LinkSpec {
  std::string name;
  std::string mesh;  // a file under data/, or "" for the box
  Vector3 box_size = Vector3::Zero();
  Vector3 scale = Vector3::Ones();
  Vector3 xyz = Vector3::Zero();
  Vector3 rpy = Vector3::Zero();
};

const std::vector<LinkSpec>& SpherizedLinks() {
  static const std::vector<LinkSpec> links = {
      // Non-uniform scale and a general rotation.
      {"base", "elephant.off", {}, {0.5, 0.8, 0.3}, {0.1, -0.2, 0.3}, {0.3, -0.5, 1.1}},
      // A mirror (one negative scale factor) and a relative path.
      {"mirrored", "eight.off", {}, {-0.2, 0.2, 0.2}, {0, 0, 0}, {0, 0, 0.7}},
      // Visual geometry only, through a file:// URI.
      {"camera", "eight.off", {}, {0.1, 0.1, 0.1}, {0, 0, 0.05}, {1.2, 0, 0}},
      {"plate", "", {0.3, 0.2, 0.05}, {1, 1, 1}, {0, 0, 0.1}, {0, 0.4, 0}},
  };
  return links;
}

std::string Triple(const Vector3& v) {
  return absl::StrFormat("%.17g %.17g %.17g", v.x(), v.y(), v.z());
}

std::string Origin(const LinkSpec& link) {
  return "<origin xyz=\"" + Triple(link.xyz) + "\" rpy=\"" + Triple(link.rpy) + "\"/>";
}

// The link's mesh in its own frame, transformed here with Eigen's Affine3d, independently of
// the CLI's TransformMesh.
Mesh LinkMesh(const LinkSpec& link) {
  Mesh mesh = link.mesh.empty() ? testing::Box(-link.box_size / 2, link.box_size / 2)
                                : *ReadMesh(testing::TestMeshPath(link.mesh));
  const Eigen::Affine3d pose =
      Eigen::Translation3d(link.xyz) * Eigen::AngleAxisd(link.rpy.z(), Vector3::UnitZ()) *
      Eigen::AngleAxisd(link.rpy.y(), Vector3::UnitY()) *
      Eigen::AngleAxisd(link.rpy.x(), Vector3::UnitX()) * Eigen::Scaling(link.scale);
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    mesh.vertices.row(i) = (pose * Vector3(mesh.vertices.row(i).transpose())).transpose();
  }
  if (pose.linear().determinant() < 0) {
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      std::swap(mesh.triangles(t, 0), mesh.triangles(t, 1));
    }
  }
  return mesh;
}

class CliUrdf : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("inscribe_cli_urdf_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "ws/pkg/meshes");
    fs::create_directories(root_ / "robot");
    fs::create_directories(root_ / "out");
    for (const char* name : {"elephant.off", "eight.off", "cube-ouvert.off"}) {
      if (testing::TestMeshPath(name).empty()) return;  // the tests skip
      fs::copy_file(testing::TestMeshPath(name), root_ / "ws/pkg/meshes" / name);
    }
    const std::vector<LinkSpec>& l = SpherizedLinks();
    const std::string eight = (root_ / "ws/pkg/meshes/eight.off").string();
    std::ofstream(Urdf())
        << R"(<?xml version="1.0"?>
<!-- A test robot: every kind of link inscribe urdf meets. -->
<robot name="testbot">
  <material name="grey"><color rgba="0.5 0.5 0.5 1"/></material>
  <link name="world"/>
  <link name="base">
    <inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <visual><geometry><mesh filename="package://pkg/meshes/elephant.off"/></geometry>
      <material name="grey"/></visual>
    <collision name="body">)" +
               Origin(l[0]) +
               R"(<geometry><mesh filename="package://pkg/meshes/elephant.off"
        scale=")" +
               Triple(l[0].scale) +
               R"("/></geometry></collision>
  </link>
  <link name="mirrored"><collision>)" +
               Origin(l[1]) + R"(<geometry><mesh filename="../ws/pkg/meshes/eight.off" scale=")" +
               Triple(l[1].scale) + R"("/></geometry></collision></link>
  <link name="camera"><visual>)" +
               Origin(l[2]) + R"(<geometry><mesh filename="file://)" + eight + "\" scale=\"" +
               Triple(l[2].scale) +
               R"("/></geometry></visual></link>
  <link name="plate"><collision>)" +
               Origin(l[3]) + "<geometry><box size=\"" + Triple(l[3].box_size) +
               R"("/></geometry></collision></link>
  <link name="gripper"><collision>
    <geometry><mesh filename="package://pkg/meshes/gripper.stl"/></geometry></collision></link>
  <link name="broken_link"><collision>
    <geometry><mesh filename="package://pkg/meshes/cube-ouvert.off"/></geometry></collision></link>
  <joint name="j1" type="fixed"><parent link="world"/><child link="base"/></joint>
  <joint name="j2" type="revolute"><parent link="base"/><child link="mirrored"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
)";
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  static std::string Urdf() { return (root_ / "robot/robot.urdf").string(); }
  static std::string Out(const std::string& name) { return (root_ / "out" / name).string(); }
  static std::string Args() {
    return "urdf " + Quote(Urdf()) + " --package-path " + Quote((root_ / "ws").string());
  }

  static fs::path root_;
};

fs::path CliUrdf::root_;

#define REQUIRE_MESHES()                 \
  INSCRIBE_REQUIRE_MESH("elephant.off"); \
  INSCRIBE_REQUIRE_MESH("eight.off");    \
  INSCRIBE_REQUIRE_MESH("cube-ouvert.off")

// The <collision> spheres of `link` in a spherized URDF.
std::vector<Sphere> UrdfSpheres(const tinyxml2::XMLElement& link) {
  std::vector<Sphere> spheres;
  for (const tinyxml2::XMLElement* c = link.FirstChildElement("collision"); c != nullptr;
       c = c->NextSiblingElement("collision")) {
    const tinyxml2::XMLElement* sphere = c->FirstChildElement("geometry")->FirstChildElement();
    EXPECT_STREQ(sphere->Name(), "sphere");
    Sphere s;
    EXPECT_EQ(std::sscanf(c->FirstChildElement("origin")->Attribute("xyz"), "%lf %lf %lf",
                          &s.center.x(), &s.center.y(), &s.center.z()),
              3);
    s.radius = sphere->DoubleAttribute("radius");
    spheres.push_back(s);
  }
  return spheres;
}

const tinyxml2::XMLElement* FindLink(const tinyxml2::XMLDocument& document,
                                     const std::string& name) {
  for (const tinyxml2::XMLElement* link = document.RootElement()->FirstChildElement("link");
       link != nullptr; link = link->NextSiblingElement("link")) {
    if (name == link->Attribute("name")) return link;
  }
  return nullptr;
}

TEST_F(CliUrdf, SpheresMatchARecomputationInEachLinksOwnFrame) {
  REQUIRE_MESHES();
  const CliRun run =
      RunCli(Args() + " --kind internal -o " + Quote(Out("robot_spheres.urdf")) + " --json");
  ASSERT_EQ(run.exit_code, 1) << run.err;  // two links skipped
  EXPECT_THAT(run.err, HasSubstr("link 'gripper' skipped"));
  EXPECT_THAT(run.err, HasSubstr("gripper.stl"));
  EXPECT_THAT(run.err, HasSubstr("link 'broken_link' skipped"));
  EXPECT_THAT(run.err, HasSubstr("not closed"));

  const nlohmann::json report = nlohmann::json::parse(run.out);
  std::map<std::string, nlohmann::json> by_link;
  for (const nlohmann::json& link : report.at("links")) by_link[link.at("link")] = link;
  ASSERT_EQ(by_link.size(), 7u);
  EXPECT_EQ(by_link["world"].at("status"), "no_geometry");
  EXPECT_EQ(by_link["gripper"].at("status"), "skipped");
  EXPECT_EQ(by_link["broken_link"].at("status"), "skipped");
  EXPECT_TRUE(by_link["camera"].at("from_visual").get<bool>());
  EXPECT_EQ(report.at("spherized"), 4);
  EXPECT_EQ(report.at("skipped"), 2);

  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.LoadFile(Out("robot_spheres.urdf").c_str()), tinyxml2::XML_SUCCESS);
  const absl::StatusOr<std::vector<LinkSpheres>> yaml =
      ParseCuroboYaml(Slurp(Out("robot_spheres.yml")));
  ASSERT_TRUE(yaml.ok()) << yaml.status();
  ASSERT_EQ(yaml->size(), 4u);  // the spherized links, in file order

  std::string figures = "URDF figures (--max-spheres-per-link 32):\n";
  for (std::size_t k = 0; k < SpherizedLinks().size(); ++k) {
    const LinkSpec& spec = SpherizedLinks()[k];
    SCOPED_TRACE(spec.name);
    ASSERT_EQ(by_link[spec.name].at("status"), "spherized") << by_link[spec.name].dump();
    const tinyxml2::XMLElement* link = FindLink(document, spec.name);
    ASSERT_NE(link, nullptr);
    const std::vector<Sphere> written = UrdfSpheres(*link);
    EXPECT_EQ(written.size(), by_link[spec.name].at("spheres").get<std::size_t>());
    EXPECT_LE(written.size(), static_cast<std::size_t>(kMaxSpheres));
    EXPECT_GE(written.size(), 8u);
    // The YAML carries the same numbers, bit for bit.
    ASSERT_EQ((*yaml)[k].link, spec.name);
    ASSERT_EQ((*yaml)[k].spheres.size(), written.size());
    for (std::size_t i = 0; i < written.size(); ++i) {
      EXPECT_EQ((*yaml)[k].spheres[i].center, written[i].center);
      EXPECT_EQ((*yaml)[k].spheres[i].radius, written[i].radius);
    }

    // Recompute: the mesh placed here, validated and spherized with the same parameters.
    const auto start = std::chrono::steady_clock::now();
    absl::StatusOr<Solid> solid = PrepareSolid(LinkMesh(spec));
    ASSERT_TRUE(solid.ok()) << solid.status();
    const double diagonal = solid->report.bbox.diagonal();
    const BoundaryOracle* oracle = &solid->oracle;
    SphereSetParameters parameters;  // core's defaults, as the CLI's
    parameters.max_spheres = kMaxSpheres;
    parameters.evaluate = false;
    const absl::StatusOr<GeneratedSphereSet> expected = GenerateSphereSet(*solid, parameters);
    ASSERT_TRUE(expected.ok()) << expected.status();
    const double recompute_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::vector<Sphere>& reference = expected->set.spheres;
    ASSERT_EQ(written.size(), reference.size());
    double centre_deviation = 0.0, radius_deviation = 0.0, tangency = 0.0;
    for (std::size_t i = 0; i < written.size(); ++i) {
      centre_deviation =
          std::max(centre_deviation, (written[i].center - reference[i].center).norm());
      radius_deviation =
          std::max(radius_deviation, std::abs(written[i].radius - reference[i].radius));
      // Independent frame check: each sphere lies inside the mesh placed here and touches it
      // (signed distance of the centre = -radius).
      const double signed_distance = oracle->SignedDistance(written[i].center);
      EXPECT_LT(signed_distance, 0.0) << "sphere " << i << " centre outside the link's mesh";
      tangency = std::max(tangency, std::abs(signed_distance + written[i].radius));
    }
    EXPECT_LE(centre_deviation, 1e-9 * diagonal);
    EXPECT_LE(radius_deviation, 1e-9 * diagonal);
    EXPECT_LE(tangency, 1e-9 * diagonal);
    figures += absl::StrFormat(
        "  %-9s %2d spheres, max |dc| %.2e m, max |dr| %.2e m, max |sd+r| %.2e m, CLI %.3f s "
        "(%d runs), recompute %.3f s, bbox diagonal %.3f m\n",
        spec.name, written.size(), centre_deviation, radius_deviation, tangency,
        by_link[spec.name].at("seconds").get<double>(),
        by_link[spec.name].at("generation_runs").get<int>(), recompute_seconds, diagonal);
  }
  figures += absl::StrFormat("  whole run %.3f s\n", report.at("seconds").get<double>());
  std::cout << figures;
  RecordProperty("figures", figures);
}

// The default: certified covers. Each link's written spheres are certified again here against
// the link's mesh placed by the test itself, and hold it within the delta the CLI reported.
void ExpectCertifiedCovers(const nlohmann::json& report, const std::string& urdf_path,
                           double padding) {
  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.LoadFile(urdf_path.c_str()), tinyxml2::XML_SUCCESS);
  std::map<std::string, nlohmann::json> by_link;
  for (const nlohmann::json& link : report.at("links")) by_link[link.at("link")] = link;
  for (const LinkSpec& spec : SpherizedLinks()) {
    SCOPED_TRACE(spec.name);
    const nlohmann::json& link = by_link[spec.name];
    ASSERT_EQ(link.at("status"), "spherized") << link.dump();
    ASSERT_TRUE(link.at("certified").get<bool>());
    const double delta = link.at("delta").get<double>();
    EXPECT_GE(delta, padding);
    std::vector<Sphere> written = UrdfSpheres(*FindLink(document, spec.name));
    ASSERT_FALSE(written.empty());
    absl::StatusOr<Solid> solid = PrepareSolid(LinkMesh(spec));
    ASSERT_TRUE(solid.ok()) << solid.status();
    const absl::StatusOr<CoverCertificate> certificate = CertifyCover(*solid, written);
    ASSERT_TRUE(certificate.ok()) << certificate.status();
    EXPECT_TRUE(certificate->certified);
    EXPECT_LE(certificate->delta, delta * (1 + 1e-9) + 1e-12);
    // Without the padding the spheres still hold the link: padding only adds.
    for (Sphere& s : written) s.radius -= padding;
    const absl::StatusOr<CoverCertificate> bare = CertifyCover(*solid, written);
    ASSERT_TRUE(bare.ok());
    EXPECT_TRUE(bare->certified);
  }
}

TEST_F(CliUrdf, CoversByDefaultAreCertifiedInEachLinksFrame) {
  REQUIRE_MESHES();
  const CliRun run = RunCli(Args() + " -o " + Quote(Out("covers.urdf")) + " --json");
  ASSERT_EQ(run.exit_code, 1) << run.err;  // the two broken links
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report.at("kind"), "cover");
  EXPECT_EQ(report.at("max_spheres_per_link"), 32);
  ExpectCertifiedCovers(report, Out("covers.urdf"), 0.0);
  std::cout << "covers, 32 per link: " << report.at("spheres") << " spheres, largest delta "
            << report.at("delta") << " m, " << report.at("spherize_seconds") << " s\n";
}

TEST_F(CliUrdf, ARobotBudgetIsSharedAndPaddingAndProtrusionBoundsHold) {
  REQUIRE_MESHES();
  const CliRun shared = RunCli(Args() + " --max-spheres 24 --padding 0.005 -o " +
                               Quote(Out("shared.urdf")) + " --json");
  ASSERT_EQ(shared.exit_code, 1) << shared.err;
  const nlohmann::json report = nlohmann::json::parse(shared.out);
  EXPECT_EQ(report.at("max_spheres"), 24);
  EXPECT_LE(report.at("spheres").get<int>(), 24);
  std::int64_t budgets = 0;
  for (const nlohmann::json& link : report.at("links")) {
    if (link.at("status") == "spherized") {
      EXPECT_GE(link.at("budget").get<int>(), 1);
      EXPECT_LE(link.at("spheres").get<int>(), link.at("budget").get<int>());
      budgets += link.at("budget").get<int>();
    }
  }
  EXPECT_EQ(budgets, 24);
  ExpectCertifiedCovers(report, Out("shared.urdf"), 0.005);

  // An override takes its link out of the shared budget.
  const CliRun pinned = RunCli(Args() + " --max-spheres 24 --link-max-spheres plate=3 -o " +
                               Quote(Out("pinned.urdf")) + " --json");
  ASSERT_EQ(pinned.exit_code, 1) << pinned.err;
  const nlohmann::json pinned_report = nlohmann::json::parse(pinned.out);
  for (const nlohmann::json& link : pinned_report.at("links")) {
    if (link.at("link") == "plate") {
      EXPECT_EQ(link.at("budget"), 3);
    }
  }

  const CliRun within =
      RunCli(Args() + " --max-protrusion 0.02 -o " + Quote(Out("within.urdf")) + " --json");
  ASSERT_EQ(within.exit_code, 1) << within.err;
  const nlohmann::json bounded = nlohmann::json::parse(within.out);
  for (const nlohmann::json& link : bounded.at("links")) {
    if (link.at("status") == "spherized") {
      EXPECT_LE(link.at("delta").get<double>(), 0.02);
    }
  }
  ExpectCertifiedCovers(bounded, Out("within.urdf"), 0.0);

  // Too small a robot budget for its elements is a usage error.
  const CliRun tiny = RunCli(Args() + " --max-spheres 2 -o " + Quote(Out("tiny.urdf")));
  EXPECT_EQ(tiny.exit_code, 64);
  EXPECT_THAT(tiny.err, HasSubstr("fewer than"));
}

// The self-collision matrix: MoveIt's SRDF and cuRobo's self_collision_ignore, the same for the
// same seed; a robot that is not one tree has none, and --srdf then fails.
TEST_F(CliUrdf, TheSrdfAndTheYamlCarryTheSelfCollisionMatrix) {
  REQUIRE_MESHES();
  const CliRun forest =
      RunCli(Args() + " --srdf " + Quote(Out("forest.srdf")) + " -o " + Quote(Out("forest.urdf")));
  EXPECT_EQ(forest.exit_code, 2) << forest.err;
  EXPECT_THAT(forest.err, HasSubstr("no self-collision matrix"));

  // Attach the loose links: one tree.
  std::string text = Slurp(Urdf());
  text.replace(text.rfind("</robot>"), 8, R"(
  <joint name="j3" type="revolute"><parent link="mirrored"/><child link="camera"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-2" upper="2"/></joint>
  <joint name="j4" type="prismatic"><parent link="base"/><child link="plate"/>
    <origin xyz="0.4 0 0"/><axis xyz="1 0 0"/><limit lower="0" upper="0.3"/></joint>
  <joint name="j5" type="fixed"><parent link="base"/><child link="gripper"/></joint>
  <joint name="j6" type="fixed"><parent link="base"/><child link="broken_link"/></joint>
</robot>)");
  const std::string tree = (fs::path(Urdf()).parent_path() / "tree.urdf").string();
  std::ofstream(tree) << text;
  const std::string args = "urdf " + Quote(tree) + " --package-path " +
                           Quote((root_ / "ws").string()) + " --samples 2000 --seed 7";
  const CliRun run = RunCli(args + " --srdf " + Quote(Out("tree.srdf")) + " -o " +
                            Quote(Out("tree.urdf")) + " --json");
  ASSERT_EQ(run.exit_code, 1) << run.err;  // the two broken links
  const nlohmann::json report = nlohmann::json::parse(run.out);
  const nlohmann::json& matrix = report.at("self_collision");
  EXPECT_EQ(matrix.at("samples"), 2000);
  EXPECT_EQ(matrix.at("seed"), 7);
  EXPECT_TRUE(matrix.at("certified").get<bool>());
  EXPECT_EQ(matrix.at("pairs").size(), 6u);  // the 4 spherized links
  std::map<std::pair<std::string, std::string>, std::string> classes;
  for (const nlohmann::json& pair : matrix.at("pairs")) {
    std::string a = pair.at("link1"), b = pair.at("link2");
    if (b < a) std::swap(a, b);
    classes[{a, b}] = pair.at("class");
  }
  EXPECT_EQ((classes[{"base", "mirrored"}]), "Adjacent");
  EXPECT_EQ((classes[{"camera", "mirrored"}]), "Adjacent");
  EXPECT_EQ((classes[{"base", "plate"}]), "Adjacent");

  tinyxml2::XMLDocument srdf;
  ASSERT_EQ(srdf.LoadFile(Out("tree.srdf").c_str()), tinyxml2::XML_SUCCESS);
  int disabled = 0;
  for (const tinyxml2::XMLElement* e = srdf.RootElement()->FirstChildElement("disable_collisions");
       e != nullptr; e = e->NextSiblingElement("disable_collisions"), ++disabled) {
    std::string a = e->Attribute("link1"), b = e->Attribute("link2");
    EXPECT_LT(a, b);
    EXPECT_EQ(e->Attribute("reason"), (classes[{a, b}]));
    EXPECT_NE((classes[{a, b}]), "Sometimes");
  }
  EXPECT_EQ(disabled, matrix.at("disabled").get<int>());
  EXPECT_GE(disabled, 3);
  const std::string yaml = Slurp(Out("tree.yml"));
  EXPECT_THAT(yaml, HasSubstr("self_collision_ignore:"));
  EXPECT_THAT(yaml, HasSubstr("self_collision_buffer:"));

  // The same seed, the same files.
  const CliRun again =
      RunCli(args + " --srdf " + Quote(Out("again.srdf")) + " -o " + Quote(Out("again.urdf")));
  ASSERT_EQ(again.exit_code, 1) << again.err;
  EXPECT_EQ(Slurp(Out("again.srdf")), Slurp(Out("tree.srdf")));
  EXPECT_EQ(Slurp(Out("again.yml")), Slurp(Out("tree.yml")));
  EXPECT_EQ(RunCli(args + " --samples 0 -o " + Quote(Out("x.urdf"))).exit_code, 64);
}

TEST_F(CliUrdf, EverythingButSphereCollisionsIsKeptAndSkippedLinksSayWhy) {
  REQUIRE_MESHES();
  const CliRun run = RunCli(Args() + " -o " + Quote(Out("kept.urdf")) + " --yaml " +
                            Quote(Out("kept_spheres.yaml")));
  ASSERT_EQ(run.exit_code, 1) << run.err;
  // The human-readable table names every link.
  for (const char* name : {"world", "base", "camera", "plate", "gripper", "broken_link"}) {
    EXPECT_THAT(run.out, HasSubstr(name));
  }
  EXPECT_TRUE(fs::exists(Out("kept_spheres.yaml")));
  EXPECT_FALSE(fs::exists(Out("kept.yml")));

  tinyxml2::XMLDocument before, after;
  ASSERT_EQ(before.LoadFile(Urdf().c_str()), tinyxml2::XML_SUCCESS);
  ASSERT_EQ(after.LoadFile(Out("kept.urdf").c_str()), tinyxml2::XML_SUCCESS);
  const auto count = [](const tinyxml2::XMLDocument& d, const char* name) {
    int n = 0;
    for (const tinyxml2::XMLElement* e = d.RootElement()->FirstChildElement(name); e != nullptr;
         e = e->NextSiblingElement(name)) {
      ++n;
    }
    return n;
  };
  for (const char* name : {"link", "joint", "material"}) {
    EXPECT_EQ(count(before, name), count(after, name)) << name;
  }
  const tinyxml2::XMLElement* base = FindLink(after, "base");
  EXPECT_STREQ(base->FirstChildElement("visual")
                   ->FirstChildElement("geometry")
                   ->FirstChildElement("mesh")
                   ->Attribute("filename"),
               "package://pkg/meshes/elephant.off");
  EXPECT_NE(base->FirstChildElement("inertial"), nullptr);
  EXPECT_NE(FindLink(after, "camera")->FirstChildElement("visual"), nullptr);
  // Skipped links keep their mesh collision, with a comment saying why.
  for (const char* name : {"gripper", "broken_link"}) {
    const tinyxml2::XMLElement* link = FindLink(after, name);
    ASSERT_NE(link, nullptr);
    EXPECT_NE(link->FirstChildElement("collision")
                  ->FirstChildElement("geometry")
                  ->FirstChildElement("mesh"),
              nullptr);
    ASSERT_NE(link->FirstChild()->ToComment(), nullptr) << name;
    EXPECT_THAT(link->FirstChild()->Value(), HasSubstr("not spherized"));
  }
  EXPECT_THAT(FindLink(after, "gripper")->FirstChild()->Value(), HasSubstr("does not exist"));
  EXPECT_THAT(FindLink(after, "broken_link")->FirstChild()->Value(), HasSubstr("not closed"));
}

TEST_F(CliUrdf, VoxelSizeModeAndOptionErrors) {
  REQUIRE_MESHES();
  const CliRun voxel = RunCli(Args() + " --kind internal --voxel-size 0.02 -o " +
                              Quote(Out("voxel.urdf")) + " --json");
  ASSERT_EQ(voxel.exit_code, 1) << voxel.err;
  const nlohmann::json report = nlohmann::json::parse(voxel.out);
  EXPECT_EQ(report.at("voxel_size"), 0.02);
  EXPECT_EQ(report.at("spherized"), 4);

  EXPECT_EQ(
      RunCli(Args() + " --voxel-size 0.02 --max-spheres-per-link 8 -o " + Quote(Out("x.urdf")))
          .exit_code,
      64);
  EXPECT_EQ(RunCli(Args()).exit_code, 64);  // -o is required
  const CliRun zero = RunCli(Args() + " --max-spheres-per-link 0 -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(zero.exit_code, 64);
  EXPECT_THAT(zero.err, HasSubstr("max_spheres_per_link must lie in 1.."));
  const CliRun cover_voxel = RunCli(Args() + " --voxel-size 0.02 -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(cover_voxel.exit_code, 64);
  EXPECT_THAT(cover_voxel.err, HasSubstr("covers take no voxel_size"));
  const CliRun negative = RunCli(Args() + " --padding -0.01 -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(negative.exit_code, 64);
  EXPECT_THAT(negative.err, HasSubstr("padding"));
  const CliRun unknown = RunCli(Args() + " --link-max-spheres nolink=4 -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(unknown.exit_code, 64);
  EXPECT_THAT(unknown.err, HasSubstr("'nolink'"));
  const CliRun clip = RunCli(Args() + " --clip base=0,0,1 -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(clip.exit_code, 64);
  EXPECT_THAT(clip.err, HasSubstr("LINK=NX,NY,NZ,OFFSET"));
  const CliRun same = RunCli(Args() + " -o " + Quote(Out("x.yml")));
  EXPECT_EQ(same.exit_code, 64);
  EXPECT_THAT(same.err, HasSubstr("--yaml"));
  const CliRun no_dir = RunCli(Args() + " -o " + Quote(Out("nowhere/x.urdf")));
  EXPECT_EQ(no_dir.exit_code, 2);
  EXPECT_THAT(no_dir.err, HasSubstr("does not exist"));
}

// Writes `contents` as a URDF next to the test robot and runs the CLI on it.
CliRun RunOn(const fs::path& root, const std::string& contents, const std::string& extra = "") {
  const fs::path urdf = root / "robot/bad.urdf";
  std::ofstream(urdf, std::ios::binary) << contents;
  return RunCli("urdf " + Quote(urdf.string()) + " --package-path " +
                Quote((root / "ws").string()) + " -o " +
                Quote((root / "out/bad_out.urdf").string()) + " " + extra);
}

TEST_F(CliUrdf, BadInputIsRefusedClearlyNeverWithACrash) {
  REQUIRE_MESHES();
  CliRun run = RunCli("urdf " + Quote(Out("absent.urdf")) + " -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("absent.urdf: no such file"));
  run = RunCli("urdf " + Quote(root_.string()) + " -o " + Quote(Out("x.urdf")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("is a directory"));

  std::string garbage(4096, '\0');
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<char>(i * 7919 % 251);
  run = RunOn(root_, garbage);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("NUL"));
  run = RunOn(root_, "<robot><link name=\"a\"><collision><geometry>");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("not well-formed XML"));
  run = RunOn(root_,
              "<robot>\n<link name=\"a\"><collision><origin xyz=\"0 NaN 0\"/><geometry>"
              "<box size=\"1 1 1\"/></geometry></collision></link></robot>");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("line 2"));
  EXPECT_THAT(run.err, HasSubstr("not finite"));

  // Per-link problems: the link is named and skipped, the others are written.
  const std::string links = R"(<robot name="bad">
  <link name="huge"><collision><geometry>
    <mesh filename="package://pkg/meshes/eight.off" scale="1e200 1e200 1e200"/></geometry></collision></link>
  <link name="unknown_package"><collision><geometry>
    <mesh filename="package://nopkg/m.stl"/></geometry></collision></link>
  <link name="collada"><collision><geometry>
    <mesh filename="package://pkg/meshes/arm.dae"/></geometry></collision></link>
  <link name="cone"><collision><geometry><cone radius="1" length="2"/></geometry>
    </collision></link>
  <link name="fine"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <link name="odd:name"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
    </link>
</robot>)";
  run = RunOn(root_, links, "--json");
  ASSERT_EQ(run.exit_code, 1) << run.err;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  std::map<std::string, std::string> errors;
  for (const nlohmann::json& link : report.at("links")) {
    if (link.at("status") == "skipped") errors[link.at("link")] = link.at("error");
  }
  EXPECT_THAT(errors["huge"], HasSubstr("coordinate"));
  EXPECT_THAT(errors["unknown_package"], HasSubstr("package 'nopkg'"));
  EXPECT_THAT(errors["collada"], HasSubstr("arm.dae"));  // read like any mesh: not found
  EXPECT_THAT(errors["cone"], HasSubstr("<cone>"));
  EXPECT_EQ(errors.count("fine"), 0u);
  EXPECT_EQ(report.at("spherized"), 2);
  // Spherized in the URDF, but not a name cuRobo's YAML can carry: said, not dropped silently.
  EXPECT_EQ(report.at("left_out_of_yaml"), nlohmann::json::array({"odd:name"}));
  EXPECT_THAT(run.err, HasSubstr("link 'odd:name' is spherized"));
  const absl::StatusOr<std::vector<LinkSpheres>> yaml =
      ParseCuroboYaml(Slurp(root_ / "out/bad_out.yml"));
  ASSERT_TRUE(yaml.ok()) << yaml.status();
  ASSERT_EQ(yaml->size(), 1u);
  EXPECT_EQ((*yaml)[0].link, "fine");
  EXPECT_EQ((*yaml)[0].spheres.at(0).radius, 0.1);
}

}  // namespace
}  // namespace inscribe
