// The robot sphere model (robot_spheres.h): every format pair round trips random robots exactly,
// the readers take hand-written files in each documented layout, SRDF merging keeps what is not
// ours, and malformed files are refused naming the line and the key.
#include "inscribe/robot/robot_spheres.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"

namespace inscribe::robot {
namespace {

using ::testing::HasSubstr;

constexpr RobotSpheresFormat kFormats[] = {RobotSpheresFormat::kCurobo, RobotSpheresFormat::kXrdf,
                                           RobotSpheresFormat::kSrdf, RobotSpheresFormat::kUrdf,
                                           RobotSpheresFormat::kMorphit};

}  // namespace

// Failures print the model, not its bytes.
void PrintTo(const RobotSpheres& m, std::ostream* os) {
  *os << "robot '" << m.robot_name << "' links";
  for (const LinkSpheres& l : m.links) *os << " '" << l.link << "':" << l.spheres.size();
  *os << " pairs " << m.self_collision_ignore.size() << " self buffers "
      << m.self_collision_buffer.size() << " world buffers " << m.collision_buffer.size();
}

namespace {

bool IsUrdf(RobotSpheresFormat format) {
  return format == RobotSpheresFormat::kUrdf || format == RobotSpheresFormat::kMorphit;
}

// Names YAML would read as other types or that look like paths and numbers, all within the
// characters cuRobo's keys carry; none of the form "P_sphere<k>".
std::string OddName(std::mt19937_64& rng, int index) {
  static const char* kWords[] = {"null", "true", "no",     "1",  ".inf", "-",   "a/b", "/x",
                                 "0x1f", "1e3",  "link.0", "--", "_",    "Yes", "off", "nan"};
  std::uniform_int_distribution<int> word(0, std::size(kWords) - 1);
  return absl::StrCat(kWords[word(rng)], index % 3 == 0 ? "" : "-", index);
}

// Doubles of every scale, signs and many digits.
double RandomLength(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-12, 3);
  return mantissa(rng) * std::pow(10.0, exponent(rng));
}

RobotSpheres RandomRobot(std::uint64_t seed, bool odd_xml_names = false) {
  std::mt19937_64 rng(seed);
  RobotSpheres model;
  model.robot_name = odd_xml_names ? "r <&> \"q\"" : absl::StrCat("robot", seed);
  const int links = std::uniform_int_distribution<int>(1, 9)(rng);
  for (int l = 0; l < links; ++l) {
    LinkSpheres link;
    link.link = odd_xml_names ? absl::StrCat("l<", l, ">&'\"") : OddName(rng, l);
    const int n = l == 1 ? 0 : std::uniform_int_distribution<int>(1, 60)(rng);
    for (int i = 0; i < n; ++i) {
      link.spheres.push_back(
          Sphere{Vector3(RandomLength(rng), RandomLength(rng), RandomLength(rng)),
                 std::abs(RandomLength(rng)) + 1e-15});
    }
    model.links.push_back(std::move(link));
  }
  std::bernoulli_distribution coin(0.4);
  static const char* kReasons[] = {"Adjacent", "Never", "Always", "Default", "User"};
  for (int a = 0; a < links; ++a) {
    for (int b = a + 1; b < links; ++b) {
      if (!coin(rng)) continue;
      model.self_collision_ignore[std::minmax(model.links[a].link, model.links[b].link)] =
          kReasons[(a + b) % 5];
    }
    if (coin(rng)) model.self_collision_buffer[model.links[a].link] = RandomLength(rng);
  }
  // Half the robots share one world buffer (cuRobo writes a single number), half have some.
  const double shared = RandomLength(rng);
  for (const LinkSpheres& link : model.links) {
    if (seed % 2 == 0) {
      model.collision_buffer[link.link] = shared;
    } else if (coin(rng)) {
      model.collision_buffer[link.link] = RandomLength(rng);
    }
  }
  return model;
}

// A URDF with every link of `model` (box collisions, revolute chain) and one link of its own.
std::string BaseUrdf(const RobotSpheres& model) {
  tinyxml2::XMLDocument document;
  tinyxml2::XMLElement* robot = document.NewElement("robot");
  robot->SetAttribute("name", model.robot_name.c_str());
  document.InsertEndChild(robot);
  std::vector<std::string> names = {"base"};
  for (const LinkSpheres& link : model.links) names.push_back(link.link);
  for (std::size_t i = 0; i < names.size(); ++i) {
    tinyxml2::XMLElement* link = robot->InsertNewChildElement("link");
    link->SetAttribute("name", names[i].c_str());
    tinyxml2::XMLElement* visual = link->InsertNewChildElement("visual");
    visual->InsertNewChildElement("geometry")
        ->InsertNewChildElement("box")
        ->SetAttribute("size", "0.1 0.2 0.3");
    tinyxml2::XMLElement* collision = link->InsertNewChildElement("collision");
    collision->InsertNewChildElement("geometry")
        ->InsertNewChildElement("box")
        ->SetAttribute("size", "0.1 0.2 0.3");
    if (i == 0) continue;
    tinyxml2::XMLElement* joint = robot->InsertNewChildElement("joint");
    joint->SetAttribute("name", absl::StrCat("j", i).c_str());
    joint->SetAttribute("type", "revolute");
    joint->InsertNewChildElement("parent")->SetAttribute("link", names[i - 1].c_str());
    joint->InsertNewChildElement("child")->SetAttribute("link", names[i].c_str());
    joint->InsertNewChildElement("limit")->SetAttribute("lower", "-1");
  }
  tinyxml2::XMLPrinter printer;
  document.Print(&printer);
  return printer.CStr();
}

absl::StatusOr<RobotSpheres> WriteAndRead(const RobotSpheres& model, RobotSpheresFormat format,
                                          const std::string& base) {
  RobotSpheresWriteOptions options;
  if (IsUrdf(format)) options.base = base;
  absl::StatusOr<std::string> text = FormatRobotSpheres(model, format, options);
  if (!text.ok()) return text.status();
  absl::StatusOr<RobotSpheresFormat> detected = DetectRobotSpheresFormat(*text);
  if (!detected.ok()) return detected.status();
  // MorphIt's layout is told apart by its sphere links, which a robot without spheres lacks.
  const bool has_spheres = !RobotSpheresCarried(model, format).links.empty();
  EXPECT_TRUE(*detected == format || (format == RobotSpheresFormat::kMorphit && !has_spheres &&
                                      *detected == RobotSpheresFormat::kUrdf))
      << RobotSpheresFormatName(format) << " detected as " << RobotSpheresFormatName(*detected);
  return ParseRobotSpheres(*text, format);
}

TEST(RobotSpheres, EveryFormatPairRoundTripsRandomRobotsExactly) {
  int pairs = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const RobotSpheres model = RandomRobot(seed);
    ASSERT_TRUE(CheckRobotSpheres(model).ok()) << CheckRobotSpheres(model);
    const std::string base = BaseUrdf(model);
    for (RobotSpheresFormat a : kFormats) {
      const absl::StatusOr<RobotSpheres> once = WriteAndRead(model, a, base);
      ASSERT_TRUE(once.ok()) << RobotSpheresFormatName(a) << ": " << once.status();
      ASSERT_EQ(*once, RobotSpheresCarried(model, a)) << RobotSpheresFormatName(a);
      for (RobotSpheresFormat b : kFormats) {
        const absl::StatusOr<RobotSpheres> twice = WriteAndRead(*once, b, base);
        ASSERT_TRUE(twice.ok()) << RobotSpheresFormatName(a) << " -> " << RobotSpheresFormatName(b)
                                << ": " << twice.status();
        // The URDF layouts carry the name of the URDF they are written into (the base's).
        RobotSpheres expected = RobotSpheresCarried(RobotSpheresCarried(model, a), b);
        if (IsUrdf(b)) expected.robot_name = model.robot_name;
        EXPECT_EQ(*twice, expected) << "seed " << seed << ": " << RobotSpheresFormatName(a)
                                    << " -> " << RobotSpheresFormatName(b);
        ++pairs;
      }
    }
  }
  EXPECT_EQ(pairs, 12 * 25);
}

