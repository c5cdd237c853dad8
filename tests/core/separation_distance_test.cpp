#include "inscribe/distance/separation_distance.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "distance/sphere_pair_search.h"
#include "support/sphere_sets.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::RandomPose;
using testing::RandomSpheres;
using testing::RealSphereSet;

SphereHierarchy Build(const std::vector<Sphere>& spheres, HierarchyVolume volume) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, volume);
  EXPECT_TRUE(h.ok()) << h.status();
  return *std::move(h);
}

// The witnesses are on their spheres, in the world frame, facing each other: |pa - pb| equals
// |distance| and pa - c_a is along c_b - c_a.
void ExpectWitnesses(const DistanceResult& r, const std::vector<Sphere>& a, const RigidPose& pose_a,
                     const std::vector<Sphere>& b, const RigidPose& pose_b) {
  ASSERT_GE(r.sphere_a, 0);
  ASSERT_GE(r.sphere_b, 0);
  const Sphere& sa = a[static_cast<std::size_t>(r.sphere_a)];
  const Sphere& sb = b[static_cast<std::size_t>(r.sphere_b)];
  const Vector3 ca = pose_a * sa.center, cb = pose_b * sb.center;
  EXPECT_NEAR((r.point_a - ca).norm(), sa.radius, 1e-9);
  EXPECT_NEAR((r.point_b - cb).norm(), sb.radius, 1e-9);
  EXPECT_NEAR((r.point_a - r.point_b).norm(), std::abs(r.distance), 1e-9);
  EXPECT_NEAR((cb - ca).norm() - sa.radius - sb.radius, r.distance, 1e-9);
}

using Case = std::tuple<std::string, HierarchyVolume>;

class AgainstBruteForce : public ::testing::TestWithParam<Case> {
 protected:
  // Random sets (by seed) or a real mesh's medial spheres (by name), a copy for b.
  std::vector<Sphere> Set(int which) const {
    const std::string& name = std::get<0>(GetParam());
    if (name == "random") return RandomSpheres(which == 0 ? 400 : 250, which == 0 ? 5 : 6);
    return RealSphereSet(name);
  }
  void SkipIfMissing() {
    const std::string& name = std::get<0>(GetParam());
    if (name != "random" && testing::TestMeshPath(name).empty()) {
      GTEST_SKIP() << name << " is missing; run scripts/fetch-meshes";
    }
  }
};

// With zero tolerance the hierarchy's answer is the minimum over all sphere pairs, on 2,000
// random poses spread so that about a third of them overlap, both sets posed.
TEST_P(AgainstBruteForce, ExactDistanceOnRandomPoses) {
  SkipIfMissing();
  const std::vector<Sphere> a = Set(0), b = Set(1);
  ASSERT_FALSE(a.empty());
  const SphereHierarchy ha = Build(a, std::get<1>(GetParam()));
  const SphereHierarchy hb = Build(b, std::get<1>(GetParam()));
  double diameter = 0.0;
  for (const Sphere& s : a) diameter = std::max(diameter, (s.center - a[0].center).norm());
  std::mt19937_64 rng(17);
  int overlapping = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const RigidPose pose_a = trial % 2 ? RandomPose(rng, diameter) : RigidPose{};
    const RigidPose pose_b = RandomPose(rng, 1.5 * diameter);
    absl::StatusOr<DistanceResult> fast = SeparationDistance(ha, pose_a, hb, pose_b);
    absl::StatusOr<DistanceResult> slow = BruteForceSeparationDistance(a, pose_a, b, pose_b);
    ASSERT_TRUE(fast.ok() && slow.ok());
    ASSERT_NEAR(fast->distance, slow->distance, 1e-9) << "trial " << trial;
    overlapping += slow->distance < 0.0;
    if (trial % 50 == 0) ExpectWitnesses(*fast, a, pose_a, b, pose_b);
    EXPECT_LT(fast->sphere_tests, static_cast<std::int64_t>(a.size() * b.size()));
  }
  EXPECT_GT(overlapping, 100);
  EXPECT_LT(overlapping, 1900);
}

