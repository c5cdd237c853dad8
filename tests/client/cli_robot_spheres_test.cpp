// A robot's spheres through the command line as users run it: `inscribe urdf --spheres` in every
// planner format, `inscribe convert` between every pair of them, and `evaluate --certify ROBOT
// SPHERES` link by link, on a small robot of primitives and a mesh file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "client/cli_run.h"
#include "inscribe/robot/robot_spheres.h"

namespace inscribe {
namespace {

using robot::RobotSpheres;
using robot::RobotSpheresFormat;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

class RobotSpheresCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("inscribe_robot_spheres_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    // A box as an OFF mesh (outward triangles), 0.1 x 0.06 x 0.04 m.
    std::ofstream(dir_ / "block.off") << "OFF\n8 12 0\n"
                                         "-0.05 -0.03 -0.02\n0.05 -0.03 -0.02\n0.05 0.03 -0.02\n"
                                         "-0.05 0.03 -0.02\n-0.05 -0.03 0.02\n0.05 -0.03 0.02\n"
                                         "0.05 0.03 0.02\n-0.05 0.03 0.02\n"
                                         "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n"
                                         "3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";
    std::ofstream(dir_ / "arm.urdf") << R"(<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="upper">
    <collision><origin xyz="0 0 0.2" rpy="0.3 0 0"/><geometry><cylinder radius="0.04" length="0.3"/></geometry></collision>
    <collision><origin xyz="0 0 0.4"/><geometry><sphere radius="0.05"/></geometry></collision>
  </link>
  <link name="hand"><visual><origin xyz="0.05 0 0" rpy="0 0 0.5"/><geometry><mesh filename="block.off"/></geometry></visual></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.05"/><axis xyz="0 0 1"/><limit lower="-3" upper="3"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="hand"/><origin xyz="0 0 0.45"/><axis xyz="0 1 0"/><limit lower="-2" upper="2"/></joint>
  <joint name="j3" type="fixed"><parent link="hand"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>
</robot>
)";
    const CliRun run =
        RunCli("urdf " + Quote(dir_ / "arm.urdf") + " -o " + Quote(dir_ / "arm_spherized.urdf") +
               " --samples 500 --json" + " --spheres " + Quote(dir_ / "arm.yml") + " --spheres " +
               Quote(dir_ / "arm.xrdf") + " --spheres " + Quote(dir_ / "arm.srdf") + " --spheres " +
               Quote(dir_ / "arm_vamp.urdf") + " --spheres " +
               "morphit:" + Quote(dir_ / "arm_morphit.urdf"));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    report_ = nlohmann::json::parse(run.out);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static fs::path Path(const std::string& name) { return dir_ / name; }

  static RobotSpheres Read(const std::string& name) {
    absl::StatusOr<RobotSpheres> model = robot::ReadRobotSpheresFile(Path(name).string());
    EXPECT_TRUE(model.ok()) << model.status();
    return model.ok() ? *model : RobotSpheres{};
  }