TEST(RobotSpheres, XmlFormatsCarryNamesYamlCannot) {
  const RobotSpheres model = RandomRobot(7, /*odd_xml_names=*/true);
  const std::string base = BaseUrdf(model);
  for (RobotSpheresFormat format :
       {RobotSpheresFormat::kSrdf, RobotSpheresFormat::kUrdf, RobotSpheresFormat::kMorphit}) {
    const absl::StatusOr<RobotSpheres> read = WriteAndRead(model, format, base);
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(*read, RobotSpheresCarried(model, format)) << RobotSpheresFormatName(format);
  }
  for (RobotSpheresFormat format : {RobotSpheresFormat::kCurobo, RobotSpheresFormat::kXrdf}) {
    const absl::StatusOr<std::string> text = FormatRobotSpheres(model, format);
    EXPECT_THAT(text.status().message(), HasSubstr("cannot carry the link name 'l<0>&'"));
  }
}

TEST(RobotSpheres, UrdfLayoutsReplaceEachOther) {
  const RobotSpheres model = RobotSpheresCarried(RandomRobot(4), RobotSpheresFormat::kUrdf);
  const std::string base = BaseUrdf(model);
  RobotSpheresWriteOptions options;
  options.base = base;
  const absl::StatusOr<std::string> vamp =
      FormatRobotSpheres(model, RobotSpheresFormat::kUrdf, options);
  ASSERT_TRUE(vamp.ok()) << vamp.status();
  options.base = *vamp;
  const absl::StatusOr<std::string> morphit =
      FormatRobotSpheres(model, RobotSpheresFormat::kMorphit, options);
  ASSERT_TRUE(morphit.ok()) << morphit.status();
  EXPECT_EQ(*ParseRobotSpheres(*morphit, RobotSpheresFormat::kMorphit), model);
  options.base = *morphit;
  const absl::StatusOr<std::string> back =
      FormatRobotSpheres(model, RobotSpheresFormat::kUrdf, options);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(DetectRobotSpheresFormat(*back).value(), RobotSpheresFormat::kUrdf);
  EXPECT_THAT(*back, ::testing::Not(HasSubstr("_sphere0")));
  EXPECT_EQ(*ParseRobotSpheres(*back, RobotSpheresFormat::kUrdf), model);
  // Writing MorphIt over MorphIt replaces the sphere links rather than adding more.
  options.base = *morphit;
  const absl::StatusOr<std::string> again =
      FormatRobotSpheres(model, RobotSpheresFormat::kMorphit, options);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(*again, *morphit);
}

