#include "inscribe/scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "distance/sphere_pair_search.h"
#include "support/sphere_sets.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::RandomPose;
using testing::RandomSpheres;

std::shared_ptr<const SphereHierarchy> Hierarchy(const std::vector<Sphere>& spheres,
                                                 HierarchyVolume volume) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, volume);
  EXPECT_TRUE(h.ok()) << h.status();
  return std::make_shared<const SphereHierarchy>(*std::move(h));
}

// The spheres grown by `by`: a set holding the original (a stand-in cover for equality tests).
std::vector<Sphere> Grown(std::vector<Sphere> spheres, double by) {
  for (Sphere& s : spheres) s.radius += by;
  return spheres;
}

// A pose near `center`: random rotation, translation uniform in a ball of `spread` around it.
RigidPose PoseNear(std::mt19937_64& rng, const Vector3& center, double spread) {
  RigidPose pose = RandomPose(rng, spread);
  pose.translation += center;
  return pose;
}

// The reference: every pair of objects, filtered by groups, masks and the ignore list, and
// compared sphere pair by sphere pair (certified pairs through CertifiedDistances).
struct Reference {
  struct Pair {
    double distance;  // plain pairs; the covers' for certified ones
    bool certified;
    double lower, upper;
  };
  std::map<std::pair<SceneObjectId, SceneObjectId>, Pair> close;
};

Reference BruteForce(const std::map<SceneObjectId, SceneObject>& objects,
                     const std::vector<std::pair<SceneObjectId, SceneObjectId>>& ignored,
                     double threshold) {
  Reference out;
  for (auto i = objects.begin(); i != objects.end(); ++i) {
    for (auto j = std::next(i); j != objects.end(); ++j) {
      const SceneObject& a = i->second;
      const SceneObject& b = j->second;
      if ((a.group & b.mask) == 0 || (b.group & a.mask) == 0) continue;
      if (std::find(ignored.begin(), ignored.end(), std::make_pair(a.id, b.id)) != ignored.end() ||
          std::find(ignored.begin(), ignored.end(), std::make_pair(b.id, a.id)) != ignored.end()) {
        continue;
      }
      const RigidPose pose_a = *NormalizedPose(a.pose), pose_b = *NormalizedPose(b.pose);
      if (a.certified() && b.certified()) {
        const CertifiedObject ca{a.internal.get(), a.cover.get(), a.cover_delta};
        const CertifiedObject cb{b.internal.get(), b.cover.get(), b.cover_delta};
        absl::StatusOr<DistanceResult> covers =
            BruteForceSeparationDistance(a.cover->spheres(), pose_a, b.cover->spheres(), pose_b);
        absl::StatusOr<double> margin = CertifiedDistanceMargin(ca, pose_a, cb, pose_b);
        absl::StatusOr<std::vector<CertifiedDistanceResult>> interval =
            CertifiedDistances({CertifiedPair{&ca, &cb, pose_a, pose_b}});
        EXPECT_TRUE(covers.ok() && margin.ok() && interval.ok());
        if (covers->distance - *margin < threshold) {
          out.close[{a.id, b.id}] = {covers->distance, true, (*interval)[0].lower,
                                     (*interval)[0].upper};
        }
        continue;
      }
      absl::StatusOr<DistanceResult> r =
          BruteForceSeparationDistance(a.spheres->spheres(), pose_a, b.spheres->spheres(), pose_b);
      EXPECT_TRUE(r.ok());
      if (r->distance < threshold) out.close[{a.id, b.id}] = {r->distance, false, 0.0, 0.0};
    }
  }
  return out;
}