// With tolerances the answer is a real pair's value, within max(abs, rel |D|) above the truth.
TEST_P(AgainstBruteForce, TolerancesBoundTheError) {
  SkipIfMissing();
  const std::vector<Sphere> a = Set(0), b = Set(1);
  const SphereHierarchy ha = Build(a, std::get<1>(GetParam()));
  const SphereHierarchy hb = Build(b, std::get<1>(GetParam()));
  std::mt19937_64 rng(19);
  std::int64_t exact_work = 0, loose_work = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const RigidPose pose = RandomPose(rng, 3.0);
    DistanceRequest request;
    request.abs_err = trial % 2 ? 0.05 : 0.0;
    request.rel_err = trial % 3 ? 0.1 : 0.0;
    absl::StatusOr<DistanceResult> loose = SeparationDistance(ha, {}, hb, pose, request);
    absl::StatusOr<DistanceResult> exact = SeparationDistance(ha, {}, hb, pose);
    ASSERT_TRUE(loose.ok() && exact.ok());
    const double allowed = std::max(request.abs_err, request.rel_err * std::abs(loose->distance));
    EXPECT_GE(loose->distance, exact->distance - 1e-12);
    EXPECT_LE(loose->distance - exact->distance, allowed + 1e-12) << "trial " << trial;
    ExpectWitnesses(*loose, a, {}, b, pose);
    exact_work += exact->volume_tests;
    loose_work += loose->volume_tests;
  }
  EXPECT_LT(loose_work, exact_work);
}

// closer_than answers yes exactly when the full query's distance is below the threshold,
// for thresholds around the true distance and negative ones (overlap depth).
TEST_P(AgainstBruteForce, CloserThanAgreesWithFullQuery) {
  SkipIfMissing();
  const std::vector<Sphere> a = Set(0), b = Set(1);
  const SphereHierarchy ha = Build(a, std::get<1>(GetParam()));
  const SphereHierarchy hb = Build(b, std::get<1>(GetParam()));
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> offset(-0.2, 0.2);
  for (int trial = 0; trial < 1000; ++trial) {
    const RigidPose pose = RandomPose(rng, 3.0);
    absl::StatusOr<DistanceResult> full = SeparationDistance(ha, {}, hb, pose);
    ASSERT_TRUE(full.ok());
    DistanceRequest request;
    request.closer_than = full->distance + (trial % 5 == 0 ? 0.0 : offset(rng));
    absl::StatusOr<DistanceResult> test = SeparationDistance(ha, {}, hb, pose, request);
    absl::StatusOr<DistanceResult> slow = BruteForceSeparationDistance(a, {}, b, pose, request);
    ASSERT_TRUE(test.ok() && slow.ok());
    const bool expected = full->distance < request.closer_than;
    ASSERT_EQ(test->closer, expected) << "trial " << trial;
    ASSERT_EQ(slow->closer, expected) << "trial " << trial;
    if (expected) {
      EXPECT_LT(test->distance, request.closer_than);
      ExpectWitnesses(*test, a, {}, b, pose);
    } else {
      EXPECT_EQ(test->distance, request.closer_than);
      EXPECT_EQ(test->sphere_a, -1);
    }
  }
}

