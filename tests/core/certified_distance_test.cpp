// Certified distance intervals (certified_distance.h) where the exact distance is known to the
// last bit: objects that are single balls (internal set = cover = the solid, delta 0), whose
// exact distance is computed in long double (64-bit mantissa, exponents to 1e4932) from the
// very doubles the call receives. The interval is then as tight as its margins allow, so these
// poses test the margins themselves: touching balls at every scale, far from the origin,
// rotated by quaternions a little off unit length, and coordinates where squares underflow or
// overflow. Also: the closer-than rule at its boundaries, and bad input.
#include "inscribe/distance/certified_distance.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "support/sphere_sets.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;
using LongVector = Eigen::Matrix<long double, 3, 1>;

SphereHierarchy Build(const std::vector<Sphere>& spheres,
                      HierarchyVolume volume = HierarchyVolume::kSphere) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, volume);
  EXPECT_TRUE(h.ok()) << h.status();
  return *std::move(h);
}

// A solid that is exactly one ball: its own internal set and cover, delta 0.
struct Ball {
  explicit Ball(const Sphere& s) : sphere(s), hierarchy(Build({s})) {}
  Sphere sphere;
  SphereHierarchy hierarchy;
  CertifiedObject object() const { return {&hierarchy, &hierarchy, 0.0}; }
};

// The point under the rotation of the unit quaternion pose.rotation / |pose.rotation|, in long
// double.
LongVector Posed(const RigidPose& pose, const Vector3& point) {
  Eigen::Quaternion<long double> q(pose.rotation.w(), pose.rotation.x(), pose.rotation.y(),
                                   pose.rotation.z());
  q.normalize();
  return q.toRotationMatrix() * point.cast<long double>() + pose.translation.cast<long double>();
}

// The exact distance between the two posed balls (0 when they touch or overlap), to about 1e-19
// of the coordinates.
long double ExactDistance(const Sphere& a, const RigidPose& pose_a, const Sphere& b,
                          const RigidPose& pose_b) {
  const long double gap = (Posed(pose_a, a.center) - Posed(pose_b, b.center)).norm() -
                          static_cast<long double>(a.radius) - static_cast<long double>(b.radius);
  return gap > 0.0L ? gap : 0.0L;
}

// A random rotation whose quaternion is off unit length by up to 5e-4 (NormalizedPose's
// business), and a translation.
RigidPose RoughPose(std::mt19937_64& rng, const Vector3& translation) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> off(-5e-4, 5e-4);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  q.coeffs() *= (1.0 + off(rng)) / q.norm();
  return RigidPose{q, translation};
}

// n poses of two balls of about `scale` whose centres are placed, in the world, exactly at
// radius-sum + gap apart (up to the rounding of the placement), the pair `offset` from the
// origin; gaps of 0, +-1e-15 .. +-1e-9 of the scale and random ones. Every interval must hold
// the long-double exact distance; without the margins about half of the touching poses fail.
void ExpectTouchingBallsHeld(double scale, double offset, int n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  const double gaps[] = {0.0, 1e-15, -1e-15, 1e-13, -1e-13, 1e-11, -1e-11, 1e-9, -1e-9};
  int held = 0, touching = 0;
  for (int i = 0; i < n; ++i) {
    const Ball a(
        Sphere{scale * Vector3(normal(rng), normal(rng), normal(rng)), scale * (0.1 + unit(rng))});
    const Ball b(
        Sphere{scale * Vector3(normal(rng), normal(rng), normal(rng)), scale * (0.1 + unit(rng))});
    const Vector3 origin = offset * Vector3(normal(rng), normal(rng), normal(rng)).normalized();
    const RigidPose pose_a = RoughPose(rng, origin);
    RigidPose pose_b = RoughPose(rng, Vector3::Zero());
    // Centre of b at the chosen distance from the centre of a, in the world.
    const double gap = i % 10 < 9 ? gaps[i % 9] * scale : scale * (unit(rng) - 0.5);
    const Vector3 u = Vector3(normal(rng), normal(rng), normal(rng)).normalized();
    const Vector3 centre_a = pose_a.rotation.normalized() * a.sphere.center + pose_a.translation;
    const Vector3 target = centre_a + u * (a.sphere.radius + b.sphere.radius + gap);
    pose_b.translation = target - pose_b.rotation.normalized() * b.sphere.center;

    const CertifiedObject oa = a.object(), ob = b.object();
    absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
        CertifiedDistances({{&oa, &ob, pose_a, pose_b}});
    ASSERT_TRUE(r.ok()) << r.status();
    const CertifiedDistanceResult& interval = (*r)[0];
    const long double exact = ExactDistance(a.sphere, pose_a, b.sphere, pose_b);
    touching += exact == 0.0L;
    const bool ok = static_cast<long double>(interval.lower) <= exact &&
                    exact <= static_cast<long double>(interval.upper);
    held += ok;
    if (!ok) {
      ADD_FAILURE() << "scale " << scale << ", offset " << offset << ", pose " << i << ": exact "
                    << static_cast<double>(exact) << " outside [" << interval.lower << ", "
                    << interval.upper << "]";
      return;
    }
    // As tight as the margins: a few 1e-12 of the coordinates (and the floor).
    EXPECT_LE(interval.upper - interval.lower,
              1e-10 * (offset + 10.0 * scale) + 4.0 * kCertifiedDistanceFloor);
  }
  EXPECT_EQ(held, n);
  EXPECT_GT(touching, n / 10);  // the overlapping gaps really overlap
}