  static inline fs::path dir_;
  static inline nlohmann::json report_;
};

const std::vector<std::pair<std::string, RobotSpheresFormat>>& Files() {
  static const std::vector<std::pair<std::string, RobotSpheresFormat>> files = {
      {"arm.yml", RobotSpheresFormat::kCurobo},
      {"arm.xrdf", RobotSpheresFormat::kXrdf},
      {"arm.srdf", RobotSpheresFormat::kSrdf},
      {"arm_vamp.urdf", RobotSpheresFormat::kUrdf},
      {"arm_morphit.urdf", RobotSpheresFormat::kMorphit}};
  return files;
}

TEST_F(RobotSpheresCli, UrdfWritesEveryFormatWithTheSameSpheres) {
  const RobotSpheres reference = Read("arm.srdf");
  ASSERT_EQ(reference.links.size(), 3u);  // base, upper, hand (tool has no geometry)
  EXPECT_EQ(reference.links[2].link, "hand");
  EXPECT_FALSE(reference.self_collision_ignore.empty());
  for (const auto& [name, format] : Files()) {
    RobotSpheresFormat read_as;
    absl::StatusOr<RobotSpheres> model =
        robot::ReadRobotSpheresFile(Path(name).string(), std::nullopt, &read_as);
    ASSERT_TRUE(model.ok()) << model.status();
    EXPECT_EQ(read_as, format) << name;
    RobotSpheres expected = robot::RobotSpheresCarried(reference, format);
    if (format == RobotSpheresFormat::kUrdf || format == RobotSpheresFormat::kMorphit) {
      expected.robot_name = "arm";
    }
    EXPECT_TRUE(*model == expected) << name;
  }
  EXPECT_EQ(report_.at("spheres_files").size(), 5u);
}

TEST_F(RobotSpheresCli, ConvertGoesBetweenEveryPairOfFormats) {
  const std::vector<std::pair<std::string, std::string>> targets = {
      {"yml", "curobo"}, {"xrdf", "xrdf"}, {"srdf", "srdf"}, {"urdf", "urdf"}, {"urdf", "morphit"}};
  const RobotSpheres reference = Read("arm.srdf");
  int conversions = 0;
  for (const auto& [input, from] : Files()) {
    for (const auto& [extension, to] : targets) {
      const fs::path out = Path("converted_" + to + "." + extension);
      fs::remove(out);
      const CliRun run = RunCli("convert " + Quote(Path(input)) + " -o " + Quote(out) + " --to " +
                                to + " --robot " + Quote(Path("arm.urdf")) + " --json");
      ASSERT_EQ(run.exit_code, 0) << input << " -> " << to << ": " << run.err;
      const nlohmann::json summary = nlohmann::json::parse(run.out);
      EXPECT_EQ(summary.at("format"), to);
      EXPECT_EQ(summary.at("from"), robot::RobotSpheresFormatName(from));
      // What the target leaves out is said, on stderr and in the summary.
      const bool loses_pairs =
          (to == "urdf" || to == "morphit") &&
          (from == RobotSpheresFormat::kCurobo || from == RobotSpheresFormat::kXrdf ||
           from == RobotSpheresFormat::kSrdf);
      if (loses_pairs) {
        EXPECT_THAT(run.err, HasSubstr("leaves out: self_collision_ignore")) << input << to;
      }
      const RobotSpheresFormat target = *robot::ParseRobotSpheresFormat(to);
      absl::StatusOr<RobotSpheres> read = robot::ReadRobotSpheresFile(out.string(), target);
      ASSERT_TRUE(read.ok()) << read.status();
      RobotSpheres expected =
          robot::RobotSpheresCarried(robot::RobotSpheresCarried(reference, from), target);
      if (target == RobotSpheresFormat::kUrdf || target == RobotSpheresFormat::kMorphit) {
        expected.robot_name = "arm";
      }
      EXPECT_TRUE(*read == expected) << input << " -> " << to;
      ++conversions;
    }
  }
  EXPECT_EQ(conversions, 25);
}

TEST_F(RobotSpheresCli, ConvertMergesIntoAnSrdfAndRefusesWhatItCannotDo) {
  const fs::path srdf = Path("moveit.srdf");
  std::ofstream(srdf) << "<robot name=\"arm\"><group name=\"arm\"><chain base_link=\"base\" "
                         "tip_link=\"tool\"/></group><disable_collisions link1=\"hand\" "
                         "link2=\"tool\" reason=\"User\"/></robot>\n";
  CliRun run = RunCli("convert " + Quote(Path("arm.xrdf")) + " -o " + Quote(srdf));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out, HasSubstr("merged into the SRDF there"));
  const std::string merged = Slurp(srdf);
  EXPECT_THAT(merged, HasSubstr("<group name=\"arm\">"));
  EXPECT_THAT(merged, HasSubstr("link1=\"hand\" link2=\"tool\" reason=\"User\""));
  EXPECT_THAT(merged, HasSubstr("<link_sphere_approximation link=\"upper\">"));