// max_distance gives the full query's answer when it is below the limit and "none" (+infinity,
// no pair) otherwise; the hierarchy and the brute force agree, and pruning saves work.
TEST_P(AgainstBruteForce, MaxDistanceKeepsOnlyAnswersBelowIt) {
  SkipIfMissing();
  const std::vector<Sphere> a = Set(0), b = Set(1);
  const SphereHierarchy ha = Build(a, std::get<1>(GetParam()));
  const SphereHierarchy hb = Build(b, std::get<1>(GetParam()));
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> offset(-0.3, 0.3);
  int below = 0;
  std::int64_t full_work = 0, limited_work = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const RigidPose pose = RandomPose(rng, 3.0);
    absl::StatusOr<DistanceResult> full = SeparationDistance(ha, {}, hb, pose);
    ASSERT_TRUE(full.ok());
    DistanceRequest request;
    request.max_distance = full->distance + (trial % 7 == 0 ? 0.0 : offset(rng));
    absl::StatusOr<DistanceResult> fast = SeparationDistance(ha, {}, hb, pose, request);
    absl::StatusOr<DistanceResult> slow = BruteForceSeparationDistance(a, {}, b, pose, request);
    ASSERT_TRUE(fast.ok() && slow.ok());
    full_work += full->volume_tests;
    limited_work += fast->volume_tests;
    if (full->distance < request.max_distance) {
      ++below;
      ASSERT_NEAR(fast->distance, full->distance, 1e-9) << "trial " << trial;
      ASSERT_NEAR(slow->distance, full->distance, 1e-9) << "trial " << trial;
      ExpectWitnesses(*fast, a, {}, b, pose);
    } else {
      ASSERT_EQ(fast->distance, std::numeric_limits<double>::infinity()) << "trial " << trial;
      ASSERT_EQ(slow->distance, std::numeric_limits<double>::infinity()) << "trial " << trial;
      EXPECT_EQ(fast->sphere_a, -1);
      EXPECT_EQ(slow->sphere_a, -1);
    }
  }
  EXPECT_GT(below, 200);
  EXPECT_LT(below, 800);
  EXPECT_LT(limited_work, full_work);
}

INSTANTIATE_TEST_SUITE_P(
    Sets, AgainstBruteForce,
    ::testing::Combine(::testing::Values("random", "eight.off", "knot1.off", "fandisk.off"),
                       ::testing::Values(HierarchyVolume::kRss, HierarchyVolume::kSphere)),
    [](const ::testing::TestParamInfo<Case>& param) {
      std::string name = std::get<0>(param.param);
      name = name.substr(0, name.find('.'));
      return name + "_" + HierarchyVolumeName(std::get<1>(param.param));
    });

TEST(SeparationDistance, MixedVolumesAndBatchAgree) {
  const std::vector<Sphere> a = RandomSpheres(200, 31), b = RandomSpheres(150, 32);
  const SphereHierarchy rss = Build(a, HierarchyVolume::kRss);
  const SphereHierarchy spheres = Build(b, HierarchyVolume::kSphere);
  std::mt19937_64 rng(5);
  std::vector<RigidPose> poses;
  for (int i = 0; i < 300; ++i) poses.push_back(RandomPose(rng, 2.0));
  absl::StatusOr<std::vector<DistanceResult>> batch = SeparationDistances(rss, spheres, poses);
  ASSERT_TRUE(batch.ok());
  ASSERT_EQ(batch->size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    absl::StatusOr<DistanceResult> slow = BruteForceSeparationDistance(a, {}, b, poses[i]);
    ASSERT_TRUE(slow.ok());
    EXPECT_NEAR((*batch)[i].distance, slow->distance, 1e-9) << i;
  }
}

TEST(SeparationDistance, SingleSpheres) {
  const SphereHierarchy a = Build({{Vector3(0, 0, 0), 1.0}}, HierarchyVolume::kRss);
  const SphereHierarchy b = Build({{Vector3(0, 0, 0), 0.5}}, HierarchyVolume::kSphere);
  const RigidPose pose{Eigen::Quaterniond::Identity(), Vector3(3, 0, 0)};
  absl::StatusOr<DistanceResult> r = SeparationDistance(a, {}, b, pose);
  ASSERT_TRUE(r.ok());
  EXPECT_DOUBLE_EQ(r->distance, 1.5);
  EXPECT_TRUE(r->point_a.isApprox(Vector3(1, 0, 0)));
  EXPECT_TRUE(r->point_b.isApprox(Vector3(2.5, 0, 0)));
  // Concentric: the deepest overlap is -(1 + 0.5).
  r = SeparationDistance(a, {}, b, {});
  ASSERT_TRUE(r.ok());
  EXPECT_DOUBLE_EQ(r->distance, -1.5);
}