TEST(RobotSpheres, ReadsCuroboRobotFilesAsCuroboLaysThemOut) {
  // A whole robot file (robot_cfg: kinematics:) with a scalar collision_sphere_buffer, a
  // placeholder sphere and the keys cuRobo has beside ours.
  const std::string yaml = R"(robot_cfg:
  kinematics:
    urdf_path: "robot/franka_description/franka_panda.urdf"
    base_link: "base_link"
    ee_link: "panda_hand"
    collision_link_names: ["panda_link0", "panda_hand"]
    collision_spheres:
      panda_link0:
        - "center": [0.0, 0.0, 0.085]
          "radius": 0.03
        - "center": [-0.1, -0.0, 0.085]
          "radius": 0.03
      panda_hand:
        - center: [0, 0, 0]
          radius: -0.01
        - {center: [0.0, -0.075, 0.01], radius: 0.028}
    collision_sphere_buffer: 0.004
    self_collision_ignore: {"panda_link0": ["panda_link1", "panda_hand"], panda_hand: [panda_link0]}
    self_collision_buffer: {"panda_link0": 0.1, 'panda_hand': -0.02}
    use_global_cumul: True
)";
  const absl::StatusOr<RobotSpheres> model = ParseRobotSpheres(yaml, RobotSpheresFormat::kCurobo);
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->links.size(), 2u);
  EXPECT_EQ(model->links[0].link, "panda_link0");
  ASSERT_EQ(model->links[0].spheres.size(), 2u);
  EXPECT_EQ(model->links[0].spheres[1].center, Vector3(-0.1, -0.0, 0.085));
  ASSERT_EQ(model->links[1].spheres.size(), 1u);  // the placeholder is skipped
  EXPECT_EQ(model->links[1].spheres[0].radius, 0.028);
  const std::map<std::string, double> buffer = {{"panda_link0", 0.004}, {"panda_hand", 0.004}};
  EXPECT_EQ(model->collision_buffer, buffer);
  const std::map<std::string, double> self = {{"panda_link0", 0.1}, {"panda_hand", -0.02}};
  EXPECT_EQ(model->self_collision_buffer, self);
  ASSERT_EQ(model->self_collision_ignore.size(), 2u);  // the pair listed both ways is one
  EXPECT_EQ(model->self_collision_ignore.count({"panda_hand", "panda_link0"}), 1u);
  EXPECT_EQ(model->self_collision_ignore.count({"panda_link0", "panda_link1"}), 1u);
  EXPECT_EQ(DetectRobotSpheresFormat(yaml).value(), RobotSpheresFormat::kCurobo);
  // Written back: one number for the shared world buffer.
  const absl::StatusOr<std::string> written =
      FormatRobotSpheres(*model, RobotSpheresFormat::kCurobo);
  ASSERT_TRUE(written.ok());
  EXPECT_THAT(*written, HasSubstr("collision_sphere_buffer: 0.004\n"));
  EXPECT_THAT(*written, HasSubstr("collision_link_names: [\"panda_link0\", \"panda_hand\"]\n"));
}

