// The self-collision matrix's rules (self_collision.h) on a robot of hand-placed spheres whose
// every pair's class is known, its validation, and the SRDF (self_collision_srdf.h) and cuRobo
// YAML (spherized_urdf.h) writers read back with tinyxml2 and yaml-cpp.
#include "inscribe/robot/self_collision.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <tinyxml2.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "inscribe/balls/sphere_io.h"
#include "inscribe/robot/self_collision_srdf.h"
#include "inscribe/robot/spherized_urdf.h"

namespace inscribe::robot {
namespace {

using ::testing::HasSubstr;

// Links and what each pair must be (see the robot below).
//   root  one sphere far above everything;
//   s     fixed, a big sphere x in [-10.1, 0.1];  p  prismatic along x in [-10, 0], a small
//         sphere 0.5 ahead of its origin: apart at q = 0 (the default), touching s for
//         q <= -0.35, 96.5% of the range: Always;
//   t     fixed at y = 20, a sphere at x = -1 (r 0.5);  q  prismatic along x in [-1, 1] at
//         y = 20, a sphere r 0.1 at its origin: touching t for q <= -0.4, 30%: Sometimes;
//   d, e  fixed at y = -20, overlapping: Default;
//   m     fixed, no spheres;  k  fixed to m at y = 40: Adjacent to root through m;
//   everything else apart: Never, except links joined to root: Adjacent.
struct Spheres {
  UrdfRobot robot;
  std::vector<LinkCollisionGeometry> geometry;
};

Spheres SphereRobot() {
  Spheres r;
  const auto add = [&](const std::string& name, std::vector<Sphere> spheres) {
    UrdfLink link;
    link.name = name;
    r.robot.links.push_back(link);
    LinkCollisionGeometry g;
    g.spheres = std::move(spheres);
    r.geometry.push_back(g);
  };
  const auto joint = [&](const std::string& child, UrdfJointType type, const Vector3& xyz,
                         double lower, double upper, const std::string& parent = "root") {
    UrdfJoint j;
    j.name = "to_" + child;
    j.type = type;
    j.parent = parent;
    j.child = child;
    j.origin.xyz = xyz;
    j.axis = Vector3::UnitX();
    j.lower = lower;
    j.upper = upper;
    r.robot.joints.push_back(j);
  };
  add("root", {{Vector3(0, 0, 100), 0.1}});
  add("s", {{Vector3(-5, 0, 0), 5.1}});
  add("p", {{Vector3(0.5, 0, 0), 0.05}});
  add("t", {{Vector3(-1, 0, 0), 0.5}});
  add("q", {{Vector3::Zero(), 0.1}});
  add("d", {{Vector3::Zero(), 1.0}});
  add("e", {{Vector3::Zero(), 1.0}, {Vector3(0, 0, 3), 0.2}});
  add("m", {});
  add("k", {{Vector3::Zero(), 0.1}});
  joint("s", UrdfJointType::kFixed, Vector3::Zero(), 0, 0);
  joint("p", UrdfJointType::kPrismatic, Vector3::Zero(), -10, 0);
  joint("t", UrdfJointType::kFixed, Vector3(0, 20, 0), 0, 0);
  joint("q", UrdfJointType::kPrismatic, Vector3(0, 20, 0), -1, 1);
  joint("d", UrdfJointType::kFixed, Vector3(0, -20, 0), 0, 0);
  joint("e", UrdfJointType::kFixed, Vector3(0, -20, 0.5), 0, 0);
  joint("m", UrdfJointType::kFixed, Vector3(0, 40, 0), 0, 0);
  joint("k", UrdfJointType::kFixed, Vector3::Zero(), 0, 0, "m");
  return r;
}

Kinematics Create(const UrdfRobot& robot) {
  absl::StatusOr<Kinematics> kinematics = Kinematics::Create(robot);
  EXPECT_TRUE(kinematics.ok()) << kinematics.status();
  return *std::move(kinematics);
}

std::map<std::pair<std::string, std::string>, const LinkPairCollision*> ByName(
    const SelfCollisionMatrix& matrix) {
  std::map<std::pair<std::string, std::string>, const LinkPairCollision*> pairs;
  for (const LinkPairCollision& pair : matrix.pairs) {
    pairs[{matrix.links[pair.link_a], matrix.links[pair.link_b]}] = &pair;
  }
  return pairs;
}

TEST(SelfCollisionMatrix, ClassifiesPairsAsMoveItsSetupAssistantDoes) {
  const Spheres r = SphereRobot();
  const Kinematics kinematics = Create(r.robot);
  const absl::StatusOr<SelfCollisionMatrix> matrix =
      ComputeSelfCollisionMatrix(kinematics, r.geometry);
  ASSERT_TRUE(matrix.ok()) << matrix.status();
  EXPECT_EQ(matrix->samples, 10'000);  // MoveIt's default
  EXPECT_FALSE(matrix->certified);
  // 8 links with spheres (m has none): 28 pairs, ordered.
  ASSERT_EQ(matrix->pairs.size(), 28u);
  for (std::size_t i = 1; i < matrix->pairs.size(); ++i) {
    EXPECT_LT(std::tie(matrix->pairs[i - 1].link_a, matrix->pairs[i - 1].link_b),
              std::tie(matrix->pairs[i].link_a, matrix->pairs[i].link_b));
  }
  const auto pairs = ByName(*matrix);
  const auto type = [&](const std::string& a, const std::string& b) {
    return pairs.at({a, b})->type;
  };
  for (const char* child : {"s", "p", "t", "q", "d", "e", "k"}) {
    EXPECT_EQ(type("root", child), CollisionPairClass::kAdjacent) << child;
  }
  EXPECT_EQ(type("s", "p"), CollisionPairClass::kAlways);
  EXPECT_NEAR(pairs.at({"s", "p"})->colliding_fraction, 0.965, 0.01);
  EXPECT_FALSE(pairs.at({"s", "p"})->colliding_at_default);
  EXPECT_EQ(type("t", "q"), CollisionPairClass::kSometimes);
  EXPECT_NEAR(pairs.at({"t", "q"})->colliding_fraction, 0.3, 0.02);
  EXPECT_EQ(type("d", "e"), CollisionPairClass::kDefault);
  EXPECT_TRUE(pairs.at({"d", "e"})->colliding_at_default);
  EXPECT_EQ(pairs.at({"d", "e"})->colliding_samples, 10'000);
  int never = 0;
  for (const LinkPairCollision& pair : matrix->pairs) {
    if (pair.type != CollisionPairClass::kNever) continue;
    ++never;
    EXPECT_EQ(pair.colliding_samples, 0);
    EXPECT_GT(pair.min_lower, 0.0);
    EXPECT_LE(pair.min_lower, pair.min_upper);
  }
  EXPECT_EQ(never, 28 - 7 - 3);
  // The smallest distances seen.
  EXPECT_EQ(pairs.at({"s", "p"})->min_lower, 0.0);
  EXPECT_NEAR(pairs.at({"s", "p"})->min_sphere_distance, -5.15, 0.01);  // at q = -5.5
  // Uncertified links are their spheres: the interval is the spheres' distance, up to margins.
  const LinkPairCollision& far = *pairs.at({"d", "k"});
  EXPECT_NEAR(far.min_lower, far.min_upper, 1e-9);

  // Always needs the fraction: at 0.97 the s-p pair is only sometimes in collision.
  SelfCollisionOptions strict;
  strict.always_fraction = 0.97;
  const absl::StatusOr<SelfCollisionMatrix> stricter =
      ComputeSelfCollisionMatrix(kinematics, r.geometry, strict);
  ASSERT_TRUE(stricter.ok());
  EXPECT_EQ(ByName(*stricter).at({"s", "p"})->type, CollisionPairClass::kSometimes);
}

TEST(SelfCollisionMatrix, IsTheSameForASeedAndChangesWithIt) {
  const Spheres r = SphereRobot();
  const Kinematics kinematics = Create(r.robot);
  SelfCollisionOptions options;
  options.samples = 3000;
  options.seed = 7;
  const auto a = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  const auto b = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  options.seed = 8;
  const auto c = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  const auto& tq_a = *ByName(*a).at({"t", "q"});
  const auto& tq_b = *ByName(*b).at({"t", "q"});
  const auto& tq_c = *ByName(*c).at({"t", "q"});
  EXPECT_EQ(tq_a.colliding_samples, tq_b.colliding_samples);
  EXPECT_EQ(tq_a.min_upper, tq_b.min_upper);
  EXPECT_NE(tq_a.colliding_samples, tq_c.colliding_samples);
}

TEST(SelfCollisionMatrix, AdjacentPairsLeftOutKeepEveryClassAndOtherStatistic) {
  const Spheres r = SphereRobot();
  const Kinematics kinematics = Create(r.robot);
  SelfCollisionOptions options;
  options.samples = 3000;
  const auto all = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  options.sample_adjacent = false;
  const auto some = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  ASSERT_TRUE(all.ok() && some.ok());
  ASSERT_EQ(all->pairs.size(), some->pairs.size());
  for (std::size_t i = 0; i < all->pairs.size(); ++i) {
    const LinkPairCollision& a = all->pairs[i];
    const LinkPairCollision& b = some->pairs[i];
    EXPECT_EQ(a.type, b.type);
    EXPECT_TRUE(a.sampled);
    if (a.type == CollisionPairClass::kAdjacent) {
      EXPECT_FALSE(b.sampled);
      EXPECT_EQ(b.colliding_samples, 0);
      EXPECT_TRUE(std::isnan(b.min_lower) && std::isnan(b.min_upper));
      continue;
    }
    EXPECT_TRUE(b.sampled);
    EXPECT_EQ(a.colliding_samples, b.colliding_samples);
    EXPECT_EQ(a.min_lower, b.min_lower);
    EXPECT_EQ(a.min_upper, b.min_upper);
    EXPECT_EQ(a.min_sphere_distance, b.min_sphere_distance);
  }
}

TEST(SelfCollisionMatrix, RefusesBadInputAndStopsWhenCancelled) {
  const Spheres r = SphereRobot();
  const Kinematics kinematics = Create(r.robot);
  const auto error = [&](std::vector<LinkCollisionGeometry> geometry,
                         SelfCollisionOptions options = {}) {
    const auto matrix = ComputeSelfCollisionMatrix(kinematics, geometry, options);
    EXPECT_FALSE(matrix.ok());
    return std::string(matrix.status().message());
  };
  std::vector<LinkCollisionGeometry> g = r.geometry;
  g.pop_back();
  EXPECT_THAT(error(g), HasSubstr("8 link geometries for a robot of 9 links"));
  g = r.geometry;
  g[2].spheres[0].center.y() = NAN;
  EXPECT_THAT(error(g), HasSubstr("link 'p' spheres: sphere 0: center y nan is not finite"));
  g = r.geometry;
  g[3].inner = {{Vector3::Zero(), -1.0}};
  EXPECT_THAT(error(g), HasSubstr("link 't' inner: sphere 0"));
  g = r.geometry;
  g[1].certified_delta = -0.5;
  EXPECT_THAT(error(g), HasSubstr("link 's': certified_delta -0.5 is not finite and >= 0"));
  SelfCollisionOptions options;
  for (std::int64_t samples : {std::int64_t{0}, std::int64_t{-3}, kMaxSelfCollisionSamples + 1}) {
    options.samples = samples;
    EXPECT_THAT(error(r.geometry, options), HasSubstr("is outside 1..100000000"));
  }
  options = {};
  for (double fraction : {0.0, 1.5, double(NAN)}) {
    options.always_fraction = fraction;
    EXPECT_THAT(error(r.geometry, options), HasSubstr("always_fraction"));
  }
  options = {};
  std::atomic<bool> cancel{true};
  options.control.cancel = &cancel;
  const auto cancelled = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  EXPECT_EQ(cancelled.status().code(), absl::StatusCode::kCancelled);
  std::vector<double> progress;
  options = {};
  options.samples = 5000;
  options.control.on_progress = [&](double f) { progress.push_back(f); };
  ASSERT_TRUE(ComputeSelfCollisionMatrix(kinematics, r.geometry, options).ok());
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back(), 1.0);
  EXPECT_THAT(LinkPairIntervals(kinematics, r.geometry, {}).status().message(),
              HasSubstr("configuration has 0 values"));
}

TEST(SelfCollisionIntervals, CertifiedBoundsUseDeltaAndInnerSpheres) {
  // Two links 1 m apart along x: covers of radius 0.2 reaching delta 0.05 past the solids,
  // inner balls of radius 0.1.
  UrdfRobot robot;
  robot.links = {UrdfLink{"a", 0, {}, false}, UrdfLink{"b", 0, {}, false}};
  UrdfJoint joint;
  joint.name = "j";
  joint.type = UrdfJointType::kFixed;
  joint.parent = "a";
  joint.child = "b";
  joint.origin.xyz = Vector3(1, 0, 0);
  robot.joints = {joint};
  const Kinematics kinematics = Create(robot);
  LinkCollisionGeometry link;
  link.spheres = {{Vector3::Zero(), 0.2}};
  link.certified_delta = 0.05;
  link.inner = {{Vector3::Zero(), 0.1}};
  const auto intervals = LinkPairIntervals(kinematics, {link, link}, {});
  ASSERT_TRUE(intervals.ok()) << intervals.status();
  ASSERT_EQ(intervals->size(), 1u);
  EXPECT_NEAR((*intervals)[0].sphere_distance, 0.6, 1e-15);
  EXPECT_NEAR((*intervals)[0].lower, 0.6, 1e-11);
  // min(inner distance 0.8, 0.6 + 0.05 + 0.05).
  EXPECT_NEAR((*intervals)[0].upper, 0.7, 1e-11);
  link.inner.clear();
  EXPECT_NEAR((*LinkPairIntervals(kinematics, {link, link}, {}))[0].upper, 0.7, 1e-11);
  link.inner = {{Vector3::Zero(), 0.19}};
  EXPECT_NEAR((*LinkPairIntervals(kinematics, {link, link}, {}))[0].upper, 0.62, 1e-11);
}

TEST(SelfCollisionSrdf, NamesExactlyTheDisabledPairsInMoveItsOrder) {
  const Spheres r = SphereRobot();
  const Kinematics kinematics = Create(r.robot);
  SelfCollisionOptions options;
  options.samples = 2000;
  const auto matrix = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  ASSERT_TRUE(matrix.ok());
  const std::string srdf = SelfCollisionSrdf(*matrix, "a \"robot\" <&>");
  tinyxml2::XMLDocument document;
  ASSERT_EQ(document.Parse(srdf.c_str()), tinyxml2::XML_SUCCESS) << srdf;
  const tinyxml2::XMLElement* robot = document.RootElement();
  ASSERT_NE(robot, nullptr);
  EXPECT_STREQ(robot->Name(), "robot");
  EXPECT_STREQ(robot->Attribute("name"), "a \"robot\" <&>");
  std::vector<std::tuple<std::string, std::string, std::string>> read;
  for (const tinyxml2::XMLElement* e = robot->FirstChildElement(); e != nullptr;
       e = e->NextSiblingElement()) {
    EXPECT_STREQ(e->Name(), "disable_collisions");
    read.emplace_back(e->Attribute("link1"), e->Attribute("link2"), e->Attribute("reason"));
  }
  std::vector<std::tuple<std::string, std::string, std::string>> expected;
  for (const LinkPairCollision& pair : matrix->pairs) {
    if (pair.type == CollisionPairClass::kSometimes) continue;
    std::string a = matrix->links[pair.link_a], b = matrix->links[pair.link_b];
    if (b < a) std::swap(a, b);
    expected.emplace_back(a, b, CollisionPairClassName(pair.type));
  }
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(read, expected);
  EXPECT_EQ(read.size(), matrix->pairs.size() - 1);  // all but t-q
  EXPECT_THAT(srdf, HasSubstr("<disable_collisions link1=\"p\" link2=\"s\" reason=\"Always\"/>"));
  EXPECT_THAT(srdf, HasSubstr("<disable_collisions link1=\"d\" link2=\"e\" reason=\"Default\"/>"));
  EXPECT_THAT(srdf, HasSubstr("link1=\"k\" link2=\"root\" reason=\"Adjacent\""));
}

TEST(SelfCollisionCuroboYaml, WritesIgnoreListsAndBuffersThatReadBack) {
  const Spheres r = SphereRobot();
  const Kinematics kinematics = Create(r.robot);
  SelfCollisionOptions options;
  options.samples = 2000;
  const auto matrix = ComputeSelfCollisionMatrix(kinematics, r.geometry, options);
  ASSERT_TRUE(matrix.ok());
  std::vector<LinkSpherizeResult> results;
  for (std::size_t i = 0; i < r.robot.links.size(); ++i) {
    LinkSpherizeResult result;
    result.link = r.robot.links[i].name;
    result.spheres = r.geometry[i].spheres;
    result.status = result.spheres.empty() ? LinkStatus::kNoGeometry : LinkStatus::kSpherized;
    results.push_back(result);
  }
  const std::map<std::string, double> buffers = {{"s", 0.01}, {"p", -0.005}, {"x", 1.0}};
  std::vector<std::string> left_out;
  const absl::StatusOr<std::string> yaml =
      SpherizedCuroboYaml(results, "r", *matrix, buffers, &left_out);
  ASSERT_TRUE(yaml.ok()) << yaml.status();
  EXPECT_TRUE(left_out.empty());
  // The spheres read back as before.
  const auto spheres = ParseCuroboYaml(*yaml);
  ASSERT_TRUE(spheres.ok()) << spheres.status();
  EXPECT_EQ(spheres->size(), 8u);

  const YAML::Node root = YAML::Load(*yaml);
  std::set<std::pair<std::string, std::string>> ignored;
  for (const auto& entry : root["self_collision_ignore"]) {
    for (const auto& other : entry.second) {
      ignored.insert(std::minmax(entry.first.as<std::string>(), other.as<std::string>()));
    }
  }
  std::set<std::pair<std::string, std::string>> expected;
  const std::vector<std::string> order = {"root", "s", "p", "t", "q", "d", "e", "k"};
  for (const LinkPairCollision& pair : matrix->pairs) {
    if (!CollisionDisabled(pair.type)) continue;
    // Each pair once, under either link (cuRobo skips a pair listed in either direction).
    expected.insert(std::minmax(matrix->links[pair.link_a], matrix->links[pair.link_b]));
  }
  EXPECT_EQ(ignored, expected);
  const YAML::Node buffer = root["self_collision_buffer"];
  ASSERT_EQ(buffer.size(), order.size());
  for (const std::string& link : order) {
    const double value = buffer[link].as<double>();
    EXPECT_EQ(value, link == "s" ? 0.01 : link == "p" ? -0.005 : 0.0) << link;
  }
  EXPECT_THAT(*yaml, HasSubstr("\"root\": 0.0\n"));  // PyYAML reads it as a float

  const auto bad = SpherizedCuroboYaml(results, "r", *matrix, {{"s", INFINITY}}, &left_out);
  EXPECT_THAT(bad.status().message(), HasSubstr("self_collision_buffer of link 's'"));
  // The original writer is unchanged for callers without a matrix.
  EXPECT_THAT(SpherizedCuroboYaml(results, "r", &left_out),
              ::testing::Not(HasSubstr("self_collision")));
}

}  // namespace
}  // namespace inscribe::robot