TEST(CertifiedDistances, HoldsTheExactDistanceOfTouchingBallsAtEveryScale) {
  for (const double scale : {1e-6, 1.0, 1e3, 1e9}) {
    ExpectTouchingBallsHeld(scale, 0.0, 3000, 1);
    ExpectTouchingBallsHeld(scale, 1e4 * scale, 3000, 2);  // far from the world origin
  }
}

// Lengths below about 1e-154 have squares below the smallest normal double: their square roots
// carry absolute errors near 1e-162, far above a margin relative to such coordinates.
TEST(CertifiedDistances, HoldsTheExactDistanceWhereSquaresUnderflow) {
  ExpectTouchingBallsHeld(1e-160, 0.0, 3000, 3);
  ExpectTouchingBallsHeld(1e-170, 1e-165, 3000, 4);
}

// Coordinates whose squares overflow are refused, rather than answered with an infinite lower
// bound for balls a finite distance apart.
TEST(CertifiedDistances, RefusesCoordinatesWhoseSquaresWouldOverflow) {
  const Ball unit(Sphere{Vector3::Zero(), 1.0});
  const CertifiedObject o = unit.object();
  RigidPose left, right;
  left.translation = Vector3(-1e154, 0.0, 0.0);
  right.translation = Vector3(1e154, 0.0, 0.0);
  absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
      CertifiedDistances({{&o, &o, RigidPose(), RigidPose()}, {&o, &o, left, right}});
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("pairs[1]"));
  // Far, but within range: answered, and sound.
  left.translation = Vector3(-1e90, 0.0, 0.0);
  right.translation = Vector3(1e90, 0.0, 0.0);
  r = CertifiedDistances({{&o, &o, left, right}});
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_LE((*r)[0].lower, 2e90 - 2.0);
  EXPECT_GE((*r)[0].upper, 2e90 - 2.0);
  EXPECT_TRUE(std::isfinite((*r)[0].lower));
}

// Many spheres per object (both hierarchy kinds), at tiny, unit and huge scales: the interval
// holds the long-double minimum over all sphere pairs (the solids here are the unions).
TEST(CertifiedDistances, HoldsTheExactDistanceOfSphereUnionsAtExtremeScales) {
  const std::vector<Sphere> base_a = testing::RandomSpheres(120, 7);
  const std::vector<Sphere> base_b = testing::RandomSpheres(90, 8);
  std::mt19937_64 rng(9);
  for (const double scale : {1e-160, 1.0, 1e80}) {
    std::vector<Sphere> a = base_a, b = base_b;
    for (Sphere& s : a) s = Sphere{s.center * scale, s.radius * scale};
    for (Sphere& s : b) s = Sphere{s.center * scale, s.radius * scale};
    const SphereHierarchy rss_a = Build(a, HierarchyVolume::kRss);
    const SphereHierarchy sphere_b = Build(b, HierarchyVolume::kSphere);
    const CertifiedObject oa{&rss_a, &rss_a, 0.0}, ob{&sphere_b, &sphere_b, 0.0};
    for (int i = 0; i < 300; ++i) {
      const RigidPose pose_a = testing::RandomPose(rng, 0.5 * scale);
      const RigidPose pose_b = testing::RandomPose(rng, 1.5 * scale);
      absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
          CertifiedDistances({{&oa, &ob, pose_a, pose_b}});
      ASSERT_TRUE(r.ok()) << r.status();
      long double exact = std::numeric_limits<long double>::infinity();
      for (const Sphere& sa : a) {
        for (const Sphere& sb : b) {
          exact = std::min(exact, (Posed(pose_a, sa.center) - Posed(pose_b, sb.center)).norm() -
                                      static_cast<long double>(sa.radius) -
                                      static_cast<long double>(sb.radius));
        }
      }
      exact = std::max(exact, 0.0L);
      ASSERT_LE(static_cast<long double>((*r)[0].lower), exact)
          << "scale " << scale << " pose " << i;
      ASSERT_GE(static_cast<long double>((*r)[0].upper), exact)
          << "scale " << scale << " pose " << i;
    }
  }
}