TEST(RobotSpheres, ReadsXrdfAsTheSpecificationLaysItOut) {
  const std::string xrdf = R"(format: xrdf
format_version: 1.0
modifiers:
  - set_base_frame: "base_link"
cspace:
  joint_names: ["j1"]
  acceleration_limits: [10]
  jerk_limits: [100]
tool_frames: ["tool0"]
collision:
  geometry: "ur_spheres"
  buffer_distance:
    shoulder_link: 0.01
self_collision:
  geometry: "ur_spheres"
  buffer_distance:
    shoulder_link: 0.07
    wrist_1_link: 0.0
  ignore:
    shoulder_link: ["upper_arm_link", "forearm_link"]
geometry:
  other_spheres:
    spheres:
      tool0: [{center: [0, 0, 0], radius: 1}]
  ur_spheres:
    spheres:
      shoulder_link:
        - center: [0.0, 0.0, 0.0]
          radius: 0.06
      upper_arm_link:
        - center: [-0.425, 0.0, 0.138]
          radius: 0.05
        - center: [-0.2125, 1e-3, 0.138]
          radius: 5e-2
)";
  const absl::StatusOr<RobotSpheres> model = ParseRobotSpheres(xrdf, RobotSpheresFormat::kXrdf);
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->links.size(), 2u);
  EXPECT_EQ(model->links[1].link, "upper_arm_link");
  EXPECT_EQ(model->links[1].spheres[1].center, Vector3(-0.2125, 0.001, 0.138));
  EXPECT_EQ(model->links[1].spheres[1].radius, 0.05);
  EXPECT_EQ(model->collision_buffer.at("shoulder_link"), 0.01);
  EXPECT_EQ(model->self_collision_buffer.size(), 2u);
  EXPECT_EQ(model->self_collision_ignore.size(), 2u);
  EXPECT_EQ(model->self_collision_ignore.count({"forearm_link", "shoulder_link"}), 1u);
  EXPECT_EQ(DetectRobotSpheresFormat(xrdf).value(), RobotSpheresFormat::kXrdf);
}

