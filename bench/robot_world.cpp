// Robot states against the world (robot/include/inscribe/robot/robot_states.h): the 60-sphere
// 7-DOF test arm (tests/support/seven_dof_arm.h) against point clouds of 10k, 100k and 1M
// points sampled on a scene of boxes and a floor, against a 256^3 signed distance grid of the
// same scene and against the scene's primitives. Per environment: build time, states per
// second and per-state latency for yes/no and for per-link intervals, on one thread; next to
// FCL on the same states (an fcl::OcTree of the cloud from octomap, collided and measured
// against the arm's capsule meshes). Then certificate reuse along a motion, segment checks,
// and the self-filter of 100k points. Before timing, yes/no on the smallest cloud is checked
// against a brute force over every sphere and point: a difference fails the program (exit 1).
// Prints Markdown.
//
//   robot_world [--states N] [--clouds 10000,100000,1000000] [--grid 256] [--fcl-states N]
//               [--quick]
#include <fcl/fcl.h>
#include <octomap/octomap.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "CLI/CLI.hpp"
#include "absl/strings/str_format.h"
#include "inscribe/env/distance_grid.h"
#include "inscribe/env/point_cloud.h"
#include "inscribe/env/point_filters.h"
#include "inscribe/env/primitives.h"
#include "inscribe/robot/robot_states.h"
#include "support/fcl_solid_distance.h"
#include "support/seven_dof_arm.h"