// upper uses the covers too: covers 1 apart with deltas 0.25 each give upper 1.5 even when the
// internal sets are far apart, and overlapping covers give lower 0 and upper the deltas.
TEST(CertifiedDistances, UpperIsAtMostTheCoversDistancePlusTheDeltas) {
  const SphereHierarchy inner = Build({Sphere{Vector3::Zero(), 0.1}});
  const SphereHierarchy outer = Build({Sphere{Vector3::Zero(), 1.0}});
  const CertifiedObject o{&inner, &outer, 0.25};
  RigidPose apart;
  apart.translation = Vector3(3.0, 0.0, 0.0);
  RigidPose overlapping;
  overlapping.translation = Vector3(1.5, 0.0, 0.0);
  absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
      CertifiedDistances({{&o, &o, RigidPose(), apart}, {&o, &o, RigidPose(), overlapping}}, 1.2);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_NEAR((*r)[0].lower, 1.0, 1e-9);
  EXPECT_NEAR((*r)[0].upper, 1.5, 1e-9);  // internal sets: 2.8
  EXPECT_EQ((*r)[0].closer, CloserAnswer::kUndecided);
  EXPECT_EQ((*r)[1].lower, 0.0);
  EXPECT_NEAR((*r)[1].upper, 0.5, 1e-9);  // internal sets: 1.3
  EXPECT_EQ((*r)[1].closer, CloserAnswer::kYes);
  EXPECT_NEAR((*r)[1].internal.distance, 1.3, 1e-9);
  EXPECT_NEAR((*r)[1].cover.distance, -0.5, 1e-9);
}

// The cores: a cover sphere of radius r whose protrusion bound is p gives the ball of radius
// r - p at its centre (when positive), in place of the internal set; without protrusions, or
// with no core left, the internal set; bad protrusions are refused.
TEST(UpperBoundSpheres, AreTheCoverSpheresCoresElseTheInternalSet) {
  const std::vector<Sphere> internal = {Sphere{Vector3::Zero(), 0.1}};
  const std::vector<Sphere> cover = {Sphere{Vector3(1.0, 0.0, 0.0), 0.5},
                                     Sphere{Vector3(2.0, 0.0, 0.0), 0.5},
                                     Sphere{Vector3(3.0, 0.0, 0.0), 0.5}};
  absl::StatusOr<std::vector<Sphere>> upper = UpperBoundSpheres(internal, cover, {0.2, 0.5, -0.1});
  ASSERT_TRUE(upper.ok()) << upper.status();
  ASSERT_EQ(upper->size(), 2u);
  EXPECT_EQ((*upper)[0].center, cover[0].center);
  EXPECT_DOUBLE_EQ((*upper)[0].radius, 0.3);
  EXPECT_EQ((*upper)[1].center, cover[2].center);  // the second reaches its whole radius out
  EXPECT_DOUBLE_EQ((*upper)[1].radius, 0.6);       // deep inside: a core beyond the sphere
  // No protrusions, or no core left: the internal set.
  for (const std::vector<double>& none : {std::vector<double>{}, std::vector<double>{1, 1, 1}}) {
    upper = UpperBoundSpheres(internal, cover, none);
    ASSERT_TRUE(upper.ok());
    ASSERT_EQ(upper->size(), 1u);
    EXPECT_EQ((*upper)[0].radius, 0.1);
  }
  upper = UpperBoundSpheres(internal, cover, {0.1, 0.1});
  EXPECT_EQ(upper.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(upper.status().message()), ::testing::HasSubstr("2 values for 3"));
  upper = UpperBoundSpheres(internal, cover, {0.1, std::nan(""), 0.1});
  EXPECT_EQ(upper.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(upper.status().message()), ::testing::HasSubstr("value 1"));
}