TEST(RobotSpheres, ReadsSrdfSpheresAndDisabledPairs) {
  const std::string srdf = R"(<?xml version="1.0"?>
<robot name="panda">
  <group name="arm"><chain base_link="panda_link0" tip_link="panda_link8"/></group>
  <link_sphere_approximation link="panda_link0">
    <sphere center="0 0 0.05" radius="0.08"/>
    <sphere center="  0.1
      -0.25e-1 3 " radius="1e-2"/>
  </link_sphere_approximation>
  <link_sphere_approximation link="panda_link1"/>
  <disable_collisions link1="panda_link1" link2="panda_link0" reason="Adjacent"/>
  <disable_collisions link1="panda_hand" link2="panda_link5"/>
</robot>
)";
  const absl::StatusOr<RobotSpheres> model = ParseRobotSpheres(srdf, RobotSpheresFormat::kSrdf);
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_EQ(model->robot_name, "panda");
  ASSERT_EQ(model->links.size(), 2u);
  EXPECT_EQ(model->links[0].spheres[1].center, Vector3(0.1, -0.025, 3));
  EXPECT_TRUE(model->links[1].spheres.empty());
  EXPECT_EQ(model->self_collision_ignore.at({"panda_link0", "panda_link1"}), "Adjacent");
  EXPECT_EQ(model->self_collision_ignore.at({"panda_hand", "panda_link5"}), "");
  EXPECT_EQ(DetectRobotSpheresFormat(srdf).value(), RobotSpheresFormat::kSrdf);
}

TEST(RobotSpheres, ReadsVampAndMorphitUrdfsInTheParentLinksFrame) {
  const std::string vamp = R"(<robot name="r">
  <link name="a">
    <visual><geometry><mesh filename="a.stl"/></geometry></visual>
    <collision><origin xyz="0.1 0.2 0.3" rpy="1 2 3"/><geometry><sphere radius="0.05"/></geometry></collision>
    <collision><origin xyz="0 0 -1"/><geometry><sphere radius="2"/></geometry></collision>
  </link>
  <link name="b"><collision><geometry><mesh filename="b.stl"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint>
</robot>)";
  const absl::StatusOr<RobotSpheres> model = ParseRobotSpheres(vamp, RobotSpheresFormat::kUrdf);
  ASSERT_TRUE(model.ok()) << model.status();
  ASSERT_EQ(model->links.size(), 1u);                                    // b is not spherized
  EXPECT_EQ(model->links[0].spheres[0].center, Vector3(0.1, 0.2, 0.3));  // rpy moves no centre
  EXPECT_EQ(model->links[0].spheres[1].radius, 2.0);
  EXPECT_EQ(DetectRobotSpheresFormat(vamp).value(), RobotSpheresFormat::kUrdf);

  // MorphIt: sphere links on fixed joints, one turned a quarter about z with an offset sphere.
  const std::string morphit = R"(<robot name="r">
  <link name="a"><visual><geometry><mesh filename="a.stl"/></geometry></visual></link>
  <link name="a_sphere0">
    <visual><origin xyz="0 0 0"/><geometry><sphere radius="0.01"/></geometry></visual>
    <collision><origin xyz="0 0 0" rpy="0 0 0"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
  <joint name="a_to_a_sphere0" type="fixed"><parent link="a"/><child link="a_sphere0"/>
    <origin xyz="0.5 0 0.25" rpy="0 0 0"/></joint>
  <link name="a_sphere1"><collision><origin xyz="1 0 0"/><geometry><sphere radius="0.02"/></geometry></collision></link>
  <joint name="a_to_a_sphere1" type="fixed"><parent link="a"/><child link="a_sphere1"/>
    <origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/></joint>
  <link name="c_sphere0"><collision><geometry><sphere radius="0.5"/></geometry></collision></link>
  <joint name="free" type="revolute"><parent link="a"/><child link="c_sphere0"/></joint>