namespace {

using inscribe::ClearanceRequest;
using inscribe::Environment;
using inscribe::Primitive;
using inscribe::PrimitiveShape;
using inscribe::Vector3;
using inscribe::robot::RobotStateChecker;
using inscribe::robot::StateBatchResult;
using inscribe::robot::StateQuery;
using Clock = std::chrono::steady_clock;

constexpr double kPointRadius = 0.005;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A table, two shelves, a wall and three boxes on the table, and a floor (a thin box), around
// an arm standing at the origin.
std::vector<Primitive> Scene() {
  auto box = [](Vector3 centre, Vector3 half) {
    Primitive p;
    p.shape = PrimitiveShape::kBox;
    p.pose.translation = centre;
    p.half_extents = half;
    return p;
  };
  return {box(Vector3(0.65, 0, 0.38), Vector3(0.3, 0.6, 0.02)),      // table top
          box(Vector3(0, 0.75, 0.9), Vector3(0.4, 0.15, 0.015)),     // shelf
          box(Vector3(0, -0.75, 0.6), Vector3(0.4, 0.15, 0.015)),    // shelf
          box(Vector3(-0.8, 0, 0.7), Vector3(0.02, 0.8, 0.7)),       // wall
          box(Vector3(0.55, 0.2, 0.48), Vector3(0.05, 0.05, 0.08)),  // objects on the table
          box(Vector3(0.7, -0.25, 0.46), Vector3(0.06, 0.04, 0.06)),
          box(Vector3(0.5, -0.05, 0.5), Vector3(0.03, 0.03, 0.1)),
          box(Vector3(0, 0, -0.12), Vector3(1.2, 1.2, 0.02))};  // floor, 10 cm below the base
}

// `count` points on the scene's box surfaces, uniform by area.
std::vector<Vector3> ScenePoints(const std::vector<Primitive>& scene, std::int64_t count,
                                 std::uint64_t seed) {
  std::vector<double> area;
  for (const Primitive& p : scene) {
    const Vector3& h = p.half_extents;
    area.push_back(8 * (h.x() * h.y() + h.y() * h.z() + h.x() * h.z()));
  }
  std::mt19937_64 rng(seed);
  std::discrete_distribution<int> which(area.begin(), area.end());
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vector3> points;
  points.reserve(count);
  while (static_cast<std::int64_t>(points.size()) < count) {
    const Primitive& p = scene[which(rng)];
    const Vector3& h = p.half_extents;
    const double faces[3] = {h.y() * h.z(), h.x() * h.z(), h.x() * h.y()};
    std::discrete_distribution<int> face(faces, faces + 3);
    const int axis = face(rng);
    Vector3 local(u(rng) * h.x(), u(rng) * h.y(), u(rng) * h.z());
    local[axis] = (u(rng) < 0 ? -1 : 1) * h[axis];
    const Vector3 world = p.pose * local;
    if (world.head<2>().norm() < 0.2) continue;  // the arm's base stands here
    points.push_back(world);
  }
  return points;
}

std::vector<double> Flatten(const std::vector<std::vector<double>>& states) {
  std::vector<double> flat;
  for (const auto& q : states) flat.insert(flat.end(), q.begin(), q.end());
  return flat;
}

struct Timed {
  double us_per_state = 0.0;
  double colliding = 0.0;  // fraction
  std::int64_t queries = 0, reused = 0;
};

// Runs the batch until at least `min_seconds` have passed.
Timed TimeStates(const RobotStateChecker& checker, const std::vector<double>& flat, int states,
                 const Environment& environment, const StateQuery& query, double min_seconds) {
  Timed timed;
  int runs = 0;
  const Clock::time_point start = Clock::now();
  StateBatchResult last;
  do {
    last = *checker.CheckStates(flat, environment, query);
    ++runs;
  } while (Since(start) < min_seconds);
  timed.us_per_state = Since(start) * 1e6 / (static_cast<double>(runs) * states);
  for (std::uint8_t c : last.collides) timed.colliding += c;
  timed.colliding /= states;
  timed.queries = last.ball_queries;
  timed.reused = last.reused;
  return timed;
}

// p50 and p99 of single-state calls, microseconds.
std::pair<double, double> Latency(const RobotStateChecker& checker,
                                  const std::vector<std::vector<double>>& states,
                                  const Environment& environment, const StateQuery& query) {
  std::vector<double> us;
  for (const auto& q : states) {
    const Clock::time_point start = Clock::now();
    const auto result = checker.CheckStates(q, environment, query);
    us.push_back(Since(start) * 1e6);
    if (!result.ok()) std::abort();
  }
  std::sort(us.begin(), us.end());
  return {us[us.size() / 2], us[us.size() * 99 / 100]};
}

struct FclArm {
  std::vector<std::shared_ptr<inscribe::testing::FclMesh>> meshes;
};

struct FclTimes {
  double collide_us = 0.0, distance_us = 0.0;
  double colliding = 0.0;
};

// fcl::collide of every link mesh with the octree (stopping at the first contact) per state,
// and fcl::distance of every link mesh to it, on the first states given.
FclTimes TimeFcl(const inscribe::robot::Kinematics& kinematics, const FclArm& arm,
                 const std::vector<Vector3>& points, const std::vector<std::vector<double>>& states,
                 int collide_states, int distance_states, double resolution) {
  auto tree = std::make_shared<octomap::OcTree>(resolution);
  for (const Vector3& p : points) tree->updateNode(octomap::point3d(p.x(), p.y(), p.z()), true);
  tree->updateInnerOccupancy();
  auto octree = std::make_shared<fcl::OcTreed>(tree);
  fcl::CollisionObjectd world(octree);
  std::vector<fcl::CollisionObjectd> links;
  links.reserve(arm.meshes.size());
  for (const auto& mesh : arm.meshes) links.emplace_back(mesh);
  FclTimes times;
  Clock::time_point start = Clock::now();
  for (int s = 0; s < collide_states; ++s) {
    const auto poses = *kinematics.LinkPoses(states[s]);
    bool hit = false;
    for (std::size_t l = 0; l < links.size() && !hit; ++l) {
      links[l].setTransform(poses[l]);
      links[l].computeAABB();
      fcl::CollisionRequestd request;
      fcl::CollisionResultd result;
      fcl::collide(&links[l], &world, request, result);
      hit = result.isCollision();
    }
    times.colliding += hit;
  }
  times.collide_us = Since(start) * 1e6 / collide_states;
  times.colliding /= collide_states;
  start = Clock::now();
  for (int s = 0; s < distance_states; ++s) {
    const auto poses = *kinematics.LinkPoses(states[s]);
    for (std::size_t l = 0; l < links.size(); ++l) {
      links[l].setTransform(poses[l]);
      links[l].computeAABB();
      fcl::DistanceRequestd request;
      fcl::DistanceResultd result;
      fcl::distance(&links[l], &world, request, result);
    }
  }
  times.distance_us = Since(start) * 1e6 / distance_states;
  return times;
}

// Yes/no against every sphere and point (no index): the program's soundness check.
bool MatchesBruteForce(const RobotStateChecker& checker, const std::vector<Vector3>& points,
                       const Environment& cloud, const std::vector<std::vector<double>>& states) {
  StateQuery query;
  query.self_collision = false;
  for (const auto& q : states) {
    const auto spheres = *checker.WorldSpheres(q);
    bool brute = false;
    for (const auto& s : spheres) {
      for (const Vector3& p : points) {
        if ((s.center - p).norm() <= s.radius + kPointRadius) brute = true;
      }
    }
    if (checker.CheckStates(q, cloud, query)->collides[0] != brute) return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"robot states against point clouds, a distance grid and primitives, with FCL"};
  int states = 20000, grid_n = 256, fcl_states = 200;
  double cell_size = 0.0;
  std::vector<std::int64_t> clouds = {10000, 100000, 1000000};
  bool quick = false;
  app.add_option("--states", states, "random states per measurement")
      ->check(CLI::Range(100, 10000000));
  app.add_option("--clouds", clouds, "cloud sizes")->delimiter(',');
  app.add_option("--grid", grid_n, "voxels per axis of the grid")->check(CLI::Range(8, 512));
  app.add_option("--fcl-states", fcl_states, "states FCL collides")->check(CLI::Range(10, 100000));
  app.add_option("--cell-size", cell_size, "the clouds' cell side, metres (0: the query radius)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--quick", quick, "a short run: 2,000 states, clouds of 10k and 100k, a 64^3 grid");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    states = 2000;
    clouds = {10000, 100000};
    grid_n = 64;
    fcl_states = 20;
  }
  const double min_seconds = quick ? 0.05 : 0.5;

