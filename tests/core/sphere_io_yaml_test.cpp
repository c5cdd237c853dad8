// cuRobo YAML sphere files: several links, whole robot configurations, cuRobo's placeholder
// spheres, link selection, and the errors a user sees for each kind of bad file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "inscribe/balls/sphere_io.h"

namespace inscribe {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

std::string Message(const absl::Status& status) {
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
  return std::string(status.message());
}

template <typename T>
std::string Message(const absl::StatusOr<T>& value) {
  return value.ok() ? std::string("(ok)") : Message(value.status());
}

// As cuRobo's robot configurations lay it out: the block under robot_cfg/kinematics, next to
// other keys, with a placeholder sphere of negative radius and integers written without '.'.
constexpr char kRobotConfig[] = R"(robot_cfg:
  kinematics:
    base_link: "base_link"
    ee_link: "tool0"
    collision_link_names: ["base_link", "forearm"]
    collision_spheres:
      base_link:
        - "center": [0.0, 0.0, 0.05]
          "radius": 0.08
        - center: [0, 0.1, 1e-2]
          radius: 5.0e-2
      forearm:
        - "center": [0.2, 0.0, 0.0]
          "radius": 0.06
        - "center": [0.0, 0.0, 0.0]
          "radius": -100
      tool0: []
    self_collision_buffer: {"base_link": 0.0}
)";

TEST(CuroboYaml, ReadsEveryLinkOfARobotConfigurationAndDropsPlaceholders) {
  const absl::StatusOr<std::vector<LinkSpheres>> links = ParseCuroboYaml(kRobotConfig);
  ASSERT_TRUE(links.ok()) << links.status();
  ASSERT_EQ(links->size(), 3u);
  EXPECT_EQ((*links)[0].link, "base_link");
  ASSERT_EQ((*links)[0].spheres.size(), 2u);
  EXPECT_EQ((*links)[0].spheres[1].center, Vector3(0, 0.1, 0.01));
  EXPECT_EQ((*links)[0].spheres[1].radius, 0.05);
  EXPECT_EQ((*links)[1].link, "forearm");
  EXPECT_EQ((*links)[1].spheres.size(), 1u);  // the radius -100 placeholder is gone
  EXPECT_EQ((*links)[2].link, "tool0");
  EXPECT_TRUE((*links)[2].spheres.empty());
}

TEST(CuroboYaml, SphereFileReadsOneLinkByName) {
  SphereFileReadOptions options;
  options.yaml_link = "forearm";
  const absl::StatusOr<SphereFile> file =
      ParseSphereFile(kRobotConfig, SphereFileFormat::kYaml, options);
  ASSERT_TRUE(file.ok()) << file.status();
  ASSERT_EQ(file->set.size(), 1u);
  EXPECT_EQ(file->set.spheres[0].center, Vector3(0.2, 0, 0));

  EXPECT_THAT(Message(ParseSphereFile(kRobotConfig, SphereFileFormat::kYaml)),
              AllOf(HasSubstr("3 links (base_link, forearm, tool0)"), HasSubstr("--link")));
  options.yaml_link = "elbow";
  EXPECT_THAT(Message(ParseSphereFile(kRobotConfig, SphereFileFormat::kYaml, options)),
              AllOf(HasSubstr("no link 'elbow'"), HasSubstr("base_link, forearm, tool0")));
}

TEST(CuroboYaml, ManyLinksRoundTripBitExact) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coordinate(-2, 2), radius(1e-6, 0.5);
  std::vector<LinkSpheres> links;
  // Names YAML would read as null, a bool, a number or a float unless quoted (fuzz_urdf).
  for (const char* name : {"panda_link0", "panda_link1", "arm/elbow", "gripper-left.pad", "null",
                           "true", "no", "1", ".inf", "...", "-", "0x1F", "1e3"}) {
    LinkSpheres link{name, {}};
    for (int i = 0; i < 50; ++i) {
      link.spheres.push_back(
          {Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), radius(rng)});
    }
    links.push_back(std::move(link));
  }
  links.push_back({"empty_link", {}});
  links[1].spheres.push_back({Vector3(1e22, -0.0, 5e-324), 1e300});  // awkward numbers
  const absl::StatusOr<std::string> bytes = FormatCuroboYaml(links, "a robot\nsecond line");
  ASSERT_TRUE(bytes.ok()) << bytes.status();
  EXPECT_THAT(*bytes, HasSubstr("# a robot\n# second line\ncollision_spheres:\n"));
  EXPECT_THAT(*bytes, HasSubstr("\"center\": [1.0e+22, -0.0, 5.0e-324]"));  // YAML 1.1 floats
  EXPECT_THAT(*bytes, HasSubstr("  \"empty_link\": []\n"));
  const absl::StatusOr<std::vector<LinkSpheres>> back = ParseCuroboYaml(*bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->size(), links.size());
  for (std::size_t l = 0; l < links.size(); ++l) {
    EXPECT_EQ((*back)[l].link, links[l].link);
    ASSERT_EQ((*back)[l].spheres.size(), links[l].spheres.size());
    for (std::size_t i = 0; i < links[l].spheres.size(); ++i) {
      EXPECT_EQ((*back)[l].spheres[i].center, links[l].spheres[i].center);
      EXPECT_EQ((*back)[l].spheres[i].radius, links[l].spheres[i].radius);
    }
  }
}