  // URDF output needs a robot to write into.
  run = RunCli("convert " + Quote(Path("arm.xrdf")) + " -o " + Quote(Path("x.urdf")));
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("--robot"));
  // A malformed file is named with its line.
  std::ofstream(Path("bad.xrdf")) << "format: xrdf\nformat_version: 1.0\ncollision: [\n";
  run = RunCli("convert " + Quote(Path("bad.xrdf")) + " -o " + Quote(Path("x.yml")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("bad.xrdf (xrdf): line"));
  // --link picks one set, which a robot conversion does not.
  run =
      RunCli("convert " + Quote(Path("arm.yml")) + " -o " + Quote(Path("x.xrdf")) + " --link base");
  EXPECT_EQ(run.exit_code, 64);
}

TEST_F(RobotSpheresCli, EvaluateCertifiesEveryFormatLinkByLink) {
  std::map<std::string, double> generated;
  for (const nlohmann::json& link : report_.at("links")) {
    if (link.contains("delta")) generated[link.at("link")] = link.at("delta");
  }
  ASSERT_EQ(generated.size(), 3u);
  for (const auto& [name, format] : Files()) {
    const CliRun run = RunCli("evaluate --certify " + Quote(Path("arm.urdf")) + " " +
                              Quote(Path(name)) + " --json");
    ASSERT_EQ(run.exit_code, 0) << name << ": " << run.err << run.out;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    EXPECT_TRUE(j.at("certified").get<bool>());
    EXPECT_EQ(j.at("format"), robot::RobotSpheresFormatName(format));
    ASSERT_EQ(j.at("links").size(), 3u);
    for (const nlohmann::json& link : j.at("links")) {
      const double delta = link.at("delta");
      // A sound bound for the link's solid, no looser than the generator's per element.
      EXPECT_GT(delta, 0.0) << link;
      EXPECT_LE(delta, generated.at(link.at("link")) * (1 + 1e-9) + 1e-12) << link;
    }
  }
  // The table names every link.
  const CliRun table =
      RunCli("evaluate --certify " + Quote(Path("arm.urdf")) + " " + Quote(Path("arm.xrdf")));
  EXPECT_EQ(table.exit_code, 0) << table.err;
  EXPECT_THAT(table.out, HasSubstr("every link is a certified cover"));
  EXPECT_THAT(table.out, HasSubstr("hand"));
}

TEST_F(RobotSpheresCli, EvaluateNamesTheLinkThatIsNotCovered) {
  RobotSpheres model = Read("arm.srdf");
  for (LinkSpheres& link : model.links) {
    if (link.link != "hand") continue;
    for (Sphere& s : link.spheres) s.radius *= 0.5;
  }
  const fs::path shrunk = Path("shrunk.srdf");
  std::ofstream(shrunk) << *robot::FormatRobotSpheres(model, RobotSpheresFormat::kSrdf);
  CliRun run =
      RunCli("evaluate --certify " + Quote(Path("arm.urdf")) + " " + Quote(shrunk) + " --json");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_THAT(run.err, HasSubstr("1 of 3 links with geometry are not certified covers"));
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_FALSE(j.at("certified").get<bool>());
  for (const nlohmann::json& link : j.at("links")) {
    EXPECT_EQ(link.at("certified").get<bool>(), link.at("link") != "hand") << link;
    if (link.at("link") == "hand") {
      EXPECT_TRUE(link.contains("uncovered_point")) << link;
      EXPECT_THAT(link.at("note").get<std::string>(), HasSubstr("NOT certified"));
    }
  }
  // A sphere file naming a link the robot lacks, and a robot without --certify, are refused.
  model.links.push_back({"elbow", {Sphere{Vector3::Zero(), 0.1}}});
  std::ofstream(Path("extra.srdf")) << *robot::FormatRobotSpheres(model, RobotSpheresFormat::kSrdf);
  run = RunCli("evaluate --certify " + Quote(Path("arm.urdf")) + " " + Quote(Path("extra.srdf")));
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("names links"));
  EXPECT_THAT(run.err, HasSubstr("elbow"));
  run = RunCli("evaluate " + Quote(Path("arm.urdf")) + " " + Quote(Path("arm.xrdf")));
  EXPECT_EQ(run.exit_code, 64);
  EXPECT_THAT(run.err, HasSubstr("--certify"));
}

}  // namespace
}  // namespace inscribe