void ExpectEqual(const SceneFrame& frame, const Reference& reference, const std::string& where) {
  ASSERT_EQ(frame.pairs.size(), reference.close.size()) << where;
  EXPECT_EQ(frame.close_pairs, static_cast<std::int64_t>(reference.close.size())) << where;
  EXPECT_FALSE(frame.truncated);
  auto expected = reference.close.begin();
  for (const ScenePair& p : frame.pairs) {
    ASSERT_EQ(std::make_pair(p.a, p.b), expected->first) << where;
    EXPECT_EQ(p.certified, expected->second.certified) << where;
    EXPECT_NEAR(p.result.distance, expected->second.distance, 1e-9) << where;
    EXPECT_NEAR((p.result.point_a - p.result.point_b).norm(), std::abs(p.result.distance), 1e-9);
    if (p.certified) {
      EXPECT_NEAR(p.lower, expected->second.lower, 1e-12) << where;
      EXPECT_NEAR(p.upper, expected->second.upper, 1e-12) << where;
    }
    ++expected;
  }
}

// A scene of many objects (random sets and, when present, real meshes' medial spheres), some
// certified, with groups, masks and ignored pairs, over frames of small moves, teleports,
// additions and removals: every frame equals the brute force over all pairs, for thresholds
// from deep overlap to every pair.
TEST(Scene, EveryFrameEqualsBruteForce) {
  std::vector<std::shared_ptr<const SphereHierarchy>> shapes, covers;
  for (int k = 0; k < 4; ++k) {
    const std::vector<Sphere> set = RandomSpheres(60 + 40 * k, 100 + k);
    const HierarchyVolume volume = k % 2 ? HierarchyVolume::kRss : HierarchyVolume::kSphere;
    shapes.push_back(Hierarchy(set, volume));
    covers.push_back(Hierarchy(Grown(set, 0.01), volume));
  }
  for (const char* name : {"eight.off", "knot1.off"}) {
    if (testing::TestMeshPath(name).empty()) continue;
    std::vector<Sphere> set = testing::RealSphereSet(name);
    // Scaled to about the random sets' unit size.
    double extent = 0.0;
    for (const Sphere& s : set) extent = std::max(extent, s.center.norm() + s.radius);
    for (Sphere& s : set) {
      s.center /= extent;
      s.radius /= extent;
    }
    shapes.push_back(Hierarchy(set, HierarchyVolume::kRss));
    covers.push_back(Hierarchy(Grown(set, 0.02), HierarchyVolume::kSphere));
  }

  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Scene scene;
  std::map<SceneObjectId, SceneObject> objects;
  std::vector<std::pair<SceneObjectId, SceneObjectId>> ignored;
  SceneObjectId next_id = 1000;
  const double box = 6.0;
  const auto make = [&]() {
    SceneObject o;
    o.id = next_id;
    next_id += 1 + rng() % 7;  // ids not in insertion order's footsteps
    const std::size_t shape = rng() % shapes.size();
    o.spheres = shapes[shape];
    if (unit(rng) < 0.4) {
      o.internal = shapes[shape];
      o.cover = covers[shape];
      o.cover_delta = 0.05;
    }
    o.pose = PoseNear(rng, Vector3(unit(rng), unit(rng), unit(rng)) * box, 0.0);
    o.group = 1u << (rng() % 3);
    o.mask = unit(rng) < 0.8 ? kAllSceneGroups : (1u | (1u << (rng() % 3)));
    return o;
  };
  for (int i = 0; i < 40; ++i) {
    SceneObject o = make();
    ASSERT_TRUE(scene.Add(o).ok());
    objects[o.id] = o;
  }
  for (int i = 0; i < 10; ++i) {
    auto a = objects.begin(), b = objects.begin();
    std::advance(a, rng() % objects.size());
    std::advance(b, rng() % objects.size());
    if (a->first == b->first) continue;
    ASSERT_TRUE(scene.Ignore(a->first, b->first).ok());
    ignored.emplace_back(a->first, b->first);
  }

  const double thresholds[] = {-0.05, 0.0, 0.1, 0.4, std::numeric_limits<double>::infinity()};
  for (int frame = 0; frame < 60; ++frame) {
    // Move a third of the objects a little, and teleport one.
    std::vector<std::pair<SceneObjectId, RigidPose>> moves;
    for (auto& [id, o] : objects) {
      if (rng() % 3 != 0) continue;
      o.pose = PoseNear(rng, o.pose.translation, 0.15);
      moves.emplace_back(id, o.pose);
    }
    auto teleported = objects.begin();
    std::advance(teleported, rng() % objects.size());
    teleported->second.pose = PoseNear(rng, Vector3(unit(rng), unit(rng), unit(rng)) * box, 0.0);
    moves.emplace_back(teleported->first, teleported->second.pose);
    ASSERT_TRUE(scene.SetPoses(moves).ok());
    if (frame % 10 == 5) {
      // Remove one (with its ignore entries) and add two.
      auto gone = objects.begin();
      std::advance(gone, rng() % objects.size());
      const SceneObjectId id = gone->first;
      ASSERT_TRUE(scene.Remove(id).ok());
      objects.erase(gone);
      ignored.erase(std::remove_if(ignored.begin(), ignored.end(),
                                   [id](const auto& p) { return p.first == id || p.second == id; }),
                    ignored.end());
      for (int k = 0; k < 2; ++k) {
        SceneObject o = make();
        ASSERT_TRUE(scene.Add(o).ok());
        objects[o.id] = o;
      }
    }
    const double threshold = thresholds[frame % 5];
    SceneQuery query;
    query.threshold = threshold;
    query.parallel = frame % 2 == 0;
    absl::StatusOr<SceneFrame> got = scene.ClosePairs(query);
    ASSERT_TRUE(got.ok()) << got.status();
    ExpectEqual(*got, BruteForce(objects, ignored, threshold),
                "frame " + std::to_string(frame) + " threshold " + std::to_string(threshold));
    if (std::isinf(threshold)) {
      EXPECT_GT(got->pairs.size(), 300u);
    }
  }
}