  const inscribe::testing::SevenDofArm arm = inscribe::testing::BuildSevenDofArm();
  const RobotStateChecker checker = *RobotStateChecker::Create(arm.robot, arm.spheres);
  const auto configurations =
      inscribe::robot::SampleConfigurations(checker.kinematics(), states, 1);
  const std::vector<double> flat = Flatten(configurations);
  const std::vector<Primitive> scene = Scene();
  FclArm fcl_arm;
  for (const inscribe::Mesh& mesh : inscribe::testing::SevenDofArmMeshes(arm)) {
    fcl_arm.meshes.push_back(inscribe::testing::BuildFclMesh(mesh));
  }
  std::printf(
      "# robot_world: %d spheres, %d variables, %zu self pairs; %d random states, one thread\n\n",
      checker.spheres(), checker.variables(), checker.self_pairs().size(), states);

  StateQuery yes_no;
  StateQuery fast_intervals;
  fast_intervals.intervals = true;
  fast_intervals.clearance = {std::numeric_limits<double>::infinity(),
                              std::numeric_limits<double>::infinity()};
  StateQuery tight_intervals;
  tight_intervals.intervals = true;
  // 1 cm up to a 20 cm activation distance (beyond it only "at least 20 cm").
  tight_intervals.clearance = {0.01, 0.2};
  const std::vector<std::vector<double>> latency_states(
      configurations.begin(), configurations.begin() + std::min<int>(states, 2000));

