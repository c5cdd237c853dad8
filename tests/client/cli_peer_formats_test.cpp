// Peers' sphere files through the command line: cuRobo YAML (one link or a whole robot) and
// spheretree .sph written by `generate`, then read back by `evaluate`, `distance` and
// `deform` with the same results as inscribe's own JSON; `convert` between every format.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "client/cli_run.h"
#include "inscribe/balls/sphere_io.h"
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
  EXPECT_THAT(yaml, HasSubstr("collision_spheres:\n  \"eight_link\":\n"));
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

// evaluate --certify on a cover written as spheretree .sph, CSV and a cuRobo robot YAML (the
// cover one link of two, picked with --link): each is certified with the JSON's delta, and the
// internal set beside it in the same robot file is not.
TEST_F(CliPeerFormats, CertifyReadsCoversInEveryPeerFormat) {
  const std::string cover_json = Path("cover.json");
  ASSERT_EQ(
      RunCli("generate " + mesh_ + " --cover --max-spheres 60 -o " + Quote(cover_json)).exit_code,
      0);
  absl::StatusOr<SphereFile> cover = ReadSphereFile(cover_json);
  ASSERT_TRUE(cover.ok()) << cover.status();
  absl::StatusOr<SphereFile> internal = ReadSphereFile(Path("eight.json"));
  ASSERT_TRUE(internal.ok()) << internal.status();
  for (const char* extension : {"sph", "csv"}) {
    ASSERT_TRUE(WriteSphereFile(Path(std::string("cover.") + extension), *cover).ok());
  }
  absl::StatusOr<std::string> robot =
      FormatCuroboYaml({{"arm", internal->set.spheres}, {"arm_cover", cover->set.spheres}});
  ASSERT_TRUE(robot.ok()) << robot.status();
  std::ofstream(Path("robot.yml")) << *robot;

  const auto certify = [&](const std::string& spheres, const std::string& extra) {
    return RunCli("evaluate --certify --json " + mesh_ + " " + Quote(spheres) + " " + extra);
  };
  const CliRun reference = certify(cover_json, "");
  ASSERT_EQ(reference.exit_code, 0) << reference.err;
  const double delta = nlohmann::json::parse(reference.out).at("delta").get<double>();
  for (const auto& [file, extra] :
       std::vector<std::pair<std::string, std::string>>{{Path("cover.sph"), ""},
                                                        {Path("cover.csv"), ""},
                                                        {Path("robot.yml"), "--link arm_cover"}}) {
    SCOPED_TRACE(file + " " + extra);
    const CliRun run = certify(file, extra);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const nlohmann::json j = nlohmann::json::parse(run.out);
    EXPECT_TRUE(j.at("certified").get<bool>());
    EXPECT_EQ(j.at("delta").get<double>(), delta);
  }
  const CliRun arm = certify(Path("robot.yml"), "--link arm");
  EXPECT_EQ(arm.exit_code, 1) << arm.err;
  EXPECT_FALSE(nlohmann::json::parse(arm.out).at("certified").get<bool>());
  EXPECT_TRUE(nlohmann::json::parse(arm.out).contains("uncovered_point"));
}

