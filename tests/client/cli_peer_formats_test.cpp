// Peers' sphere files through the command line: cuRobo YAML (one link or a whole robot) and
// spheretree .sph written by `generate`, then read back by `evaluate`, `distance` and
// `deform` with the same results as inscribe's own JSON.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "client/cli_run.h"
#include "inscribe/sphere_io.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

class CliPeerFormats : public ::testing::Test {
 protected:
  void SetUp() override {
    INSCRIBE_REQUIRE_MESH("eight.off");
    dir_ = fs::temp_directory_path() / ("inscribe_cli_peer_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    mesh_ = Quote(testing::TestMeshPath("eight.off"));
    for (const char* extension : {"json", "sph", "yml"}) {
      const CliRun run = RunCli("generate " + mesh_ + " --voxel-size 0.08 --link eight_link -o " +
                                Quote(Path(std::string("eight.") + extension)));
      ASSERT_EQ(run.exit_code, 0) << run.err;
    }
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // `evaluate --json` of a sphere file, parsed.
  nlohmann::json Evaluate(const std::string& spheres, const std::string& extra = "") {
    const CliRun run =
        RunCli("evaluate --json --samples 2000 " + mesh_ + " " + Quote(spheres) + " " + extra);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return run.exit_code == 0 ? nlohmann::json::parse(run.out) : nlohmann::json::object();
  }

  fs::path dir_;
  std::string mesh_;
};

TEST_F(CliPeerFormats, YamlAndSphEvaluateExactlyAsJson) {
  const nlohmann::json json = Evaluate(Path("eight.json"));
  const std::string yaml = Slurp(Path("eight.yml"));
  EXPECT_THAT(yaml, HasSubstr("collision_spheres:\n  eight_link:\n"));
  for (const char* name : {"eight.yml", "eight.sph"}) {
    SCOPED_TRACE(name);
    const nlohmann::json peer = Evaluate(Path(name));
    EXPECT_EQ(peer.at("spheres"), json.at("spheres"));
    EXPECT_EQ(peer.at("nerr").get<double>(), json.at("nerr").get<double>());
    EXPECT_EQ(peer.at("nerr_kind"), "exact");
  }
}

TEST_F(CliPeerFormats, ARobotYamlIsReadOneLinkAtATime) {
  // A cuRobo robot file: our link next to another with a placeholder sphere.
  const std::string robot = Path("robot.yml");
  // Every line of eight.yml under "collision_spheres:" moves 4 spaces in, under robot_cfg.
  const std::string text = Slurp(Path("eight.yml"));
  const std::size_t block = text.find("collision_spheres:\n");
  ASSERT_NE(block, std::string::npos);
  std::string indented = "robot_cfg:\n  kinematics:\n    collision_spheres:\n";
  for (std::size_t start = text.find('\n', block) + 1; start < text.size();) {
    const std::size_t end = text.find('\n', start);
    indented += "    " + text.substr(start, end - start) + "\n";
    start = end + 1;
  }
  indented += "      gripper:\n        - center: [0, 0, 0]\n          radius: -10\n";
  std::ofstream(robot) << indented;

  const CliRun ambiguous = RunCli("evaluate " + mesh_ + " " + Quote(robot));
  EXPECT_EQ(ambiguous.exit_code, 2);
  EXPECT_THAT(ambiguous.err,
              AllOf(HasSubstr("robot.yml"), HasSubstr("eight_link, gripper"), HasSubstr("--link")));
  const CliRun unknown = RunCli("evaluate " + mesh_ + " " + Quote(robot) + " --link elbow");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err, HasSubstr("no link 'elbow'"));

  const nlohmann::json picked = Evaluate(robot, "--link eight_link");
  EXPECT_EQ(picked.at("nerr").get<double>(), Evaluate(Path("eight.json")).at("nerr").get<double>());
  // gripper has only cuRobo's placeholder: no sphere, so nothing of the mesh is covered.
  const nlohmann::json empty = Evaluate(robot, "--link gripper");
  EXPECT_EQ(empty.at("spheres"), 0);
  EXPECT_EQ(empty.at("nerr").get<double>(), 1.0);
}

TEST_F(CliPeerFormats, DistanceReadsYamlLinksAndSphLevels) {
  std::ofstream(Path("poses.txt")) << "1 0 0 0 3 0 0\n1 0 0 0 0.5 0.2 0\n0.7071067811865476 0 "
                                      "0.7071067811865476 0 2 1 0\n";
  const std::string poses = " --poses " + Quote(Path("poses.txt"));
  const CliRun json =
      RunCli("distance " + Quote(Path("eight.json")) + " " + Quote(Path("eight.json")) + poses);
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const CliRun peer =
      RunCli("distance " + Quote(Path("eight.yml")) + " " + Quote(Path("eight.sph")) + poses +
             " --link-a eight_link --sph-level-b -1");
  ASSERT_EQ(peer.exit_code, 0) << peer.err;
  EXPECT_EQ(peer.out, json.out);  // the same spheres, bit for bit, give the same CSV
  const CliRun wrong = RunCli("distance " + Quote(Path("eight.yml")) + " " +
                              Quote(Path("eight.json")) + poses + " --link-a nope");
  EXPECT_EQ(wrong.exit_code, 2);
  EXPECT_THAT(wrong.err, HasSubstr("no link 'nope'"));
}

TEST_F(CliPeerFormats, FormatOptionReadsYamlWhateverTheExtension) {
  fs::copy_file(Path("eight.yml"), Path("spheres.txt"));
  const nlohmann::json by_option = Evaluate(Path("spheres.txt"), "--format yaml");
  const nlohmann::json sniffed = Evaluate(Path("spheres.txt"));
  EXPECT_EQ(by_option.at("nerr").get<double>(), sniffed.at("nerr").get<double>());
  EXPECT_EQ(by_option.at("spheres"), Evaluate(Path("eight.json")).at("spheres"));
}

}  // namespace
}  // namespace inscribe