// Objects spread over a large box: the broad phase hands the narrow phase a small fraction of
// all pairs, and still misses none (equal to brute force).
TEST(Scene, BroadPhasePrunesFarPairs) {
  const auto shape = Hierarchy(RandomSpheres(50, 7), HierarchyVolume::kSphere);
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> coordinate(0.0, 40.0);
  Scene scene;
  std::map<SceneObjectId, SceneObject> objects;
  for (SceneObjectId id = 0; id < 300; ++id) {
    SceneObject o;
    o.id = id;
    o.spheres = shape;
    o.pose = PoseNear(rng, Vector3(coordinate(rng), coordinate(rng), coordinate(rng)), 0.0);
    ASSERT_TRUE(scene.Add(o).ok());
    objects[id] = o;
  }
  SceneQuery query;
  query.threshold = 0.5;
  for (int frame = 0; frame < 5; ++frame) {
    std::vector<std::pair<SceneObjectId, RigidPose>> moves;
    for (auto& [id, o] : objects) {
      o.pose = PoseNear(rng, o.pose.translation, 0.5);
      moves.emplace_back(id, o.pose);
    }
    ASSERT_TRUE(scene.SetPoses(moves).ok());
    absl::StatusOr<SceneFrame> got = scene.ClosePairs(query);
    ASSERT_TRUE(got.ok());
    ExpectEqual(*got, BruteForce(objects, {}, query.threshold), "frame " + std::to_string(frame));
    EXPECT_LT(got->candidate_pairs, 300 * 299 / 2 / 50);  // under 2% of all pairs
    EXPECT_GE(got->candidate_pairs, got->close_pairs);
  }
}

// Spheres of radius r along a line (a rod) or over a square (a plate), centred at the origin:
// sets whose boxes are thin, so that the oriented-box test decides many pairs.
std::vector<Sphere> Rod(double length, double r) {
  std::vector<Sphere> out;
  for (double x = -0.5 * length; x <= 0.5 * length + 1e-12; x += r) {
    out.push_back(Sphere{Vector3(x, 0.0, 0.0), r});
  }
  return out;
}
std::vector<Sphere> Plate(double side, double r) {
  std::vector<Sphere> out;
  for (double x = -0.5 * side; x <= 0.5 * side + 1e-12; x += 2.0 * r) {
    for (double y = -0.5 * side; y <= 0.5 * side + 1e-12; y += 2.0 * r) {
      out.push_back(Sphere{Vector3(x, y, 0.0), r});
    }
  }
  return out;
}

