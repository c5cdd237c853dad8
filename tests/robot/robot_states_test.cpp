// RobotStateChecker on the 7-DOF test arm (support/seven_dof_arm.h) against brute force: every
// posed sphere against every point in long double, every sphere pair of every enabled link
// pair; certificate reuse against no reuse on long random motions; segments against dense
// sampling; travel bounds against the sampled arc length of every sphere centre.
#include "inscribe/robot/robot_states.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "inscribe/env/distance_grid.h"
#include "inscribe/env/point_cloud.h"
#include "inscribe/env/point_filters.h"
#include "support/seven_dof_arm.h"

namespace inscribe::robot {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPointRadius = 0.01;

struct Fixture {
  testing::SevenDofArm arm = testing::BuildSevenDofArm();
  RobotStateChecker checker = *RobotStateChecker::Create(arm.robot, arm.spheres);
  Kinematics kinematics = *Kinematics::Create(arm.robot);
  std::vector<Vector3> points;
  PointCloud cloud = *PointCloud::Create({}, {});

  explicit Fixture(int n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    // Points in the arm's reach, with a hole around its base: some states collide, some not.
    std::uniform_real_distribution<double> xy(-0.9, 0.9), z(0.0, 1.3);
    while (static_cast<int>(points.size()) < n) {
      const Vector3 p(xy(rng), xy(rng), z(rng));
      if (std::hypot(p.x(), p.y()) < 0.35) continue;
      points.push_back(p);
    }
    PointCloudOptions options;
    options.point_radius = kPointRadius;
    cloud = *PointCloud::Create(points, {}, options);
  }

  // Posed spheres (world radius) by the kinematics, link by link in the model's order.
  struct Posed {
    std::vector<Vector3> centre;
    std::vector<double> radius;
    std::vector<int> link;  // index into arm.spheres.links
  };
  Posed Pose(const std::vector<double>& q) const {
    const std::vector<Eigen::Isometry3d> poses = *kinematics.LinkPoses(q);
    Posed posed;
    for (std::size_t l = 0; l < arm.spheres.links.size(); ++l) {
      for (const Sphere& s : arm.spheres.links[l].spheres) {
        posed.centre.push_back(poses[l] * s.center);
        posed.radius.push_back(s.radius);
        posed.link.push_back(static_cast<int>(l));
      }
    }
    return posed;
  }
  long double SphereClearance(const Posed& posed, std::size_t i) const {
    long double best = std::numeric_limits<long double>::infinity();
    for (const Vector3& p : points) {
      const long double dx = static_cast<long double>(posed.centre[i].x()) - p.x();
      const long double dy = static_cast<long double>(posed.centre[i].y()) - p.y();
      const long double dz = static_cast<long double>(posed.centre[i].z()) - p.z();
      best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz) - kPointRadius);
    }
    return best - posed.radius[i];
  }
  bool WorldCollides(const std::vector<double>& q) const {
    const Posed posed = Pose(q);
    for (std::size_t i = 0; i < posed.centre.size(); ++i) {
      if (SphereClearance(posed, i) <= 0) return true;
    }
    return false;
  }
  bool SelfCollides(const std::vector<double>& q) const {
    const Posed posed = Pose(q);
    for (std::size_t i = 0; i < posed.centre.size(); ++i) {
      for (std::size_t j = i + 1; j < posed.centre.size(); ++j) {
        const int a = posed.link[i], b = posed.link[j];
        if (a == b || arm.spheres.self_collision_ignore.count(
                          {arm.spheres.links[a].link, arm.spheres.links[b].link}) > 0) {
          continue;
        }
        if ((posed.centre[i] - posed.centre[j]).norm() <= posed.radius[i] + posed.radius[j]) {
          return true;
        }
      }
    }
    return false;
  }
};

std::vector<double> Flatten(const std::vector<std::vector<double>>& states) {
  std::vector<double> flat;
  for (const auto& q : states) flat.insert(flat.end(), q.begin(), q.end());
  return flat;
}