// A cover made on the mesh in millimetres (generate --scale 1000), converted to metres
// (convert --scale 0.001), certifies on the metre mesh; the conversion says what it drops.
TEST_F(CliPeerFormats, ConvertScalesACoverMadeInMillimetresBackToMetres) {
  const std::string mm = Path("cover_mm.json"), m = Path("cover_m.json");
  const CliRun made =
      RunCli("generate " + mesh_ + " --scale 1000 --cover --max-spheres 40 -o " + Quote(mm));
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const CliRun converted = RunCli("convert --json " + Quote(mm) + " --scale 0.001 -o " + Quote(m));
  ASSERT_EQ(converted.exit_code, 0) << converted.err;
  EXPECT_THAT(converted.err,
              AllOf(HasSubstr("--scale 0.001"), HasSubstr("mesh hash"), HasSubstr("certificate")));
  const nlohmann::json summary = nlohmann::json::parse(converted.out);
  EXPECT_EQ(summary.at("scale").get<double>(), 0.001);
  EXPECT_EQ(summary.at("mesh_sha256").get<std::string>(), "");
  absl::StatusOr<SphereFile> before = ReadSphereFile(mm), after = ReadSphereFile(m);
  ASSERT_TRUE(before.ok() && after.ok());
  ASSERT_EQ(before->set.spheres.size(), after->set.spheres.size());
  for (std::size_t i = 0; i < after->set.spheres.size(); ++i) {
    EXPECT_EQ(after->set.spheres[i].radius, before->set.spheres[i].radius * 0.001) << i;
  }
  EXPECT_TRUE(after->stats.empty());  // the millimetre certificate is not carried over
  const CliRun certify = RunCli("evaluate --certify --json " + mesh_ + " " + Quote(m));
  ASSERT_EQ(certify.exit_code, 0) << certify.err;
  EXPECT_TRUE(nlohmann::json::parse(certify.out).at("certified").get<bool>());
  const CliRun bad = RunCli("convert " + Quote(mm) + " --scale -2 -o " + Quote(Path("x.json")));
  EXPECT_EQ(bad.exit_code, 64);
  EXPECT_THAT(bad.err, AllOf(HasSubstr("--scale"), HasSubstr("> 0")));
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

// The spheres of a file as the core reads them, bit for bit comparable.
std::vector<Sphere> SpheresOf(const std::string& path, const SphereFileReadOptions& read = {}) {
  absl::StatusOr<SphereFile> file = ReadSphereFile(path, read);
  EXPECT_TRUE(file.ok()) << file.status();
  return file.ok() ? file->set.spheres : std::vector<Sphere>{};
}

void ExpectSameSpheres(const std::vector<Sphere>& a, const std::vector<Sphere>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].center, b[i].center) << "sphere " << i;
    EXPECT_EQ(a[i].radius, b[i].radius) << "sphere " << i;
  }
}

TEST_F(CliPeerFormats, ConvertCarriesEverySphereBitForBitThroughEveryFormat) {
  const std::vector<Sphere> original = SpheresOf(Path("eight.json"));
  ASSERT_GT(original.size(), 10u);

  const CliRun to_sph =
      RunCli("convert " + Quote(Path("eight.json")) + " -o " + Quote(Path("c.sph")));
  ASSERT_EQ(to_sph.exit_code, 0) << to_sph.err;
  EXPECT_THAT(to_sph.out, HasSubstr("wrote " + std::to_string(original.size()) + " spheres"));
  // What .sph cannot hold is named, not lost silently.
  EXPECT_THAT(to_sph.err, AllOf(HasSubstr("left out"), HasSubstr("contacts"), HasSubstr("params")));
  EXPECT_THAT(Slurp(Path("c.sph")), ::testing::StartsWith("2 " + std::to_string(original.size())));

  const CliRun to_yaml = RunCli("convert " + Quote(Path("c.sph")) + " -o " + Quote(Path("c.yml")) +
                                " --yaml-link arm/link_1 --json");
  ASSERT_EQ(to_yaml.exit_code, 0) << to_yaml.err;
  const nlohmann::json summary = nlohmann::json::parse(to_yaml.out);
  EXPECT_EQ(summary.at("spheres"), original.size());
  EXPECT_EQ(summary.at("format"), "yaml");
  EXPECT_TRUE(summary.at("left_out").empty());  // .sph had nothing but spheres
  EXPECT_THAT(Slurp(Path("c.yml")), HasSubstr("collision_spheres:\n  \"arm/link_1\":\n"));

  // The link read is the link written, unless --yaml-link says otherwise; stdout by default.
  const CliRun to_csv = RunCli("convert " + Quote(Path("c.yml")) + " --link arm/link_1 --to csv");
  ASSERT_EQ(to_csv.exit_code, 0) << to_csv.err;
  std::ofstream(Path("c.csv")) << to_csv.out;
  const CliRun to_json = RunCli("convert " + Quote(Path("c.csv")) + " -o " + Quote(Path("c.json")));
  ASSERT_EQ(to_json.exit_code, 0) << to_json.err;
  // JSON holds all a CSV has: no warning, only the line naming what was written.
  EXPECT_EQ(to_json.err, "inscribe: wrote " + Path("c.json") + " (" +
                             std::to_string(original.size()) + " spheres, json)\n");

  for (const char* name : {"c.sph", "c.csv", "c.json"}) {
    SCOPED_TRACE(name);
    ExpectSameSpheres(SpheresOf(Path(name)), original);
  }
  SphereFileReadOptions link;
  link.yaml_link = "arm/link_1";
  ExpectSameSpheres(SpheresOf(Path("c.yml"), link), original);
  // And evaluate agrees with the original on the converted file.
  EXPECT_EQ(Evaluate(Path("c.json")).at("nerr").get<double>(),
            Evaluate(Path("eight.json")).at("nerr").get<double>());

  // OBJ is for viewers: one icosphere (42 vertices at subdivision 1) per sphere.
  const CliRun to_obj = RunCli("convert " + Quote(Path("eight.json")) + " --to obj");
  ASSERT_EQ(to_obj.exit_code, 0) << to_obj.err;
  std::size_t vertices = 0;
  for (std::size_t at = to_obj.out.find("\nv "); at != std::string::npos;
       at = to_obj.out.find("\nv ", at + 1)) {
    ++vertices;
  }
  EXPECT_EQ(vertices, 42 * original.size());
}

