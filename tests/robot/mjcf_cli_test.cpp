// `inscribe urdf` / `inscribe robot` on MuJoCo models: read by content, every body spherized (no
// link of a joint chain listed), the cuRobo YAML written to -o with the bodies' spheres as the
// library gives them, warnings on stderr, the solid chosen by --solid-group / --solid-class, and
// bad models exit 2 naming the line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "client/cli_run.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/mjcf_robot.h"
#include "inscribe/robot/urdf_spherize.h"
#include "mjcf_test_models.h"

namespace inscribe::robot {
namespace {

using mjcf_models::FreshFolder;
using mjcf_models::WriteArm;
using mjcf_models::WriteText;
using ::testing::HasSubstr;

TEST(MjcfCli, EveryBodySpherizedIntoTheYaml) {
  const std::string folder = FreshFolder("mjcf_cli");
  const std::string model = WriteArm(folder);
  const CliRun run = RunCli("robot " + model + " -o " + folder +
                            "/arm_spheres.xml --max-spheres-per-link 5 --samples 100 --json");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json report = nlohmann::json::parse(run.out);
  EXPECT_EQ(report["format"], "mjcf");
  EXPECT_EQ(report["robot"], "arm");
  EXPECT_EQ(report["skipped"], 0);
  std::set<std::string> listed;
  for (const nlohmann::json& link : report["links"]) {
    listed.insert(link["link"].get<std::string>());
    if (link["link"] != "world") {
      EXPECT_EQ(link["status"], "spherized") << link.dump();
    }
  }
  EXPECT_EQ(listed, (std::set<std::string>{"world", "base", "shoulder", "upper", "fore", "hand",
                                           "camera_mount"}));
  EXPECT_THAT(run.err, HasSubstr("'camera_mount'"));  // visual geoms stand in
  // The spherized model is the library's, and the YAML sits beside it.
  EXPECT_EQ(report["output"], folder + "/arm_spheres.xml");
  EXPECT_EQ(report["yaml"], folder + "/arm_spheres.yml");
  EXPECT_THAT(Slurp(folder + "/arm_spheres.xml"), HasSubstr("group=\"3\" mass=\"0\""));
  // The YAML holds every spherized body, as the library spherizes it.
  absl::StatusOr<MjcfModel> parsed = ReadMjcf(model);
  ASSERT_TRUE(parsed.ok());
  UrdfSpherizeOptions options;
  options.max_spheres_per_link = 5;
  absl::StatusOr<RobotSpherizeResult> library = SpherizeRobot(parsed->robot, options);
  ASSERT_TRUE(library.ok());
  absl::StatusOr<std::vector<LinkSpheres>> yaml =
      ParseCuroboYaml(Slurp(folder + "/arm_spheres.yml"));
  ASSERT_TRUE(yaml.ok()) << yaml.status();
  std::map<std::string, std::vector<Sphere>> written;
  for (const LinkSpheres& link : *yaml) written[link.link] = link.spheres;
  EXPECT_EQ(written.size(), parsed->bodies.size() - 1);  // every body but the world
  for (const MjcfBody& body : parsed->bodies) {
    if (body.name == "world") continue;
    ASSERT_TRUE(written.count(body.name)) << body.name;
    const std::vector<Sphere>* spheres = &written[body.name];
    const std::vector<Sphere>& expected =
        library->links[static_cast<std::size_t>(body.link)].spheres;
    ASSERT_EQ(spheres->size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ((*spheres)[i].center, expected[i].center);
      EXPECT_EQ((*spheres)[i].radius, expected[i].radius);
    }
  }
  // The table names the bodies and no joint-chain link; `urdf` reads it the same way.
  const CliRun table =
      RunCli("urdf " + model + " -o " + folder + "/arm2.xml --max-spheres-per-link 3");
  ASSERT_EQ(table.exit_code, 0) << table.err;
  EXPECT_THAT(table.out, HasSubstr("camera_mount"));
  EXPECT_THAT(table.out, ::testing::Not(HasSubstr("fore/elbow")));
}

// The MJCF model's spheres in a planner format (here XRDF) are checked body by body against
// the model's own solid geoms: every spherized body certified, with a delta no looser than the
// spherizer's; one body's spheres shrunk is named as not covered.
TEST(MjcfCli, EvaluateCertifyChecksAnMjcfModelBodyByBody) {
  const std::string folder = FreshFolder("mjcf_cli_certify");
  const std::string model = WriteArm(folder);
  const std::string xrdf = folder + "/arm.xrdf";
  const CliRun made =
      RunCli("robot " + model + " -o " + folder +
             "/out.xml --max-spheres-per-link 5 --samples 100 --json --spheres " + xrdf);
  ASSERT_EQ(made.exit_code, 0) << made.err;
  std::map<std::string, double> generated;
  const nlohmann::json report = nlohmann::json::parse(made.out);
  for (const nlohmann::json& link : report.at("links")) {
    if (link.contains("delta")) generated[link.at("link")] = link.at("delta");
  }
  ASSERT_FALSE(generated.empty());
  const CliRun run = RunCli("evaluate --certify " + model + " " + xrdf + " --json");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_TRUE(j.at("certified").get<bool>());
  int checked = 0;
  for (const nlohmann::json& link : j.at("links")) {
    const std::string name = link.at("link");
    if (!generated.count(name)) continue;
    ++checked;
    EXPECT_LE(link.at("delta").get<double>(), generated.at(name) * (1 + 1e-9) + 1e-12) << link;
  }
  EXPECT_EQ(checked, static_cast<int>(generated.size()));
}

TEST(MjcfCli, SolidByGroupAndRefusals) {
  const std::string folder = FreshFolder("mjcf_cli_refusals");
  const std::string model = WriteArm(folder);
  const CliRun group = RunCli("robot " + model + " -o " + folder +
                              "/g.xml --solid-group 2 --max-spheres-per-link 3 --json");
  ASSERT_EQ(group.exit_code, 0) << group.err;
  // Group 2 (the visual class) leaves the upper arm without solid geoms: its others stand in.
  EXPECT_THAT(group.err, HasSubstr("body 'upper'"));
  const CliRun same =
      RunCli("robot " + model + " -o " + folder + "/a.xml --yaml " + folder + "/a.xml");
  EXPECT_EQ(same.exit_code, 64);
  EXPECT_THAT(same.err, HasSubstr("would overwrite"));
  WriteText(folder + "/bad.xml",
            "<mujoco>\n<worldbody>\n<geom type=\"cone\"/>\n</worldbody>\n</mujoco>");
  const CliRun bad = RunCli("robot " + folder + "/bad.xml -o " + folder + "/bad_out.xml");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err, HasSubstr("bad.xml line 3: <geom type=\"cone\">"));
  WriteText(folder + "/r.urdf", "<robot name=\"r\"><link name=\"a\"/></robot>");
  const CliRun urdf_group =
      RunCli("robot " + folder + "/r.urdf -o " + folder + "/r_out.urdf --solid-group 3");
  EXPECT_EQ(urdf_group.exit_code, 64);
  EXPECT_THAT(urdf_group.err, HasSubstr("choose MJCF geoms"));
}

}  // namespace
}  // namespace inscribe::robot