TEST(RobotStates, YesNoEqualsBruteForce) {
  const Fixture f(2500, 1);
  ASSERT_EQ(f.checker.spheres(), 60);
  ASSERT_EQ(f.checker.variables(), 7);
  const auto states = SampleConfigurations(f.kinematics, 300, 7);
  absl::StatusOr<StateBatchResult> result = f.checker.CheckStates(Flatten(states), f.cloud);
  ASSERT_TRUE(result.ok()) << result.status();
  int world = 0, self = 0;
  for (std::size_t s = 0; s < states.size(); ++s) {
    const bool w = f.WorldCollides(states[s]);
    const bool c = f.SelfCollides(states[s]);
    world += w;
    self += c;
    ASSERT_EQ(result->world_collision[s] != 0, w) << "state " << s;
    if (!w) ASSERT_EQ(result->self_collision[s] != 0, c) << "state " << s;
    ASSERT_EQ(result->collides[s] != 0, w || c) << "state " << s;
  }
  EXPECT_GT(world, 30);
  EXPECT_LT(world, 270);
  EXPECT_GT(self, 3);
}

TEST(RobotStates, IntervalsHoldTheExactClearances) {
  const Fixture f(2000, 2);
  const auto states = SampleConfigurations(f.kinematics, 80, 8);
  for (const double tolerance : {0.0, 0.005, kInf}) {
    StateQuery query;
    query.intervals = true;
    query.per_sphere = tolerance == 0.005;
    query.clearance.tolerance = tolerance;
    absl::StatusOr<StateBatchResult> result =
        f.checker.CheckStates(Flatten(states), f.cloud, query);
    ASSERT_TRUE(result.ok()) << result.status();
    for (std::size_t s = 0; s < states.size(); ++s) {
      const Fixture::Posed posed = f.Pose(states[s]);
      std::vector<long double> link_truth(8, std::numeric_limits<long double>::infinity());
      bool world = false;
      for (std::size_t i = 0; i < posed.centre.size(); ++i) {
        const long double truth = f.SphereClearance(posed, i);
        world = world || truth <= 0;
        link_truth[posed.link[i]] = std::min(link_truth[posed.link[i]], truth);
        if (query.per_sphere) {
          const ClearanceInterval& got = result->sphere_clearance[s * 60 + i];
          ASSERT_LE(got.lower, truth);
          ASSERT_GE(got.upper, truth);
          ASSERT_LE(got.upper - got.lower, tolerance + 1e-9);
        }
      }
      for (int l = 0; l < 8; ++l) {
        const ClearanceInterval& got = result->link_clearance[s * 8 + l];
        ASSERT_LE(got.lower, link_truth[l]) << "state " << s << " link " << l;
        ASSERT_GE(got.upper, link_truth[l]) << "state " << s << " link " << l;
        if (std::isfinite(tolerance)) ASSERT_LE(got.upper - got.lower, tolerance + 1e-9);
      }
      ASSERT_EQ(result->world_collision[s] != 0, world) << "state " << s;
    }
  }
}

// A random walk in joint space: steps of up to `step` radians per joint.
std::vector<std::vector<double>> RandomMotion(const Kinematics& kinematics, int count, double step,
                                              std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> delta(-step, step);
  std::vector<std::vector<double>> states = SampleConfigurations(kinematics, 1, seed);
  for (int s = 1; s < count; ++s) {
    std::vector<double> q = states.back();
    for (std::size_t j = 0; j < q.size(); ++j) {
      const JointVariable& v = kinematics.variables()[j];
      q[j] = std::clamp(q[j] + delta(rng), v.lower, v.upper);
    }
    states.push_back(q);
  }
  return states;
}

TEST(RobotStates, ReuseNeverSkipsANeededQuery) {
  const Fixture f(500, 3);
  int colliding = 0, total = 0;
  for (const double step : {0.01, 0.05}) {
    const auto motion = RandomMotion(f.kinematics, 1500, step, 11);
    const std::vector<double> flat = Flatten(motion);
    StateQuery fresh, reuse;
    reuse.reuse_certificates = true;
    absl::StatusOr<StateBatchResult> a = f.checker.CheckStates(flat, f.cloud, fresh);
    absl::StatusOr<StateBatchResult> b = f.checker.CheckStates(flat, f.cloud, reuse);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->collides, b->collides) << "step " << step;
    EXPECT_EQ(a->world_collision, b->world_collision) << "step " << step;
    EXPECT_GT(b->reused, 0);
    for (std::uint8_t c : a->world_collision) colliding += c;
    total += static_cast<int>(motion.size());
    // Intervals with reuse: still hold the exact clearances (checked on every 10th state).
    StateQuery intervals;
    intervals.intervals = true;
    intervals.per_sphere = true;
    intervals.clearance.tolerance = 0.05;
    intervals.reuse_certificates = true;
    absl::StatusOr<StateBatchResult> c = f.checker.CheckStates(flat, f.cloud, intervals);
    ASSERT_TRUE(c.ok());
    EXPECT_GT(c->reused, 0);
    for (std::size_t s = 0; s < motion.size(); s += 10) {
      const Fixture::Posed posed = f.Pose(motion[s]);
      for (std::size_t i = 0; i < posed.centre.size(); ++i) {
        const long double truth = f.SphereClearance(posed, i);
        ASSERT_LE(c->sphere_clearance[s * 60 + i].lower, truth) << s << " " << i;
        ASSERT_GE(c->sphere_clearance[s * 60 + i].upper, truth) << s << " " << i;
      }
      ASSERT_EQ(c->world_collision[s], a->world_collision[s]) << s;
    }
  }
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, total);
}