TEST_F(CliPeerFormats, ConvertReadsTheSphTreeLevelAsked) {
  // A spheretree tree of 3 levels, degree 2: root, 2 children, 4 leaves of which one unused.
  std::ofstream(Path("tree.sph")) << "3 2\n0 0 0 4 1\n-1 0 0 2 1\n1 0 0 2 1\n"
                                     "-1.5 0 0 1 1\n-0.5 0 0 1 1\n1.5 0 0 1 1\n0 0 0 0 0\n";
  const CliRun leaves = RunCli("convert " + Quote(Path("tree.sph")) + " --to csv");
  ASSERT_EQ(leaves.exit_code, 0) << leaves.err;
  EXPECT_EQ(leaves.out, "x,y,z,r\n-1.5,0,0,1\n-0.5,0,0,1\n1.5,0,0,1\n");
  const CliRun level1 = RunCli("convert " + Quote(Path("tree.sph")) + " --sph-level 1 --to csv");
  ASSERT_EQ(level1.exit_code, 0) << level1.err;
  EXPECT_EQ(level1.out, "x,y,z,r\n-1,0,0,2\n1,0,0,2\n");
}

TEST_F(CliPeerFormats, ConvertRefusesBadInputAndOptionsClearly) {
  const std::string json = Quote(Path("eight.json"));
  const auto expect = [](const CliRun& run, int code, const std::string& message) {
    EXPECT_EQ(run.exit_code, code) << run.err;
    EXPECT_THAT(run.err, HasSubstr(message));
  };
  expect(RunCli("convert " + Quote(Path("missing.json"))), 2, "missing.json");
  std::ofstream(Path("garbage.csv")) << "1,2,3,4\n1,2,three,4\n";
  expect(RunCli("convert " + Quote(Path("garbage.csv"))), 2, "line 2");
  std::ofstream(Path("negative.csv")) << "1,2,3,-4\n";
  expect(RunCli("convert " + Quote(Path("negative.csv"))), 2, "radius -4 is not positive");
  expect(RunCli("convert " + json + " -o " + Quote(Path("out.txt"))), 64, "--to");
  expect(RunCli("convert " + json + " -o " + Quote(Path("no/such/dir/out.sph"))), 2, "no/such/dir");
  expect(RunCli("convert " + json + " --to yaml --yaml-link 'two words'"), 64, "two words");
  expect(RunCli("convert " + json + " --json"), 64, "needs -o");
  expect(RunCli("convert " + json + " --from obj"), 64, "obj");
  // A robot file with two links names them when none is picked.
  std::ofstream(Path("two.yml")) << "collision_spheres:\n  a:\n    - center: [0, 0, 0]\n"
                                    "      radius: 1\n  b:\n    - center: [1, 0, 0]\n"
                                    "      radius: 1\n";
  expect(RunCli("convert " + Quote(Path("two.yml"))), 2, "a, b");
  // Nothing half-written is left behind by a refused conversion.
  EXPECT_FALSE(fs::exists(Path("out.txt")));
}

}  // namespace
}  // namespace inscribe