</robot>)";
  const absl::StatusOr<RobotSpheres> m = ParseRobotSpheres(morphit, RobotSpheresFormat::kMorphit);
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_EQ(DetectRobotSpheresFormat(morphit).value(), RobotSpheresFormat::kMorphit);
  ASSERT_EQ(m->links.size(), 2u);  // a (with its two sphere links), and c_sphere0 on its own
  EXPECT_EQ(m->links[0].link, "a");
  ASSERT_EQ(m->links[0].spheres.size(), 2u);
  EXPECT_EQ(m->links[0].spheres[0].center, Vector3(0.5, 0, 0.25));
  EXPECT_TRUE(m->links[0].spheres[1].center.isApprox(Vector3(0, 1, 1), 1e-15));
  EXPECT_EQ(m->links[0].spheres[1].radius, 0.02);
  EXPECT_EQ(m->links[1].link, "c_sphere0");  // a revolute joint: a link of its own
}

TEST(RobotSpheres, WritingIntoAnSrdfReplacesOursAndKeepsTheRest) {
  const std::string existing = R"(<?xml version="1.0"?>
<!-- made by the setup assistant -->
<robot name="panda">
  <group name="arm"><chain base_link="a" tip_link="c"/></group>
  <group_state name="ready" group="arm"><joint name="j1" value="0"/></group_state>
  <end_effector name="hand" parent_link="c" group="hand"/>
  <virtual_joint name="world" type="fixed" parent_frame="world" child_link="a"/>
  <link_sphere_approximation link="a"><sphere center="9 9 9" radius="9"/></link_sphere_approximation>
  <link_sphere_approximation link="z"><sphere center="1 1 1" radius="1"/></link_sphere_approximation>
  <disable_collisions link1="b" link2="a" reason="Never"/>
  <disable_collisions link1="c" link2="x" reason="User"/>
</robot>
)";
  RobotSpheres model;
  model.robot_name = "other";
  model.links = {{"a", {Sphere{Vector3(0.1, 0, 0), 0.2}}}, {"b", {}}};
  model.self_collision_ignore = {{{"a", "b"}, "Adjacent"}, {{"a", "c"}, ""}};
  RobotSpheresWriteOptions options;
  options.base = existing;
  const absl::StatusOr<std::string> merged =
      FormatRobotSpheres(model, RobotSpheresFormat::kSrdf, options);
  ASSERT_TRUE(merged.ok()) << merged.status();
  for (const char* kept :
       {"<group name=\"arm\">", "<group_state name=\"ready\"", "<end_effector name=\"hand\"",
        "<virtual_joint name=\"world\"", "made by the setup assistant", "link=\"z\"",
        "<disable_collisions link1=\"c\" link2=\"x\" reason=\"User\"/>",
        "<robot name=\"panda\">"}) {
    EXPECT_THAT(*merged, HasSubstr(kept));
  }
  EXPECT_THAT(*merged, ::testing::Not(HasSubstr("9 9 9")));
  EXPECT_THAT(*merged, ::testing::Not(HasSubstr("reason=\"Never\"")));
  const absl::StatusOr<RobotSpheres> read = ParseRobotSpheres(*merged, RobotSpheresFormat::kSrdf);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(read->robot_name, "panda");
  ASSERT_EQ(read->links.size(), 3u);  // z, then ours
  EXPECT_EQ(read->links[0].link, "z");
  EXPECT_EQ(read->links[1].spheres[0].radius, 0.2);
  EXPECT_EQ(read->self_collision_ignore.size(), 3u);
  EXPECT_EQ(read->self_collision_ignore.at({"a", "b"}), "Adjacent");
  EXPECT_EQ(read->self_collision_ignore.at({"c", "x"}), "User");
}