// Objects 0..count-1 of the shapes in turn, at random poses in a cube of side `box`, added to
// `scene`; returned by id.
std::map<SceneObjectId, SceneObject> AddObjects(
    const std::vector<std::shared_ptr<const SphereHierarchy>>& shapes, SceneObjectId count,
    double box, std::mt19937_64& rng, Scene* scene) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::map<SceneObjectId, SceneObject> objects;
  for (SceneObjectId id = 0; id < count; ++id) {
    SceneObject o;
    o.id = id;
    o.spheres = shapes[id % shapes.size()];
    o.pose = PoseNear(rng, Vector3(unit(rng), unit(rng), unit(rng)) * box, 0.0);
    EXPECT_TRUE(scene->Add(o).ok());
    objects[id] = o;
  }
  return objects;
}

// Rods and plates packed densely, turned at random and by quarter turns (parallel edges, the
// degenerate axes of the oriented-box test), each frame nudged by tiny moves so that many
// pairs graze: the broad phase never drops a pair the brute force finds.
TEST(Scene, ThinObjectsGrazingEqualBruteForce) {
  const std::vector<std::shared_ptr<const SphereHierarchy>> shapes = {
      Hierarchy(Rod(1.0, 0.02), HierarchyVolume::kRss),
      Hierarchy(Rod(0.6, 0.05), HierarchyVolume::kSphere),
      Hierarchy(Plate(0.8, 0.03), HierarchyVolume::kRss)};
  std::mt19937_64 rng(71);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto quarter_turns = [&rng]() {
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(static_cast<int>(rng() % 3));
    return Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2 * static_cast<double>(rng() % 4), axis));
  };
  Scene scene;
  std::map<SceneObjectId, SceneObject> objects = AddObjects(shapes, 60, 1.6, rng, &scene);
  for (auto& [id, o] : objects) {
    if (id % 2 == 0) o.pose.rotation = quarter_turns();
  }
  std::int64_t candidates = 0, close = 0;
  for (int frame = 0; frame < 40; ++frame) {
    std::vector<std::pair<SceneObjectId, RigidPose>> moves;
    for (auto& [id, o] : objects) {
      o.pose.translation += Vector3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5) * 0.02;
      if (frame % 8 == 7)
        o.pose.rotation = id % 2 == 0 ? quarter_turns() : RandomPose(rng, 0).rotation;
      moves.emplace_back(id, o.pose);
    }
    ASSERT_TRUE(scene.SetPoses(moves).ok());
    for (const double threshold : {-0.01, 0.0, 0.003, 0.05}) {
      SceneQuery query;
      query.threshold = threshold;
      absl::StatusOr<SceneFrame> got = scene.ClosePairs(query);
      ASSERT_TRUE(got.ok()) << got.status();
      ExpectEqual(*got, BruteForce(objects, {}, threshold),
                  "frame " + std::to_string(frame) + " threshold " + std::to_string(threshold));
      candidates += got->candidate_pairs;
      close += got->close_pairs;
    }
  }
  EXPECT_GT(close, 400);
  EXPECT_GE(candidates, close);
}