TEST(SeparationDistance, RefusesBadPosesAndTolerances) {
  const SphereHierarchy a = Build(RandomSpheres(20, 1), HierarchyVolume::kRss);
  RigidPose nan_pose;
  nan_pose.translation.x() = std::nan("");
  EXPECT_FALSE(SeparationDistance(a, {}, a, nan_pose).ok());
  RigidPose long_quaternion{Eigen::Quaterniond(2, 0, 0, 0), Vector3::Zero()};
  absl::StatusOr<DistanceResult> r = SeparationDistance(a, {}, a, long_quaternion);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("norm"), std::string::npos) << r.status();
  DistanceRequest negative;
  negative.abs_err = -1;
  EXPECT_FALSE(SeparationDistance(a, {}, a, {}, negative).ok());
  DistanceRequest nan_threshold;
  nan_threshold.closer_than = std::nan("");
  EXPECT_FALSE(SeparationDistance(a, {}, a, {}, nan_threshold).ok());
  DistanceRequest nan_limit;
  nan_limit.max_distance = std::nan("");
  absl::StatusOr<DistanceResult> refused = SeparationDistance(a, {}, a, {}, nan_limit);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("max_distance"), std::string::npos);
  absl::StatusOr<std::vector<DistanceResult>> batch =
      SeparationDistances(a, a, {RigidPose{}, nan_pose});
  ASSERT_FALSE(batch.ok());
  EXPECT_NE(batch.status().message().find("pose 1"), std::string::npos) << batch.status();
}

}  // namespace
}  // namespace inscribe