TEST(RobotSpheres, MalformedFilesAreRefusedNamingTheLineAndTheKey) {
  struct Case {
    RobotSpheresFormat format;
    std::string text;
    std::string message;
  };
  const std::vector<Case> cases = {
      {RobotSpheresFormat::kCurobo,
       "collision_spheres:\n  a:\n    - center: [1, 2]\n      radius: 1\n",
       "line 3: link 'a' sphere 0 center is not a list of 3 numbers"},
      {RobotSpheresFormat::kCurobo, "collision_spheres: {a: []}\nself_collision_ignore: [a]\n",
       "line 2: self_collision_ignore is not a mapping"},
      {RobotSpheresFormat::kCurobo,
       "collision_spheres: {a: []}\nself_collision_buffer:\n  a: .nan\n",
       "line 3: self_collision_buffer of link 'a' is not a finite number"},
      {RobotSpheresFormat::kCurobo, "collision_spheres: {a: []}\nself_collision_ignore: {a: [a]}\n",
       "link 'a' ignores itself"},
      {RobotSpheresFormat::kCurobo, "collision_spheres: {a: []}\ncollision_sphere_buffer: x\n",
       "line 2: collision_sphere_buffer is not a finite number"},
      {RobotSpheresFormat::kCurobo, "collision_spheres: [\n", "malformed YAML"},
      {RobotSpheresFormat::kXrdf, "format: urdf\n", "format is not xrdf"},
      {RobotSpheresFormat::kXrdf, "format: xrdf\nformat_version: 2.0\n",
       "format_version is not 1.x"},
      {RobotSpheresFormat::kXrdf,
       "format: xrdf\nformat_version: 1.0\ncollision: {geometry: g}\nself_collision: {geometry: "
       "h}\n",
       "line 4: collision uses geometry 'g' but self_collision 'h'"},
      {RobotSpheresFormat::kXrdf,
       "format: xrdf\nformat_version: 1.0\ncollision: {geometry: g}\ngeometry: {}\n",
       "geometry has no group 'g'"},
      {RobotSpheresFormat::kXrdf,
       "format: xrdf\nformat_version: 1.0\ncollision: {geometry: g}\ngeometry:\n  g:\n    "
       "spheres:\n      a:\n        - center: [0, 0, 0]\n          radius: 0\n",
       "link 'a' sphere 0 radius is not positive"},
      {RobotSpheresFormat::kSrdf, "<robot><link_sphere_approximation/></robot>",
       "line 1: <link_sphere_approximation> has no link attribute"},
      {RobotSpheresFormat::kSrdf,
       "<robot>\n<link_sphere_approximation link=\"a\">\n<sphere center=\"1 2\" "
       "radius=\"1\"/></link_sphere_approximation></robot>",
       "line 3: <sphere> of link 'a': center '1 2' is not 3 finite numbers"},
      {RobotSpheresFormat::kSrdf,
       "<robot><link_sphere_approximation link=\"a\"><sphere center=\"1 2 3\" "
       "radius=\"-1\"/></link_sphere_approximation></robot>",
       "radius '-1' is not a positive finite number"},
      {RobotSpheresFormat::kSrdf, "<robot><disable_collisions link1=\"a\"/></robot>",
       "<disable_collisions> has no link2 attribute"},
      {RobotSpheresFormat::kSrdf, "<robot><x></robot>", "not well-formed XML"},
      {RobotSpheresFormat::kSrdf, "<srdf/>", "the root element is <srdf>"},
      {RobotSpheresFormat::kUrdf,
       "<robot name=\"r\"><link name=\"a\">\n<collision><geometry><sphere "
       "radius=\"1\"/></geometry></collision>\n<collision><geometry><box size=\"1 1 "
       "1\"/></geometry></collision></link></robot>",
       "line 3 (<collision>) of link 'a' is not a sphere"},
      {RobotSpheresFormat::kMorphit,
       "<robot name=\"r\"><link name=\"a\"/><link name=\"a_sphere0\"/>\n<joint name=\"j\" "
       "type=\"fixed\"><parent link=\"a\"/><child link=\"a_sphere0\"/></joint>\n<joint "
       "name=\"k\" type=\"fixed\"><parent link=\"a\"/><child link=\"a_sphere0\"/></joint></robot>",
       "line 3: joint 'k' has child link 'a_sphere0', the child of joint 'j' (line 2) too"},
      {RobotSpheresFormat::kMorphit,
       "<robot name=\"r\"><link name=\"a\"/>\n<link name=\"a_sphere0\"/><joint name=\"j\" "
       "type=\"fixed\"><parent link=\"a\"/><child link=\"a_sphere0\"/></joint></robot>",
       "line 2: MorphIt sphere link 'a_sphere0' has no sphere <collision>"},
  };
  for (const Case& c : cases) {
    const absl::StatusOr<RobotSpheres> read = ParseRobotSpheres(c.text, c.format);
    EXPECT_FALSE(read.ok()) << c.text;
    EXPECT_THAT(read.status().message(), HasSubstr(c.message)) << c.text;
  }
}