// One-sphere objects (the float sphere test in the sweep then decides alone) in pairs whose
// gaps lie within 0.01 of the threshold, far from the origin (1e4: float rounding of the
// centres is about 1e-3 there), on both sweep paths (AVX2 and SSE2): the float filters drop no
// pair the brute force finds. Without the sphere test's margin, pairs within the rounding of
// the threshold are lost.
TEST(Scene, SweepFloatFiltersKeepGrazingPairsFarFromTheOrigin) {
  std::mt19937_64 rng(91);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const bool avx2 = internal::use_avx2_filter;
  for (const bool use_avx2 : {true, false}) {
    internal::use_avx2_filter = use_avx2 && avx2;
    for (const double threshold : {0.0, 0.02, -0.3}) {
      Scene scene;
      std::map<SceneObjectId, SceneObject> objects;
      for (SceneObjectId pair = 0; pair < 150; ++pair) {
        const Vector3 base =
            Vector3(1e4, -1e4, 1e4) + Vector3(3.0 * (pair % 10), 3.0 * ((pair / 10) % 5),
                                              3.0 * static_cast<double>(pair / 50));
        const double r_a = 0.2 + 0.3 * unit(rng), r_b = 0.2 + 0.3 * unit(rng);
        const Vector3 offset_a = RandomPose(rng, 0.2).translation;
        const Vector3 offset_b = RandomPose(rng, 0.2).translation;
        SceneObject a, b;
        a.id = 2 * pair;
        b.id = 2 * pair + 1;
        a.spheres = Hierarchy({Sphere{offset_a, r_a}}, HierarchyVolume::kSphere);
        b.spheres = Hierarchy({Sphere{offset_b, r_b}}, HierarchyVolume::kSphere);
        a.pose = PoseNear(rng, base, 0.0);
        b.pose = PoseNear(rng, Vector3::Zero(), 0.0);
        // b's sphere centre at r_a + r_b + threshold + [-0.01, 0.01] from a's, in a random
        // direction.
        const Vector3 center_a = a.pose * offset_a;
        const Vector3 direction = RandomPose(rng, 1.0).translation.normalized();
        const double gap = std::max(0.05 - r_a - r_b, threshold) + 0.02 * (unit(rng) - 0.5);
        const Vector3 center_b = center_a + direction * (r_a + r_b + gap);
        b.pose.translation = center_b - b.pose.rotation * offset_b;
        for (const SceneObject& o : {a, b}) {
          ASSERT_TRUE(scene.Add(o).ok());
          objects[o.id] = o;
        }
      }
      SceneQuery query;
      query.threshold = threshold;
      absl::StatusOr<SceneFrame> got = scene.ClosePairs(query);
      ASSERT_TRUE(got.ok()) << got.status();
      const Reference expected = BruteForce(objects, {}, threshold);
      ExpectEqual(
          *got, expected,
          std::string(use_avx2 ? "AVX2" : "SSE2") + " threshold " + std::to_string(threshold));
      EXPECT_GT(expected.close.size(), 40u) << threshold;
      EXPECT_LT(expected.close.size(), 110u) << threshold;
    }
  }
  internal::use_avx2_filter = avx2;
}

// stop_at_first over frames of small moves, with objects removed and re-added under the same
// id with another set (a remembered sphere pair may then be out of range or stale): every
// frame reports the brute force's pairs, each with the exact value of the sphere pair it
// names, below the threshold.
TEST(Scene, StopAtFirstAcrossFramesEqualsBruteForce) {
  const std::vector<std::shared_ptr<const SphereHierarchy>> shapes = {
      Hierarchy(RandomSpheres(200, 21), HierarchyVolume::kRss),
      Hierarchy(RandomSpheres(12, 22), HierarchyVolume::kSphere),
      Hierarchy(Rod(1.2, 0.04), HierarchyVolume::kRss)};
  std::mt19937_64 rng(73);
  Scene scene;
  std::map<SceneObjectId, SceneObject> objects = AddObjects(shapes, 40, 2.5, rng, &scene);
  for (int frame = 0; frame < 60; ++frame) {
    std::vector<std::pair<SceneObjectId, RigidPose>> moves;
    for (auto& [id, o] : objects) {
      o.pose = PoseNear(rng, o.pose.translation, 0.03);
      moves.emplace_back(id, o.pose);
    }
    ASSERT_TRUE(scene.SetPoses(moves).ok());
    if (frame % 10 == 9) {
      // The same id back with another set.
      const SceneObjectId id = rng() % objects.size();
      ASSERT_TRUE(scene.Remove(id).ok());
      SceneObject& o = objects[id];
      o.spheres = shapes[(id + 1 + rng() % 2) % shapes.size()];
      ASSERT_TRUE(scene.Add(o).ok());
    }
    const double threshold = frame % 3 == 0 ? 0.0 : 0.02;
    SceneQuery query;
    query.threshold = threshold;
    query.stop_at_first = true;
    absl::StatusOr<SceneFrame> got = scene.ClosePairs(query);
    ASSERT_TRUE(got.ok()) << got.status();
    const Reference expected = BruteForce(objects, {}, threshold);
    ASSERT_EQ(got->pairs.size(), expected.close.size()) << "frame " << frame;
    ASSERT_GT(got->pairs.size(), 5u);
    for (const ScenePair& p : got->pairs) {
      const auto it = expected.close.find({p.a, p.b});
      ASSERT_NE(it, expected.close.end()) << "frame " << frame;
      const SceneObject& a = objects[p.a];
      const SceneObject& b = objects[p.b];
      absl::StatusOr<DistanceResult> named =
          SpherePairDistance(a.spheres->spheres(), a.pose, b.spheres->spheres(), b.pose,
                             p.result.sphere_a, p.result.sphere_b);
      ASSERT_TRUE(named.ok()) << named.status();
      EXPECT_EQ(p.result.distance, named->distance) << "frame " << frame;
      EXPECT_LT(p.result.distance, threshold);
      EXPECT_GE(p.result.distance, it->second.distance - 1e-12);
      EXPECT_TRUE(p.result.closer);
    }
  }
}