namespace inscribe {
namespace {

// PairSeparationDistances, the batch the service's Distance and DistanceStream run: every
// pair's answer is SeparationDistance's for that pair, bit for bit, and the minimum over all
// sphere pairs (brute force); below and above the 64-pair chunk that goes parallel.
TEST(PairSeparationDistances, EveryPairMatchesBruteForce) {
  const std::vector<std::vector<Sphere>> sets = {testing::RandomSpheres(120, 11),
                                                 testing::RandomSpheres(80, 12),
                                                 testing::RandomSpheres(30, 13)};
  std::vector<SphereHierarchy> hierarchies;
  for (const auto& s : sets) hierarchies.push_back(Build(s, HierarchyVolume::kRss));
  for (const auto& s : sets) hierarchies.push_back(Build(s, HierarchyVolume::kSphere));
  std::mt19937_64 rng(7);
  for (const std::size_t n : {std::size_t{5}, std::size_t{300}}) {
    std::vector<PosedPair> pairs;
    std::vector<std::pair<std::size_t, std::size_t>> which;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t a = rng() % hierarchies.size(), b = rng() % hierarchies.size();
      pairs.push_back(PosedPair{&hierarchies[a], &hierarchies[b], testing::RandomPose(rng, 3.0),
                                testing::RandomPose(rng, 3.0)});
      which.emplace_back(a % sets.size(), b % sets.size());
    }
    absl::StatusOr<std::vector<DistanceResult>> batch = PairSeparationDistances(pairs);
    ASSERT_TRUE(batch.ok()) << batch.status();
    ASSERT_EQ(batch->size(), n);
    for (std::size_t i = 0; i < n; ++i) {
      const PosedPair& p = pairs[i];
      absl::StatusOr<DistanceResult> one = SeparationDistance(*p.a, p.pose_a, *p.b, p.pose_b);
      ASSERT_TRUE(one.ok());
      EXPECT_EQ((*batch)[i].distance, one->distance) << i;
      EXPECT_EQ((*batch)[i].point_a, one->point_a) << i;
      EXPECT_EQ((*batch)[i].point_b, one->point_b) << i;
      absl::StatusOr<DistanceResult> brute = BruteForceSeparationDistance(
          sets[which[i].first], p.pose_a, sets[which[i].second], p.pose_b);
      ASSERT_TRUE(brute.ok());
      EXPECT_NEAR((*batch)[i].distance, brute->distance, 1e-12) << i;
      ExpectWitnesses((*batch)[i], sets[which[i].first], p.pose_a, sets[which[i].second], p.pose_b);
    }
  }
}

TEST(PairSeparationDistances, RefusesBadPairsAndStopsWhenCancelled) {
  const SphereHierarchy h = Build(testing::RandomSpheres(20, 3), HierarchyVolume::kSphere);
  std::vector<PosedPair> pairs(100, PosedPair{&h, &h, RigidPose{}, RigidPose{}});
  EXPECT_TRUE(PairSeparationDistances({}).ok());
  pairs[70].b = nullptr;
  absl::StatusOr<std::vector<DistanceResult>> missing = PairSeparationDistances(pairs);
  EXPECT_EQ(missing.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(missing.status().message()).find("pairs[70]"), std::string::npos);
  pairs[70].b = &h;
  pairs[3].pose_b.translation.x() = std::nan("");
  absl::StatusOr<std::vector<DistanceResult>> nan = PairSeparationDistances(pairs);
  EXPECT_EQ(nan.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(std::string(nan.status().message()).find("pairs[3]"), std::string::npos);
  pairs[3].pose_b = RigidPose{};
  DistanceRequest bad;
  bad.abs_err = -1.0;
  EXPECT_EQ(PairSeparationDistances(pairs, bad).status().code(),
            absl::StatusCode::kInvalidArgument);
  const std::atomic<bool> cancel{true};
  EXPECT_EQ(PairSeparationDistances(pairs, {}, &cancel).status().code(),
            absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace inscribe

namespace inscribe {
namespace {

// Queries b (posed by each pose) against a with both hierarchies and checks the exact answer:
// the same double as the brute force, bit for bit, since every pair the float filters pass is
// evaluated by the brute force's expression.
void ExpectExact(const std::vector<Sphere>& a, const std::vector<Sphere>& b,
                 const std::vector<RigidPose>& poses, const std::string& what) {
  for (HierarchyVolume volume : {HierarchyVolume::kRss, HierarchyVolume::kSphere}) {
    const SphereHierarchy ha = Build(a, volume), hb = Build(b, volume);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      absl::StatusOr<DistanceResult> fast = SeparationDistance(ha, {}, hb, poses[i]);
      absl::StatusOr<DistanceResult> slow = BruteForceSeparationDistance(a, {}, b, poses[i]);
      ASSERT_TRUE(fast.ok() && slow.ok()) << what;
      EXPECT_EQ(fast->distance, slow->distance)
          << what << " pose " << i << " " << HierarchyVolumeName(volume);
    }
  }
}

std::vector<RigidPose> RandomPoses(std::mt19937_64& rng, int n, double spread) {
  std::vector<RigidPose> poses;
  for (int i = 0; i < n; ++i) poses.push_back(RandomPose(rng, spread));
  return poses;
}

// A set scaled by `scale` and shifted by `offset`: the float filters' margins grow with the
// magnitudes; outside 2^-40..2^60 the double search answers.
std::vector<Sphere> Scaled(std::vector<Sphere> spheres, double scale, const Vector3& offset) {
  for (Sphere& s : spheres) {
    s.center = scale * s.center + offset;
    s.radius *= scale;
  }
  return spheres;
}

TEST(SeparationDistanceFloatFilter, ExactAcrossScalesAndOffsets) {
  const std::vector<Sphere> a = RandomSpheres(300, 41), b = RandomSpheres(200, 42);
  std::mt19937_64 rng(43);
  for (const double scale : {1e-14, 1e-9, 1e-3, 1.0, 1e3, 1e9, 1e15, 1e19, 1e25}) {
    for (const double offset : {0.0, 1e3, 1e7}) {
      const Vector3 shift = Vector3(offset, -offset, 0.5 * offset) * scale;
      const std::vector<Sphere> sa = Scaled(a, scale, shift), sb = Scaled(b, scale, shift);
      std::vector<RigidPose> poses = RandomPoses(rng, 20, 2.0);
      for (RigidPose& pose : poses) pose.translation *= scale;
      ExpectExact(sa, sb, poses,
                  "scale " + std::to_string(scale) + " offset " + std::to_string(offset));
    }
  }
}

TEST(SeparationDistanceFloatFilter, ExactOnDegenerateSets) {
  std::mt19937_64 rng(47);
  std::vector<Sphere> identical(200, Sphere{Vector3(0.3, 0.2, 0.1), 0.25});
  std::vector<Sphere> collinear, huge_and_tiny, near_ties;
  for (int i = 0; i < 300; ++i) {
    collinear.push_back({Vector3(0.01 * i, 0.0, 0.0), 0.004 + 0.001 * (i % 3)});
    huge_and_tiny.push_back(
        {Vector3(0.001 * i, std::sin(i), std::cos(i)), i % 10 == 0 ? 50.0 : 1e-12 * (1 + i)});
    // Centres on a sphere of radius 1 with equal radii: many pairs tie within rounding.
    const double t = 0.1 * i, p = 0.037 * i;
    near_ties.push_back(
        {Vector3(std::cos(t) * std::sin(p), std::sin(t) * std::sin(p), std::cos(p)), 0.05});
  }
  const std::vector<Sphere> one = {{Vector3(1, 2, 3), 0.5}};
  const std::vector<std::pair<std::string, std::vector<Sphere>>> sets = {
      {"one", one},
      {"identical", identical},
      {"collinear", collinear},
      {"huge and tiny radii", huge_and_tiny},
      {"near ties", near_ties},
      {"random", RandomSpheres(150, 48)}};
  for (const auto& [name_a, a] : sets) {
    for (const auto& [name_b, b] : sets) {
      std::vector<RigidPose> poses = RandomPoses(rng, 10, 1.5);
      poses.push_back(RigidPose{});
      ExpectExact(a, b, poses, name_a + " vs " + name_b);
    }
  }
  // A quaternion off unit by as much as CheckPose allows: the rotation matrix then stretches
  // distances, and the node bounds' margin must cover it.
  std::vector<RigidPose> stretched = RandomPoses(rng, 50, 1.5);
  for (std::size_t i = 0; i < stretched.size(); ++i) {
    stretched[i].rotation.coeffs() *= 1.0 + (i % 2 ? 9e-7 : -9e-7);
  }
  ExpectExact(RandomSpheres(200, 49), near_ties, stretched, "quaternion off unit");
}

// Sets of every size from 1 to 70 spheres against sets of 1 to 1,500: the compared ranges
// then have every length modulo the SIMD widths (four and eight lanes), the row masks every
// fill, and the steps split one node or both (sizes close or far apart). Both sets posed,
// poses from overlapping to apart, magnitudes from near 2^-40 to near 2^60 (where the float
// search still runs), rotations off unit by as much as CheckPose allows. Exact every time.
void ExpectExactForEverySetSizeMagnitudeAndPose() {
  std::mt19937_64 rng(59);
  std::uniform_int_distribution<int> small(1, 70);
  const std::vector<Sphere> big = testing::RandomBalls(1500, 1.0, 0.001, 0.05, 60);
  const std::vector<Sphere> medium = RandomSpheres(300, 61);
  int checked = 0;
  for (const double scale : {0x1p-39, 1e-6, 1.0, 1e6, 0x1p57}) {
    for (int trial = 0; trial < 12; ++trial) {
      std::vector<Sphere> a = testing::RandomBalls(small(rng), 0.5, 0.001, 0.1, 100 + trial);
      const std::vector<Sphere>& b =
          trial % 3 == 0
              ? big
              : (trial % 3 == 1 ? medium
                                : testing::RandomBalls(small(rng), 0.5, 0.001, 0.1, 200 + trial));
      const std::vector<Sphere> sa = Scaled(a, scale, Vector3::Zero()),
                                sb = Scaled(b, scale, Vector3::Zero());
      for (HierarchyVolume volume : {HierarchyVolume::kRss, HierarchyVolume::kSphere}) {
        const SphereHierarchy ha = Build(sa, volume), hb = Build(sb, volume);
        for (int p = 0; p < 6; ++p) {
          RigidPose pose_a = RandomPose(rng, 0.2 * p), pose_b = RandomPose(rng, 0.2 * p);
          pose_a.translation *= scale;
          pose_b.translation *= scale;
          if (p % 2 == 1) pose_b.rotation.coeffs() *= 1.0 + (p % 4 == 1 ? 9e-7 : -9e-7);
          // Each side in turn as a (the search moves b's spheres).
          for (const bool swap : {false, true}) {
            const SphereHierarchy& first = swap ? hb : ha;
            const SphereHierarchy& second = swap ? ha : hb;
            absl::StatusOr<DistanceResult> fast = SeparationDistance(first, pose_a, second, pose_b);
            absl::StatusOr<DistanceResult> slow =
                BruteForceSeparationDistance(swap ? sb : sa, pose_a, swap ? sa : sb, pose_b);
            ASSERT_TRUE(fast.ok() && slow.ok());
            EXPECT_EQ(fast->distance, slow->distance)
                << "scale " << scale << " trial " << trial << " pose " << p << " swap " << swap
                << " " << HierarchyVolumeName(volume);
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_EQ(checked, 5 * 12 * 2 * 6 * 2);
}

TEST(SeparationDistanceFloatFilter, ExactForEverySetSizeMagnitudeAndPose) {
  ExpectExactForEverySetSizeMagnitudeAndPose();
}

// The same with the SSE2 sphere-pair filter (the AVX2 one runs by default where the CPU has it).
TEST(SeparationDistanceFloatFilter, ExactWithTheSse2Filter) {
  const bool avx2 = internal::use_avx2_filter;
  internal::use_avx2_filter = false;
  ExpectExactForEverySetSizeMagnitudeAndPose();
  for (const char* name : {"eight.off", "knot1.off"}) {
    if (testing::TestMeshPath(name).empty()) continue;
    std::mt19937_64 rng(67);
    const std::vector<Sphere>& spheres = RealSphereSet(name);
    ExpectExact(spheres, spheres, RandomPoses(rng, 50, 0.3), std::string(name) + " touching");
    ExpectExact(spheres, spheres, RandomPoses(rng, 50, 1.0), std::string(name) + " near");
  }
  internal::use_avx2_filter = avx2;
}

// Real medial spheres in touching and near poses, where the answer is decided among many
// pairs within float rounding of each other.
TEST(SeparationDistanceFloatFilter, ExactOnRealSetsInContact) {
  for (const char* name : {"eight.off", "knot1.off", "fandisk.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const std::vector<Sphere>& spheres = RealSphereSet(name);
    ASSERT_FALSE(spheres.empty());
    std::mt19937_64 rng(53);
    ExpectExact(spheres, spheres, RandomPoses(rng, 100, 0.3), std::string(name) + " touching");
    ExpectExact(spheres, spheres, RandomPoses(rng, 100, 1.0), std::string(name) + " near");
  }
}

}  // namespace
}  // namespace inscribe
