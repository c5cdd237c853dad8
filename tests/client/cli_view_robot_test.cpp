// `inscribe view ROBOT.urdf SPHERES`, run as users run it on a small robot made from CGAL's demo
// meshes (revolute, prismatic, continuous, fixed and mimic joints; mesh, box, cylinder and
// sphere links; a Collada link whose file is missing), spherized by `inscribe urdf`, and the page
// opened in headless Chromium: it draws, has a slider per joint variable, names the unreadable
// link, and its forward kinematics equals robot::Kinematics::LinkPoses.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/cli_run.h"
#include "client/headless_chromium.h"
#include "inscribe/robot/kinematics.h"
#include "inscribe/robot/urdf_robot.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::ContainsRegex;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

constexpr int kWidth = 800, kHeight = 600;
constexpr int kPanelWidth = 340;                                         // view_page.css #panel
constexpr std::array<std::uint8_t, 3> kBackground = {0xf3, 0xf4, 0xf6};  // robot_view_page.js

// The robot: a base (elephant), an arm (eight) on a revolute joint about a skew axis, a box on
// a prismatic joint, two cylinder fingers (the right one mimics the left), a ball tip on a
// continuous joint mimicking the right finger (a mimic of a mimic), and a Collada camera.
const char* kRobot = R"(<?xml version="1.0"?>
<robot name="gripperbot">
  <link name="base"><collision><geometry>
    <mesh filename="package://bot/meshes/elephant.off" scale="0.5 0.5 0.5"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="0 0 0.2" rpy="0.1 0.2 0.3"/><geometry>
    <mesh filename="package://bot/meshes/eight.off" scale="0.3 0.3 0.3"/></geometry></collision></link>
  <link name="slider"><collision><geometry><box size="0.2 0.1 0.05"/></geometry></collision></link>
  <link name="finger_left"><collision><origin xyz="0 0 0.05"/><geometry>
    <cylinder radius="0.02" length="0.1"/></geometry></collision></link>
  <link name="finger_right"><collision><origin xyz="0 0 0.05"/><geometry>
    <cylinder radius="0.02" length="0.1"/></geometry></collision></link>
  <link name="tip"><collision><origin xyz="0 0 0.03"/><geometry><sphere radius="0.03"/></geometry>
    </collision></link>
  <link name="camera"><visual><geometry><mesh filename="package://bot/meshes/camera.dae"/>
    </geometry></visual></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0.1 0 0.3" rpy="0 0 0.5"/><axis xyz="0 1 1"/>
    <limit lower="-1.5" upper="2" effort="1" velocity="1"/></joint>
  <joint name="extend" type="prismatic"><parent link="arm"/><child link="slider"/>
    <origin xyz="0 0.1 0.2" rpy="0.3 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.3" effort="1" velocity="1"/></joint>
  <joint name="finger_left_joint" type="revolute"><parent link="slider"/><child link="finger_left"/>
    <origin xyz="0.1 0.02 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/></joint>
  <joint name="finger_right_joint" type="revolute"><parent link="slider"/>
    <child link="finger_right"/><origin xyz="0.1 -0.02 0"/><axis xyz="0 0 1"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/>
    <mimic joint="finger_left_joint" multiplier="-1" offset="0.1"/></joint>
  <joint name="tip_joint" type="continuous"><parent link="finger_right"/><child link="tip"/>
    <origin xyz="0 0 0.1" rpy="0.2 -0.1 0.4"/><axis xyz="1 0 0"/>
    <mimic joint="finger_right_joint" multiplier="2" offset="-0.05"/></joint>
  <joint name="camera_joint" type="fixed"><parent link="base"/><child link="camera"/>
    <origin xyz="0 0 0.5" rpy="0 0.4 0"/></joint>
</robot>
)";

std::string FileUrl(const fs::path& page, const std::string& options = "") {
  return "file://" + fs::absolute(page).string() + (options.empty() ? "" : "#" + options);
}

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

// The JSON the page's script reads.
nlohmann::json PageData(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"inscribe-data\">";
  const std::size_t start = html.find(open);
  if (start == std::string::npos) return nullptr;
  const std::size_t end = html.find("</script>", start);
  return nlohmann::json::parse(html.substr(start + open.size(), end - start - open.size()));
}

int Count(const std::string& haystack, const std::string& needle) {
  int n = 0;
  for (std::size_t at = haystack.find(needle); at != std::string::npos;
       at = haystack.find(needle, at + 1)) {
    ++n;
  }
  return n;
}