// stop_at_first reports the same pairs as the full query, each with a real sphere pair's value
// below the threshold (not always the minimum), for less work.
TEST(Scene, StopAtFirstReportsTheSamePairs) {
  const auto shape = Hierarchy(RandomSpheres(150, 13), HierarchyVolume::kRss);
  std::mt19937_64 rng(59);
  Scene scene;
  for (SceneObjectId id = 0; id < 40; ++id) {
    SceneObject o;
    o.id = id;
    o.spheres = shape;
    o.pose = PoseNear(rng, Vector3::Constant(1.5), 1.5);
    ASSERT_TRUE(scene.Add(o).ok());
  }
  for (const double threshold : {-0.02, 0.0, 0.05}) {
    SceneQuery full;
    full.threshold = threshold;
    SceneQuery first = full;
    first.stop_at_first = true;
    absl::StatusOr<SceneFrame> a = scene.ClosePairs(full);
    absl::StatusOr<SceneFrame> b = scene.ClosePairs(first);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(a->pairs.size(), b->pairs.size());
    ASSERT_GT(a->pairs.size(), 10u);
    std::int64_t full_work = 0, first_work = 0;
    for (std::size_t i = 0; i < a->pairs.size(); ++i) {
      ASSERT_EQ(a->pairs[i].a, b->pairs[i].a);
      ASSERT_EQ(a->pairs[i].b, b->pairs[i].b);
      EXPECT_LT(b->pairs[i].result.distance, threshold);
      EXPECT_GE(b->pairs[i].result.distance, a->pairs[i].result.distance);
      EXPECT_GE(b->pairs[i].result.sphere_a, 0);
      full_work += a->pairs[i].result.sphere_tests;
      first_work += b->pairs[i].result.sphere_tests;
    }
    EXPECT_LT(first_work, full_work);
  }
}

// max_pairs keeps the nearest pairs, sorted by id, and says it cut.
TEST(Scene, MaxPairsKeepsTheNearest) {
  const auto shape = Hierarchy(RandomSpheres(40, 9), HierarchyVolume::kRss);
  std::mt19937_64 rng(47);
  Scene scene;
  for (SceneObjectId id = 0; id < 30; ++id) {
    SceneObject o;
    o.id = id;
    o.spheres = shape;
    o.pose = RandomPose(rng, 3.0);
    ASSERT_TRUE(scene.Add(o).ok());
  }
  SceneQuery all;
  all.threshold = std::numeric_limits<double>::infinity();
  absl::StatusOr<SceneFrame> full = scene.ClosePairs(all);
  ASSERT_TRUE(full.ok());
  ASSERT_EQ(full->pairs.size(), 30u * 29 / 2);
  SceneQuery cut = all;
  cut.max_pairs = 25;
  absl::StatusOr<SceneFrame> some = scene.ClosePairs(cut);
  ASSERT_TRUE(some.ok());
  EXPECT_TRUE(some->truncated);
  EXPECT_EQ(some->close_pairs, 435);
  ASSERT_EQ(some->pairs.size(), 25u);
  std::vector<double> distances;
  for (const ScenePair& p : full->pairs) distances.push_back(p.result.distance);
  std::sort(distances.begin(), distances.end());
  for (std::size_t i = 0; i + 1 < some->pairs.size(); ++i) {
    EXPECT_LT(std::make_pair(some->pairs[i].a, some->pairs[i].b),
              std::make_pair(some->pairs[i + 1].a, some->pairs[i + 1].b));
  }
  for (const ScenePair& p : some->pairs) EXPECT_LE(p.result.distance, distances[24]);
}