TEST(DecideCloser, AnswersOnlyWhatTheIntervalProves) {
  EXPECT_EQ(DecideCloser(0.0, 0.9, 1.0), CloserAnswer::kYes);
  EXPECT_EQ(DecideCloser(0.0, 1.0, 1.0), CloserAnswer::kUndecided);  // exact may equal d
  EXPECT_EQ(DecideCloser(1.0, 2.0, 1.0), CloserAnswer::kNo);         // exact >= d
  EXPECT_EQ(DecideCloser(0.5, 2.0, 1.0), CloserAnswer::kUndecided);
  EXPECT_EQ(DecideCloser(0.0, 0.0, 0.0), CloserAnswer::kNo);  // no distance is below 0
  EXPECT_STREQ(CloserAnswerName(CloserAnswer::kYes), "yes");
  EXPECT_STREQ(CloserAnswerName(CloserAnswer::kNo), "no");
  EXPECT_STREQ(CloserAnswerName(CloserAnswer::kUndecided), "undecided");
}

TEST(CertifiedDistances, BadInputIsRefusedNamingThePair) {
  const Ball ball(Sphere{Vector3::Zero(), 1.0});
  const CertifiedObject good = ball.object();
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  const CertifiedObject no_internal{nullptr, &ball.hierarchy, 0.0};
  const CertifiedObject no_cover{&ball.hierarchy, nullptr, 0.0};
  const CertifiedObject negative{&ball.hierarchy, &ball.hierarchy, -1e-9};
  const CertifiedObject not_a_number{&ball.hierarchy, &ball.hierarchy, nan};
  const CertifiedObject infinite{&ball.hierarchy, &ball.hierarchy, inf};
  RigidPose far;
  far.translation = Vector3(5.0, 0.0, 0.0);
  RigidPose nan_translation = far, zero_rotation = far, long_rotation = far, inf_translation = far;
  nan_translation.translation.y() = nan;
  inf_translation.translation.z() = inf;
  zero_rotation.rotation.coeffs().setZero();
  long_rotation.rotation.coeffs() *= 2.0;
  struct Case {
    CertifiedPair pair;
    const char* says;
  };
  const Case cases[] = {
      {{nullptr, &good, RigidPose(), far}, "missing"},
      {{&good, nullptr, RigidPose(), far}, "missing"},
      {{&no_internal, &good, RigidPose(), far}, "internal"},
      {{&good, &no_cover, RigidPose(), far}, "cover"},
      {{&negative, &good, RigidPose(), far}, "delta"},
      {{&good, &not_a_number, RigidPose(), far}, "delta"},
      {{&infinite, &good, RigidPose(), far}, "delta"},
      {{&good, &good, RigidPose(), nan_translation}, ""},
      {{&good, &good, inf_translation, far}, ""},
      {{&good, &good, zero_rotation, far}, ""},
      {{&good, &good, RigidPose(), long_rotation}, ""},
  };
  for (const Case& c : cases) {
    absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
        CertifiedDistances({{&good, &good, RigidPose(), far}, c.pair});
    EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument) << c.says;
    EXPECT_THAT(r.status().message(), HasSubstr("pairs[1]"));
    EXPECT_THAT(r.status().message(), HasSubstr(c.says));
  }
  absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
      CertifiedDistances({{&good, &good, RigidPose(), far}}, nan);
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("closer_than"));
  EXPECT_TRUE(CheckCertifiedObject(good).ok());
  EXPECT_FALSE(CheckCertifiedObject(negative).ok());
  // No pairs: no answers.
  r = CertifiedDistances({});
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->empty());
}

TEST(CertifiedDistances, StopsWhenCancelled) {
  const Ball ball(Sphere{Vector3::Zero(), 1.0});
  const CertifiedObject o = ball.object();
  RigidPose far;
  far.translation = Vector3(5.0, 0.0, 0.0);
  const std::vector<CertifiedPair> pairs(500, CertifiedPair{&o, &o, RigidPose(), far});
  std::atomic<bool> cancel{true};
  EXPECT_EQ(CertifiedDistances(pairs, 1.0, &cancel).status().code(), absl::StatusCode::kCancelled);
  cancel = false;
  absl::StatusOr<std::vector<CertifiedDistanceResult>> r = CertifiedDistances(pairs, 4.0, &cancel);
  ASSERT_TRUE(r.ok()) << r.status();
  for (const CertifiedDistanceResult& one : *r) {
    EXPECT_NEAR(one.lower, 3.0, 1e-9);
    EXPECT_NEAR(one.upper, 3.0, 1e-9);
    EXPECT_EQ(one.closer, CloserAnswer::kYes);
  }
}

}  // namespace
}  // namespace inscribe