// The robot spherized once by `inscribe urdf` (a URDF and a YAML), and a page of each.
class CliViewRobot : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("inscribe_cli_view_robot_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "ws/bot/meshes");
    for (const char* name : {"elephant.off", "eight.off"}) {
      if (testing::TestMeshPath(name).empty()) return;  // the tests skip
      fs::copy_file(testing::TestMeshPath(name), dir_ / "ws/bot/meshes" / name);
    }
    WriteText(Robot(), kRobot);
    spherized_ = RunCli("urdf " + Quote(Robot()) + Packages() + " --kind internal -o " +
                        Quote((dir_ / "spheres.urdf").string()));
    for (const char* name : {"spheres.urdf", "spheres.yml"}) {
      views_.push_back(RunCli("view " + Quote(Robot()) + " " + Quote((dir_ / name).string()) +
                              Packages() + " -o " +
                              Quote((dir_ / (std::string(name) + ".html")).string())));
    }
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  void SetUp() override {
    INSCRIBE_REQUIRE_MESH("elephant.off");
    INSCRIBE_REQUIRE_MESH("eight.off");
    // The Collada camera (its file is missing) is skipped (exit 1), everything else spherized.
    ASSERT_EQ(spherized_.exit_code, 1) << spherized_.err;
    ASSERT_THAT(spherized_.err, HasSubstr("camera"));
    for (const CliRun& view : views_) ASSERT_EQ(view.exit_code, 0) << view.err;
  }

  static std::string Robot() { return (dir_ / "robot.urdf").string(); }
  static std::string Packages() { return " --package-path " + Quote((dir_ / "ws").string()); }
  static fs::path Page(const std::string& spheres = "spheres.urdf") {
    return dir_ / (spheres + ".html");
  }

  static std::string Chromium() {
    const std::string chromium = testing::FindChromium();
    EXPECT_FALSE(chromium.empty())
        << "chromium not found on PATH (or $INSCRIBE_CHROMIUM): install Debian's chromium "
           "(apt-get install chromium, as scripts/install-deps does) to test inscribe view";
    return chromium;
  }

  static std::string DumpDom(const std::string& chromium, const fs::path& page,
                             const std::string& options = "") {
    const testing::ChromiumRun run =
        testing::ChromiumDumpDom(chromium, dir_.string(), FileUrl(page, options), kWidth, kHeight);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.out;
  }

  static testing::RgbImage Screenshot(const std::string& chromium, const std::string& options,
                                      const std::string& name) {
    const fs::path png = dir_ / name;
    const testing::ChromiumRun run = testing::ChromiumScreenshot(
        chromium, dir_.string(), FileUrl(Page(), options), png.string(), kWidth, kHeight);
    testing::RgbImage image;
    std::string error;
    EXPECT_TRUE(testing::ReadPng(png.string(), &image, &error))
        << error << "\nchromium exit " << run.exit_code << ":\n"
        << run.err;
    return image;
  }

  inline static fs::path dir_;
  inline static CliRun spherized_;
  inline static std::vector<CliRun> views_;
};

TEST_F(CliViewRobot, PageCarriesEveryLinkJointAndSphere) {
  const std::string html = Slurp(Page());
  EXPECT_THAT(html, HasSubstr("three.js 0.147.0"));
  EXPECT_EQ(Count(html, " src="), 0);
  const nlohmann::json data = PageData(html);
  ASSERT_TRUE(data.is_object());
  ASSERT_EQ(data.at("links").size(), 7u);
  EXPECT_EQ(data.at("joints").size(), 6u);
  ASSERT_EQ(data.at("variables").size(), 3u);  // shoulder, extend, finger_left_joint
  EXPECT_EQ(data.at("variables")[0].at("joint"), "shoulder");
  EXPECT_EQ(data.at("variables")[1].at("joint"), "extend");
  EXPECT_EQ(data.at("variables")[2].at("joint"), "finger_left_joint");
  // The mimic of a mimic resolves to the variable at its end: 2 * (-1 * q + 0.1) - 0.05.
  const nlohmann::json& tip = data.at("joints")[4];
  EXPECT_EQ(tip.at("variable"), 2);
  EXPECT_DOUBLE_EQ(tip.at("multiplier").get<double>(), -2.0);
  EXPECT_DOUBLE_EQ(tip.at("offset").get<double>(), 0.15);

  // Both sphere files carry the same spheres; every spherized link has some, inside its
  // geometry (inscribe urdf's spheres are internal), and the camera is named as a problem.
  const nlohmann::json yaml = PageData(Slurp(Page("spheres.yml")));
  EXPECT_EQ(data.at("spheres").at("format"), "urdf");
  EXPECT_EQ(yaml.at("spheres").at("format"), "yaml");
  EXPECT_EQ(yaml.at("spheres").at("count"), data.at("spheres").at("count"));
  EXPECT_EQ(data.at("spheres").at("protruding"), 0);
  for (std::size_t l = 0; l < 6; ++l) {
    SCOPED_TRACE(data.at("links")[l].at("name").get<std::string>());
    const nlohmann::json& g = data.at("geometry")[l];
    EXPECT_GT(g.at("spheres").size(), 0u);
    EXPECT_EQ(g.at("spheres"), yaml.at("geometry")[l].at("spheres"));
    ASSERT_TRUE(g.at("protrusion").is_array());
    EXPECT_EQ(g.at("problems").size(), 0u);
  }
  EXPECT_EQ(data.at("geometry")[5].at("shapes").size(), 4u);  // the tip's <sphere>
  const nlohmann::json& camera = data.at("geometry")[6];
  EXPECT_EQ(camera.at("spheres").size(), 0u);
  ASSERT_EQ(camera.at("problems").size(), 1u);
  EXPECT_THAT(camera.at("problems")[0].get<std::string>(), HasSubstr("camera.dae"));
}