TEST(RobotStates, SegmentsNeverMissACollision) {
  const Fixture f(500, 4);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> delta(-0.3, 0.3);
  const auto starts = SampleConfigurations(f.kinematics, 60, 12);
  int proved = 0, found = 0;
  for (const auto& q0 : starts) {
    std::vector<double> q1 = q0;
    for (double& v : q1) v += delta(rng);
    bool dense = false;
    for (int k = 0; k <= 300 && !dense; ++k) {
      std::vector<double> q(7);
      for (int j = 0; j < 7; ++j) q[j] = q0[j] + k / 300.0 * (q1[j] - q0[j]);
      dense = f.WorldCollides(q) || f.SelfCollides(q);
    }
    absl::StatusOr<SegmentResult> advancement = f.checker.CheckSegment(q0, q1, f.cloud);
    ASSERT_TRUE(advancement.ok()) << advancement.status();
    if (advancement->proved) ASSERT_FALSE(dense);
    if (dense) ASSERT_TRUE(advancement->collides || !advancement->proved);
    if (advancement->collides) {
      std::vector<double> q(7);
      const double t = advancement->t_collision;
      for (int j = 0; j < 7; ++j) q[j] = q0[j] + t * (q1[j] - q0[j]);
      ASSERT_TRUE(f.WorldCollides(q) || f.SelfCollides(q));
    }
    proved += advancement->proved;
    found += advancement->collides;
    SegmentOptions discrete;
    discrete.method = SegmentOptions::Method::kResolution;
    discrete.resolution = 0.01;
    absl::StatusOr<SegmentResult> sampled = f.checker.CheckSegment(q0, q1, f.cloud, discrete);
    ASSERT_TRUE(sampled.ok());
    if (advancement->proved) ASSERT_FALSE(sampled->collides);
  }
  EXPECT_GT(proved, 3) << found << " of " << starts.size() << " found colliding";
  EXPECT_GT(found, 3);
}

// Arc length of every centre, sampled finely, against SegmentTravelBounds, on the arm and on a
// robot with an anchored revolute joint, a prismatic joint and a mimic of it.
TEST(RobotStates, TravelBoundsHoldTheSampledArcLength) {
  const testing::SevenDofArm arm = testing::BuildSevenDofArm();
  UrdfRobot mixed = arm.robot;
  mixed.joints[1].anchor = Vector3(0.05, -0.02, 0.03);
  mixed.joints[2].type = UrdfJointType::kPrismatic;
  mixed.joints[2].lower = -0.1;
  mixed.joints[2].upper = 0.2;
  mixed.joints[4].mimic = UrdfMimic{"joint3", -1.5, 0.05};
  mixed.joints[4].type = UrdfJointType::kPrismatic;
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> delta(-0.8, 0.8);
  for (const UrdfRobot* robot : std::vector<const UrdfRobot*>{&arm.robot, &mixed}) {
    absl::StatusOr<RobotStateChecker> checker = RobotStateChecker::Create(*robot, arm.spheres);
    ASSERT_TRUE(checker.ok()) << checker.status();
    const auto starts = SampleConfigurations(checker->kinematics(), 40, 13);
    for (const auto& q0 : starts) {
      std::vector<double> q1 = q0;
      for (double& v : q1) v += delta(rng);
      absl::StatusOr<std::vector<double>> bounds = checker->SegmentTravelBounds(q0, q1);
      ASSERT_TRUE(bounds.ok());
      std::vector<double> length(60, 0.0);
      std::vector<Sphere> last = *checker->WorldSpheres(q0);
      for (int k = 1; k <= 500; ++k) {
        std::vector<double> q(q0.size());
        for (std::size_t j = 0; j < q.size(); ++j) q[j] = q0[j] + k / 500.0 * (q1[j] - q0[j]);
        const std::vector<Sphere> now = *checker->WorldSpheres(q);
        for (int i = 0; i < 60; ++i) length[i] += (now[i].center - last[i].center).norm();
        last = now;
      }
      for (int i = 0; i < 60; ++i) ASSERT_LE(length[i], (*bounds)[i]) << "sphere " << i;
    }
  }
}