  std::printf(
      "| environment | build ms | yes/no us/state | states/s | colliding | p50 / p99 us "
      "| intervals O(1) us | intervals 1-20 cm us | FCL octree collide us | ratio | FCL "
      "distance us | ratio |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<Vector3> points_100k;
  bool checked = false;
  for (const std::int64_t n : clouds) {
    const std::vector<Vector3> points = ScenePoints(scene, n, 2);
    if (n == 100000) points_100k = points;
    inscribe::PointCloudOptions options;
    options.point_radius = kPointRadius;
    options.query_radius = 0.06;
    options.cell_size = cell_size;
    const Clock::time_point build = Clock::now();
    const inscribe::PointCloud cloud = *inscribe::PointCloud::Create(points, {}, options);
    const double build_ms = Since(build) * 1e3;
    if (!checked) {
      const std::vector<std::vector<double>> sample(configurations.begin(),
                                                    configurations.begin() + std::min(states, 300));
      if (!MatchesBruteForce(checker, points, cloud, sample)) {
        std::fprintf(stderr, "yes/no differs from the brute force on %lld points\n",
                     static_cast<long long>(n));
        return 1;
      }
      checked = true;
    }
    const Timed a = TimeStates(checker, flat, states, cloud, yes_no, min_seconds);
    const auto [p50, p99] = Latency(checker, latency_states, cloud, yes_no);
    const Timed b = TimeStates(checker, flat, states, cloud, fast_intervals, min_seconds);
    const Timed c = TimeStates(checker, flat, states, cloud, tight_intervals, min_seconds);
    const FclTimes fcl = TimeFcl(checker.kinematics(), fcl_arm, points, configurations,
                                 std::min(fcl_states, states), std::max(2, fcl_states / 20), 0.01);
    std::printf(
        "| cloud %lld | %.1f | %.3f | %.0f | %.0f%% | %.2f / %.2f | %.3f | %.3f | %.1f | "
        "%.0fx | %.0f | %.0fx |\n",
        static_cast<long long>(n), build_ms, a.us_per_state, 1e6 / a.us_per_state,
        100 * a.colliding, p50, p99, b.us_per_state, c.us_per_state, fcl.collide_us,
        fcl.collide_us / a.us_per_state, fcl.distance_us, fcl.distance_us / c.us_per_state);
  }

  // Where a state's time goes: forward kinematics alone, and yes/no without self-collision.
  {
    std::vector<Eigen::Isometry3d> poses;
    const Clock::time_point start = Clock::now();
    for (const auto& q : configurations) {
      if (!checker.kinematics().LinkPoses(q, &poses).ok()) return 1;
    }
    const double fk_us = Since(start) * 1e6 / states;
    std::vector<Vector3> points = points_100k.empty() ? ScenePoints(scene, 100000, 2) : points_100k;
    inscribe::PointCloudOptions options;
    options.point_radius = kPointRadius;
    options.query_radius = 0.06;
    options.cell_size = cell_size;
    const inscribe::PointCloud cloud = *inscribe::PointCloud::Create(points, {}, options);
    StateQuery world_only = yes_no;
    world_only.self_collision = false;
    const Timed w = TimeStates(checker, flat, states, cloud, world_only, min_seconds);
    std::printf(
        "| cloud 100000, world only (no self-collision) | | %.3f | %.0f | %.0f%% | | | | | | | "
        "|\n| forward kinematics alone | | %.3f | | | | | | | | | |\n",
        w.us_per_state, 1e6 / w.us_per_state, 100 * w.colliding, fk_us);
  }

  // The grid: the scene's primitives' signed distance sampled at the voxels.
  {
    inscribe::DistanceGridLayout layout;
    layout.voxel_size = 2.56 / grid_n;
    layout.dims = Vector3::Constant(layout.voxel_size * grid_n);
    layout.pose.translation = Vector3(0, 0, 0.7);
    const auto voxels = *inscribe::DistanceGridVoxels(layout);
    std::vector<float> values(static_cast<std::size_t>(voxels[0]) * voxels[1] * voxels[2], 0.0f);
    const inscribe::SignedDistanceGrid probe =
        *inscribe::SignedDistanceGrid::Create(layout, values);
    const Clock::time_point build = Clock::now();
    double error = 0.0;
    for (int x = 0; x < voxels[0]; ++x) {
      for (int y = 0; y < voxels[1]; ++y) {
        for (int z = 0; z < voxels[2]; ++z) {
          const Vector3 s = probe.SamplePosition(x, y, z);
          double best = std::numeric_limits<double>::infinity();
          for (const Primitive& p : scene)
            best = std::min(best, inscribe::PrimitiveSignedDistance(p, s));
          const float stored = static_cast<float>(best);
          error = std::max(error, std::abs(static_cast<double>(stored) - best));
          values[(static_cast<std::size_t>(x) * voxels[1] + y) * voxels[2] + z] = stored;
        }
      }
    }
    const double fill_ms = Since(build) * 1e3;
    inscribe::DistanceGridOptions grid_options;
    grid_options.value_error = error * (1 + 1e-9);
    const inscribe::SignedDistanceGrid grid =
        *inscribe::SignedDistanceGrid::Create(layout, std::move(values), grid_options);
    const Timed a = TimeStates(checker, flat, states, grid, yes_no, min_seconds);
    const auto [p50, p99] = Latency(checker, latency_states, grid, yes_no);
    const Timed b = TimeStates(checker, flat, states, grid, fast_intervals, min_seconds);
    std::printf(
        "| grid %d^3 (%.0f ms to sample) | - | %.3f | %.0f | %.0f%% | %.2f / %.2f | %.3f | "
        "%.3f | | | | |\n",
        grid_n, fill_ms, a.us_per_state, 1e6 / a.us_per_state, 100 * a.colliding, p50, p99,
        b.us_per_state, b.us_per_state);
    const inscribe::PrimitiveEnvironment primitives =
        *inscribe::PrimitiveEnvironment::Create(scene);
    const Timed p = TimeStates(checker, flat, states, primitives, yes_no, min_seconds);
    const Timed pi = TimeStates(checker, flat, states, primitives, fast_intervals, min_seconds);
    std::printf("| %zu primitives | - | %.3f | %.0f | %.0f%% | | %.3f | %.3f | | | | |\n\n",
                scene.size(), p.us_per_state, 1e6 / p.us_per_state, 100 * p.colliding,
                pi.us_per_state, pi.us_per_state);
  }

  if (points_100k.empty()) points_100k = ScenePoints(scene, 100000, 2);
  inscribe::PointCloudOptions options;
  options.point_radius = kPointRadius;
  options.query_radius = 0.06;
  options.cell_size = cell_size;
  const inscribe::PointCloud cloud = *inscribe::PointCloud::Create(points_100k, {}, options);

  // A motion: a random walk of 0.01 rad steps per joint from a clear state; with and without
  // reuse.
  std::size_t first_clear = 0;
  while (first_clear + 1 < configurations.size() &&
         checker.CheckStates(configurations[first_clear], cloud)->collides[0]) {
    ++first_clear;
  }
  std::vector<std::vector<double>> motion = {configurations[first_clear]};
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> step(-0.01, 0.01);
  while (static_cast<int>(motion.size()) < states) {
    std::vector<double> q = motion.back();
    for (std::size_t j = 0; j < q.size(); ++j) {
      const auto& v = checker.kinematics().variables()[j];
      q[j] = std::clamp(q[j] + step(rng), v.lower, v.upper);
    }
    motion.push_back(q);
  }
  const std::vector<double> motion_flat = Flatten(motion);
  StateQuery reuse = yes_no;
  reuse.reuse_certificates = true;
  StateQuery reuse_intervals = tight_intervals;
  reuse_intervals.reuse_certificates = true;
  const Timed m0 = TimeStates(checker, motion_flat, states, cloud, yes_no, min_seconds);
  const Timed m1 = TimeStates(checker, motion_flat, states, cloud, reuse, min_seconds);
  const Timed m2 = TimeStates(checker, motion_flat, states, cloud, tight_intervals, min_seconds);
  const Timed m3 = TimeStates(checker, motion_flat, states, cloud, reuse_intervals, min_seconds);
  std::printf(
      "| motion of %d states, 0.01 rad steps, cloud 100k | us/state | ball queries/state | "
      "reused/state |\n|---|---|---|---|\n",
      states);
  std::printf("| yes/no | %.3f | %.1f | |\n| yes/no, reuse | %.3f | %.1f | %.1f |\n",
              m0.us_per_state, static_cast<double>(m0.queries) / states, m1.us_per_state,
              static_cast<double>(m1.queries) / states, static_cast<double>(m1.reused) / states);
  std::printf(
      "| intervals 1-20 cm | %.3f | %.1f | |\n| intervals 1-20 cm, reuse | %.3f | %.1f | %.1f "
      "|\n\n",
      m2.us_per_state, static_cast<double>(m2.queries) / states, m3.us_per_state,
      static_cast<double>(m3.queries) / states, static_cast<double>(m3.reused) / states);

  // Segments between states 10 steps apart along the motion.
  {
    int segments = 0, proved = 0, colliding = 0;
    std::int64_t checked_states = 0;
    const Clock::time_point start = Clock::now();
    for (std::size_t s = 0; s + 10 < motion.size() && segments < 2000; s += 10, ++segments) {
      const auto r = *checker.CheckSegment(motion[s], motion[s + 10], cloud);
      proved += r.proved;
      colliding += r.collides;
      checked_states += r.states_checked;
    }
    const double us = Since(start) * 1e6 / segments;
    inscribe::robot::SegmentOptions discrete;
    discrete.method = inscribe::robot::SegmentOptions::Method::kResolution;
    discrete.resolution = 0.01;
    int discrete_segments = 0;
    std::int64_t discrete_states = 0;
    const Clock::time_point start2 = Clock::now();
    for (std::size_t s = 0; s + 10 < motion.size() && discrete_segments < 2000;
         s += 10, ++discrete_segments) {
      discrete_states +=
          checker.CheckSegment(motion[s], motion[s + 10], cloud, discrete)->states_checked;
    }
    const double us2 = Since(start2) * 1e6 / discrete_segments;
    std::printf(
        "| segments (0.1 rad per joint at most), cloud 100k | us/segment | states/segment "
        "| proved clear | colliding |\n|---|---|---|---|---|\n");
    std::printf("| conservative advancement | %.1f | %.1f | %.0f%% | %.0f%% |\n", us,
                static_cast<double>(checked_states) / segments, 100.0 * proved / segments,
                100.0 * colliding / segments);
    std::printf("| resolution 0.01 rad | %.1f | %.1f | (no proof) | |\n\n", us2,
                static_cast<double>(discrete_states) / discrete_segments);
  }

  // The self-filter: 100k points, the arm's spheres padded by 2 cm, at 50 states.
  {
    const int runs = quick ? 5 : 50;
    std::int64_t dropped = 0;
    const Clock::time_point start = Clock::now();
    for (int s = 0; s < runs; ++s) {
      const auto spheres = *checker.WorldSpheres(configurations[s], 0.02);
      dropped += inscribe::SelfFilterPoints(points_100k, spheres)->dropped;
    }
    std::printf(
        "| self-filter of 100k points (60 spheres, 2 cm padding) | ms | points dropped |\n"
        "|---|---|---|\n| mean of %d states | %.3f | %.0f |\n",
        runs, Since(start) * 1e3 / runs, static_cast<double>(dropped) / runs);
  }
  return 0;
}