TEST_F(CliViewRobot, PageForwardKinematicsEqualsKinematicsLinkPoses) {
  const std::string chromium = Chromium();
  ASSERT_FALSE(chromium.empty());
  absl::StatusOr<robot::UrdfRobot> urdf = robot::ParseUrdf(kRobot);
  ASSERT_TRUE(urdf.ok()) << urdf.status();
  absl::StatusOr<robot::Kinematics> kinematics = robot::Kinematics::Create(*urdf);
  ASSERT_TRUE(kinematics.ok()) << kinematics.status();
  // Home, inside the limits, at the limits and outside them (used as given).
  const std::vector<std::vector<double>> configurations = {
      {0.0, 0.0, 0.0}, {0.7, 0.15, -0.3}, {-1.5, 0.3, 0.5}, {3.1, -0.4, 2.2}};
  for (const std::vector<double>& q : configurations) {
    const std::string fragment = absl::StrFormat("q=%.17g,%.17g,%.17g", q[0], q[1], q[2]);
    SCOPED_TRACE(fragment);
    absl::StatusOr<std::vector<Eigen::Isometry3d>> poses = kinematics->LinkPoses(q);
    ASSERT_TRUE(poses.ok()) << poses.status();
    bool found = false;
    const std::string dom = DumpDom(chromium, Page(), fragment);
    const std::string text = testing::BodyAttribute(dom, "data-link-poses", &found);
    ASSERT_TRUE(found) << dom.substr(0, 2000);
    std::vector<double> page;
    for (absl::string_view number : absl::StrSplit(text, ',')) {
      page.push_back(std::stod(std::string(number)));
    }
    ASSERT_EQ(page.size(), 12 * poses->size());
    for (std::size_t l = 0; l < poses->size(); ++l) {
      const Eigen::Matrix<double, 3, 4> expected = (*poses)[l].matrix().topRows<3>();
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 4; ++j) {
          EXPECT_NEAR(page[12 * l + 4 * i + j], expected(i, j), 1e-12)
              << kinematics->link_name(static_cast<int>(l)) << " (" << i << ", " << j << ")";
        }
      }
    }
  }
}