TEST(Scene, RefusesBadInputAndChangesNothing) {
  const auto shape = Hierarchy(RandomSpheres(20, 3), HierarchyVolume::kRss);
  Scene scene;
  SceneObject o;
  o.id = 7;
  o.spheres = shape;
  ASSERT_TRUE(scene.Add(o).ok());
  EXPECT_EQ(scene.Add(o).code(), absl::StatusCode::kAlreadyExists);

  SceneObject missing;
  missing.id = 8;
  absl::Status s = scene.Add(missing);
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("object 8"), std::string::npos) << s;
  SceneObject half = o;
  half.id = 9;
  half.cover = shape;
  EXPECT_NE(scene.Add(half).message().find("both"), std::string::npos);
  SceneObject bad_delta = half;
  bad_delta.internal = shape;
  bad_delta.cover_delta = std::nan("");
  EXPECT_FALSE(scene.Add(bad_delta).ok());
  SceneObject bad_pose = o;
  bad_pose.id = 10;
  bad_pose.pose.translation.y() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(scene.Add(bad_pose).ok());
  EXPECT_EQ(scene.size(), 1u);

  SceneObject other = o;
  other.id = 11;
  other.pose.translation = Vector3(0.1, 0, 0);
  ASSERT_TRUE(scene.Add(other).ok());
  // All or nothing: the good first pose is not applied when the second is bad.
  RigidPose far;
  far.translation = Vector3(100, 0, 0);
  RigidPose nan_pose;
  nan_pose.rotation.w() = std::nan("");
  s = scene.SetPoses({{7, far}, {11, nan_pose}});
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("poses[1] (object 11)"), std::string::npos) << s;
  s = scene.SetPoses({{7, far}, {12, far}});
  EXPECT_EQ(s.code(), absl::StatusCode::kNotFound);
  EXPECT_NE(s.message().find("no object 12"), std::string::npos) << s;
  absl::StatusOr<SceneFrame> frame = scene.ClosePairs({});
  ASSERT_TRUE(frame.ok());
  EXPECT_EQ(frame->pairs.size(), 1u);  // 7 never moved away from 11

  EXPECT_EQ(scene.Ignore(7, 7).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(scene.Ignore(7, 99).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(scene.Remove(99).code(), absl::StatusCode::kNotFound);
  SceneQuery nan_query;
  nan_query.threshold = std::nan("");
  EXPECT_NE(scene.ClosePairs(nan_query).status().message().find("threshold"), std::string::npos);
  SceneQuery no_pairs;
  no_pairs.max_pairs = 0;
  EXPECT_FALSE(scene.ClosePairs(no_pairs).ok());
  SceneQuery negative;
  negative.abs_err = -1;
  EXPECT_FALSE(scene.ClosePairs(negative).ok());
}

TEST(Scene, StopsWhenCancelled) {
  const auto shape = Hierarchy(RandomSpheres(100, 5), HierarchyVolume::kSphere);
  Scene scene;
  std::mt19937_64 rng(53);
  for (SceneObjectId id = 0; id < 50; ++id) {
    SceneObject o;
    o.id = id;
    o.spheres = shape;
    o.pose = RandomPose(rng, 2.0);
    ASSERT_TRUE(scene.Add(o).ok());
  }
  std::atomic<bool> cancel{true};
  SceneQuery query;
  query.threshold = 1.0;
  EXPECT_EQ(scene.ClosePairs(query, &cancel).status().code(), absl::StatusCode::kCancelled);
  cancel = false;
  EXPECT_TRUE(scene.ClosePairs(query, &cancel).ok());
}

}  // namespace
}  // namespace inscribe