TEST(RobotSpheres, WritersRefuseWhatTheyCannotWrite) {
  RobotSpheres model;
  model.links = {{"a", {Sphere{Vector3::Zero(), 1.0}}}, {"a", {}}};
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kSrdf).status().message(),
              HasSubstr("link 'a' is listed twice"));
  model.links = {{"a", {Sphere{Vector3::Zero(), -1.0}}}};
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kCurobo).status().message(),
              HasSubstr("link 'a'"));
  model.links = {{"a", {Sphere{Vector3::Zero(), 1.0}}}};
  model.self_collision_ignore = {{{"b", "a"}, ""}};
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kXrdf).status().message(),
              HasSubstr("is not ordered"));
  model.self_collision_ignore.clear();
  model.collision_buffer = {{"a", INFINITY}};
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kCurobo).status().message(),
              HasSubstr("collision_sphere_buffer of link 'a'"));
  model.collision_buffer.clear();
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kUrdf).status().message(),
              HasSubstr("needs the robot's URDF"));
  RobotSpheresWriteOptions options;
  options.base = "<robot name=\"r\"><link name=\"b\"/></robot>";
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kMorphit, options).status().message(),
              HasSubstr("link 'a' is not in the base URDF"));
  options.base = "<robot name=\"r\"><link name=\"a\"/><link name=\"a_sphere0\"/></robot>";
  EXPECT_THAT(FormatRobotSpheres(model, RobotSpheresFormat::kMorphit, options).status().message(),
              HasSubstr("already has a link named 'a_sphere0'"));
}

TEST(RobotSpheres, DroppedPartsAreNamed) {
  const RobotSpheres model = RandomRobot(4);
  const std::vector<std::string> curobo = RobotSpheresDropped(model, RobotSpheresFormat::kCurobo);
  EXPECT_EQ(curobo.size(), 2u);  // the reasons and the name
  EXPECT_THAT(curobo, ::testing::Contains(HasSubstr("robot's name")));
  const std::vector<std::string> urdf = RobotSpheresDropped(model, RobotSpheresFormat::kUrdf);
  EXPECT_THAT(urdf, ::testing::Contains(HasSubstr("without spheres")));
  EXPECT_THAT(urdf, ::testing::Contains(HasSubstr("self_collision_ignore")));
  const std::vector<std::string> xrdf = RobotSpheresDropped(model, RobotSpheresFormat::kXrdf);
  EXPECT_THAT(xrdf, ::testing::Contains(HasSubstr("reasons")));
  EXPECT_THAT(RobotSpheresDropped(model, RobotSpheresFormat::kSrdf),
              ::testing::Contains(HasSubstr("collision_sphere_buffer")));
}

}  // namespace
}  // namespace inscribe::robot