TEST_F(CliViewRobot, HeadlessChromiumDrawsTheRobotWithASliderPerJoint) {
  const std::string chromium = Chromium();
  ASSERT_FALSE(chromium.empty());
  bool found = false;
  const std::string dom = DumpDom(chromium, Page());
  const std::string error = testing::BodyAttribute(dom, "data-error", &found);
  EXPECT_FALSE(found) << error;
  EXPECT_THAT(dom, HasSubstr("(rendered)</title>"));
  EXPECT_EQ(testing::BodyAttribute(dom, "data-sliders", &found), "3");
  EXPECT_EQ(Count(dom, "class=\"joint-slider\""), 3);
  EXPECT_THAT(dom, HasSubstr("data-joint=\"finger_left_joint\""));
  // The link that cannot be shown is named in the panel.
  EXPECT_THAT(dom, ContainsRegex("<div class=\"problem\">line [0-9]+ \\(&lt;visual&gt;\\): "
                                 "[^<]*camera.dae"));
  const nlohmann::json data = PageData(Slurp(Page()));
  const std::string all = std::to_string(data.at("spheres").at("count").get<int>());
  EXPECT_EQ(testing::BodyAttribute(dom, "data-spheres-drawn", &found), all);
  // Hiding a link hides its spheres.
  const std::string hidden = DumpDom(chromium, Page(), "hide=base");
  const int base = static_cast<int>(data.at("geometry")[0].at("spheres").size() / 4);
  EXPECT_EQ(testing::BodyAttribute(hidden, "data-spheres-drawn", &found),
            std::to_string(data.at("spheres").at("count").get<int>() - base));

  const testing::RgbImage page = Screenshot(chromium, "", "robot.png");
  ASSERT_EQ(page.width, kWidth);
  const testing::PixelRegion viewport = {kPanelWidth + 10, 0, kWidth, kHeight};
  EXPECT_GT(testing::DistinctColours(page, viewport), 300);
  EXPECT_GT(testing::FractionUnlike(page, viewport, kBackground, 8), 0.02);
  // Spheres alone, nothing, and the arm moved: each changes the picture.
  const testing::RgbImage spheres = Screenshot(chromium, "panel=0&meshes=0", "spheres.png");
  const testing::RgbImage empty = Screenshot(chromium, "panel=0&meshes=0&spheres=0", "empty.png");
  const testing::RgbImage moved =
      Screenshot(chromium, "panel=0&meshes=0&q=1.5,0.3,0.5", "moved.png");
  ASSERT_EQ(spheres.width, kWidth);
  ASSERT_EQ(empty.width, kWidth);
  ASSERT_EQ(moved.width, kWidth);
  const testing::PixelRegion all_pixels = testing::WholeImage(spheres);
  EXPECT_LT(testing::FractionUnlike(empty, all_pixels, kBackground, 8), 0.001);
  EXPECT_GT(testing::FractionUnlike(spheres, all_pixels, kBackground, 8), 0.02);
  EXPECT_GT(testing::FractionDiffering(moved, spheres, all_pixels, 8), 0.01);
  // Colour by error: these spheres are all inside, so they turn grey.
  const testing::RgbImage grey = Screenshot(chromium, "panel=0&meshes=0&color=error", "grey.png");
  ASSERT_EQ(grey.width, kWidth);
  EXPECT_GT(testing::FractionDiffering(grey, spheres, all_pixels, 24), 0.02);
}

TEST_F(CliViewRobot, BadInputIsAClearError) {
  const fs::path bad = dir_ / "bad";
  fs::create_directories(bad);
  const std::string robot = Quote(Robot()), spheres = Quote((dir_ / "spheres.yml").string());
  const std::string out = " -o " + Quote((bad / "page.html").string());
  WriteText(bad / "stranger.yml",
            "collision_spheres:\n  gripper_palm:\n    - center: [0, 0, 0]\n      radius: 0.1\n");
  WriteText(bad / "garbage.yml", "\x01\x02 this: [is not\n");
  WriteText(bad / "none.urdf", "<robot name=\"gripperbot\"><link name=\"base\"/></robot>");
  WriteText(bad / "broken.urdf", "<robot name=\"x\"><link name=\"a\"></robot>");
  std::string cycle = kRobot;
  cycle.replace(cycle.find("<child link=\"arm\"/>"), 19, "<child link=\"base\"/>");
  WriteText(bad / "cycle.urdf", cycle);
  struct Case {
    std::string args;
    int exit_code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {robot + " " + Quote((bad / "stranger.yml").string()) + out, 2, "gripper_palm"},
      {robot + " " + Quote((bad / "garbage.yml").string()) + out, 2, "garbage.yml"},
      {robot + " " + Quote((bad / "none.urdf").string()) + out, 2, "no <collision> with <sphere>"},
      {robot + " " + Quote((bad / "missing.yml").string()) + out, 2, "missing.yml"},
      {Quote((bad / "missing.urdf").string()) + " " + spheres + out, 2, "missing.urdf"},
      {Quote((bad / "broken.urdf").string()) + " " + spheres + out, 2, "broken.urdf"},
      {Quote((bad / "cycle.urdf").string()) + " " + spheres + out, 2, "cycle.urdf"},
      {robot + " " + spheres + " --link base" + out, 64, "--link applies to a mesh"},
      {robot + " " + spheres + " -o " + spheres, 64, "overwrite the sphere file"},
      {Quote(testing::TestMeshPath("eight.off")) + " " + spheres + " --package-path /tmp" + out, 64,
       "--package-path applies to a robot"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    const CliRun run = RunCli("view " + c.args);
    EXPECT_EQ(run.exit_code, c.exit_code) << run.err;
    EXPECT_THAT(run.err, HasSubstr(c.message));
    EXPECT_EQ(run.out, "");
  }
  EXPECT_FALSE(fs::exists(bad / "page.html"));
}

}  // namespace
}  // namespace inscribe