TEST(CuroboYaml, WriterRefusesWhatCannotBeReadBack) {
  EXPECT_THAT(Message(FormatCuroboYaml({{"a", {}}, {"a", {}}})),
              HasSubstr("link a is listed twice"));
  EXPECT_THAT(Message(FormatCuroboYaml({{"bad name: x", {}}})), HasSubstr("'bad name: x'"));
  EXPECT_THAT(Message(FormatCuroboYaml({{"", {}}})), HasSubstr("non-empty"));
  EXPECT_THAT(Message(FormatCuroboYaml({{"l", {{Vector3(0, 0, 0), 1}, {Vector3(0, 0, 0), 0}}}})),
              HasSubstr("link l: sphere 1: radius 0 is not positive"));
  EXPECT_EQ(*FormatCuroboYaml({}), "# inscribe spheres\ncollision_spheres: {}\n");
  EXPECT_TRUE(ParseCuroboYaml(*FormatCuroboYaml({}))->empty());
}

TEST(CuroboYaml, EachBadFileGetsAMessageNamingTheProblem) {
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a: [\n")),
              HasSubstr("malformed YAML"));
  EXPECT_THAT(Message(ParseCuroboYaml("robot_cfg: {kinematics: {}}\n")),
              HasSubstr("no collision_spheres mapping"));
  EXPECT_THAT(Message(ParseCuroboYaml("robot_cfg:\n  collision_spheres: spheres/franka.yml\n")),
              AllOf(HasSubstr("line 2"), HasSubstr("'spheres/franka.yml'"),
                    HasSubstr("read that file instead")));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres: [1, 2]\n")),
              HasSubstr("not a mapping from link names"));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a: 3\n")),
              HasSubstr("link 'a' is not a list"));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a:\n    - center: [0, 0]\n"
                                      "      radius: 1\n")),
              AllOf(HasSubstr("line 3"), HasSubstr("link 'a' sphere 0 center is not a list of 3")));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a:\n    - center: [0, 0, 0]\n"
                                      "      radius: 1\n    - center: [0, .nan, 0]\n"
                                      "      radius: 1\n")),
              AllOf(HasSubstr("line 5"), HasSubstr("sphere 1 center '.nan' is not a finite")));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a:\n    - center: [0, 0, 0]\n"
                                      "      radius: big\n")),
              HasSubstr("radius 'big' is not a finite number"));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a:\n    - radius: 1\n")),
              HasSubstr("needs center and radius"));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  a: []\n  a: []\n")),
              HasSubstr("listed twice"));
  EXPECT_THAT(Message(ParseCuroboYaml("collision_spheres:\n  [1]: []\n")),
              HasSubstr("not a plain string"));
  // A UTF-16 byte-order mark: yaml-cpp decodes the rest as UTF-16, which holds no spheres.
  EXPECT_THAT(Message(ParseCuroboYaml("\xff\xfe garbage: [\n")), HasSubstr("no collision_spheres"));
}

TEST(CuroboYaml, DeepNestingIsRefusedNotACrash) {
  // yaml-cpp recurses per nesting level; a hostile file must not overflow the stack.
  const std::string deep = "collision_spheres: " + std::string(100000, '[');
  EXPECT_THAT(Message(ParseCuroboYaml(deep)), HasSubstr("malformed YAML"));
}

}  // namespace
}  // namespace inscribe