TEST(RobotStates, SelfFilterDropsThePointsOnTheRobot) {
  const Fixture f(10, 7);
  const std::vector<double> q = SampleConfigurations(f.kinematics, 1, 14)[0];
  const std::vector<Sphere> spheres = *f.checker.WorldSpheres(q, 0.01);
  std::mt19937_64 rng(8);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Vector3> points;
  for (const Sphere& s : spheres) {  // 50 points inside each padded sphere, 50 just outside
    for (int k = 0; k < 100; ++k) {
      const Vector3 direction = Vector3(normal(rng), normal(rng), normal(rng)).normalized();
      points.push_back(s.center + direction * s.radius * (k < 50 ? 0.9 : 1.5));
    }
  }
  absl::StatusOr<SelfFilteredPoints> out = SelfFilterPoints(points, spheres);
  ASSERT_TRUE(out.ok());
  for (std::size_t i = 0; i < points.size(); ++i) {
    bool inside = false;
    for (const Sphere& s : spheres) inside = inside || (points[i] - s.center).norm() <= s.radius;
    const bool kept =
        std::binary_search(out->kept.begin(), out->kept.end(), static_cast<std::int64_t>(i));
    ASSERT_EQ(kept, !inside) << i;
  }
  EXPECT_GE(out->dropped, 60 * 50);
}

TEST(RobotStates, GridNeverMissesACollision) {
  const Fixture f(400, 9);
  DistanceGridLayout layout;
  layout.dims = Vector3(2.0, 2.0, 1.6);
  layout.voxel_size = 0.04;
  layout.pose.translation = Vector3(0, 0, 0.6);
  const std::array<int, 3> n = *DistanceGridVoxels(layout);
  std::vector<float> values(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  absl::StatusOr<SignedDistanceGrid> probe = SignedDistanceGrid::Create(layout, values);
  ASSERT_TRUE(probe.ok());
  double error = 0.0;
  for (int x = 0; x < n[0]; ++x) {
    for (int y = 0; y < n[1]; ++y) {
      for (int z = 0; z < n[2]; ++z) {
        const Vector3 s = probe->SamplePosition(x, y, z);
        double best = kInf;
        for (const Vector3& p : f.points) best = std::min(best, (s - p).norm() - kPointRadius);
        const float stored = static_cast<float>(best);
        error = std::max(error, std::abs(stored - best));
        values[(static_cast<std::size_t>(x) * n[1] + y) * n[2] + z] = stored;
      }
    }
  }
  DistanceGridOptions options;
  options.value_error = error;
  absl::StatusOr<SignedDistanceGrid> grid = SignedDistanceGrid::Create(layout, values, options);
  ASSERT_TRUE(grid.ok());
  const auto states = SampleConfigurations(f.kinematics, 200, 15);
  StateQuery query;
  query.self_collision = false;
  absl::StatusOr<StateBatchResult> result = f.checker.CheckStates(Flatten(states), *grid, query);
  ASSERT_TRUE(result.ok());
  int clear = 0;
  for (std::size_t s = 0; s < states.size(); ++s) {
    if (f.WorldCollides(states[s])) ASSERT_TRUE(result->collides[s]) << s;
    clear += !result->collides[s];
  }
  EXPECT_GT(clear, 10);
}

TEST(RobotStates, BadInputNamesTheProblem) {
  const Fixture f(10, 10);
  absl::StatusOr<StateBatchResult> wrong = f.checker.CheckStates(std::vector<double>(8), f.cloud);
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.status().message().find("multiple"), std::string::npos);
  std::vector<double> q(14, 0.0);
  q[9] = std::nan("");
  absl::StatusOr<StateBatchResult> nan = f.checker.CheckStates(q, f.cloud);
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.status().message().find("state 1"), std::string::npos);
  RobotSpheres unknown = f.arm.spheres;
  unknown.links[0].link = "nowhere";
  absl::StatusOr<RobotStateChecker> bad = RobotStateChecker::Create(f.arm.robot, unknown);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("nowhere"), std::string::npos);
  RobotSpheres shrunk = f.arm.spheres;
  shrunk.collision_buffer["link3"] = -1.0;
  EXPECT_FALSE(RobotStateChecker::Create(f.arm.robot, shrunk).ok());
}

}  // namespace
}  // namespace inscribe::robot
