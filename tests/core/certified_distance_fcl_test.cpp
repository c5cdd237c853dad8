// Certified distance intervals (certified_distance.h) against the exact distance between the
// solids, with FCL as the oracle (support/fcl_solid_distance.h): on thousands of random poses
// per mesh pair (far apart, near, touching, interpenetrating, one inside the other) the exact
// distance lies in [lower, upper], the closer-than answers are never wrong, and the sphere
// queries behind the interval equal brute force. Mutation checks: a cover missing a sphere, or
// a delta below the cover's real reach, gives an interval that misses the exact distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "inscribe/cover/cover_certificate.h"
#include "inscribe/cover/sphere_cover.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "support/fcl_solid_distance.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using testing::FclSolid;

// FCL's distance carries its own rounding (triangle-triangle distances and BVH transforms, a
// few ulps of the coordinates); the interval's margins are 1e-12 of the coordinates. The
// comparison allows 1e-9 of the largest bounding-box side for FCL's part: far above both
// roundings, far below what a missing sphere or a wrong delta moves an interval by (the
// mutation checks below move it by more than 1e-4 of the side). certified_distance_test.cpp
// checks the margins themselves against exact reference values, without FCL.
constexpr double kFclSlack = 1e-9;

// The mesh centred on its bounding box and scaled so that its largest side is `side`.
Mesh Fitted(Mesh mesh, double side) {
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const Vector3 centre = 0.5 * (box.min + box.max);
  const double scale = side / box.extent().maxCoeff();
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    mesh.vertices.row(i) = ((mesh.vertices.row(i).transpose() - centre) * scale).transpose();
  }
  return mesh;
}

// Test meshes by name: CGAL's demo meshes ("eight.off") and adversarial shapes.
Mesh NamedMesh(const std::string& name) {
  if (name == "plate") return testing::Box(Vector3::Zero(), Vector3(1.0, 1.0, 0.01));
  if (name == "needle") return testing::Box(Vector3::Zero(), Vector3(1.0, 0.01, 0.01));
  if (name == "cavity") {
    return testing::Concatenate(
        testing::UnitCube(),
        testing::Inverted(testing::Box(Vector3::Constant(0.3), Vector3::Constant(0.7))));
  }
  if (name == "two shells") {
    return testing::Concatenate(testing::UnitCube(),
                                testing::Box(Vector3::Constant(2.0), Vector3::Constant(2.5)));
  }
  return testing::LoadTestMesh(name);
}

bool IsDemoMesh(const std::string& name) { return name.find(".off") != std::string::npos; }

SphereHierarchy Build(const std::vector<Sphere>& spheres, HierarchyVolume volume) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, volume);
  EXPECT_TRUE(h.ok()) << h.status();
  return *std::move(h);
}

// One solid with its internal set and certified cover, and FCL's tree. Held by pointer: the
// object and the oracle point into it.
struct Model {
  std::string name;
  Solid solid;
  std::vector<Sphere> internal_spheres, cover_spheres;
  double delta = 0.0;
  SphereHierarchy internal, cover;
  CertifiedObject object = {};
  FclSolid fcl = {};
  double largest = 0.0, diagonal = 0.0;
};

// The internal set (RSS hierarchy) and the cover (sphere hierarchy) of a solid.
std::unique_ptr<Model> MakeModel(const std::string& name, Mesh mesh, std::vector<Sphere> internal,
                                 std::vector<Sphere> cover, double delta) {
  absl::StatusOr<Solid> solid = PrepareSolid(std::move(mesh));
  EXPECT_TRUE(solid.ok()) << solid.status();
  if (!solid.ok()) return nullptr;
  SphereHierarchy internal_hierarchy = Build(internal, HierarchyVolume::kRss);
  SphereHierarchy cover_hierarchy = Build(cover, HierarchyVolume::kSphere);
  auto model = std::unique_ptr<Model>(
      new Model{name, *std::move(solid), std::move(internal), std::move(cover), delta,
                std::move(internal_hierarchy), std::move(cover_hierarchy)});
  model->object = CertifiedObject{&model->internal, &model->cover, delta};
  model->fcl = testing::MakeFclSolid(model->solid);
  const BoundingBox box = ComputeBoundingBox(model->solid.mesh().vertices);
  model->largest = box.extent().maxCoeff();
  model->diagonal = box.diagonal();
  return model;
}

// The mesh fitted to `side`, the cores of a certified cover (UpperBoundSpheres) and the
// cover, with modest budgets.
std::unique_ptr<Model> GeneratedModel(const std::string& name, double side) {
  const Mesh mesh = Fitted(NamedMesh(name), side);
  absl::StatusOr<Solid> solid = PrepareSolid(mesh);
  EXPECT_TRUE(solid.ok()) << solid.status();
  if (!solid.ok()) return nullptr;
  SphereSetParameters internal;
  internal.max_spheres = 150;
  internal.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> set = GenerateSphereSet(*solid, internal);
  EXPECT_TRUE(set.ok()) << name << ": " << set.status();
  CoverParameters parameters;
  parameters.max_spheres = 150;
  parameters.growth_samples = 50'000;
  absl::StatusOr<GeneratedCover> cover = GenerateCover(*solid, parameters);
  EXPECT_TRUE(cover.ok()) << name << ": " << cover.status();
  if (!set.ok() || !cover.ok()) return nullptr;
  EXPECT_TRUE(cover->certificate.certified);
  // The cover's cores in place of the internal set, as the service takes them.
  absl::StatusOr<std::vector<Sphere>> upper =
      UpperBoundSpheres(set->set.spheres, cover->set.spheres, cover->certificate.protrusions);
  EXPECT_TRUE(upper.ok()) << upper.status();
  if (!upper.ok()) return nullptr;
  EXPECT_GT(upper->size(), cover->set.size() / 2);
  return MakeModel(name, mesh, *std::move(upper), std::move(cover->set.spheres),
                   cover->certificate.delta);
}

// An icosphere of circumradius `radius` at the origin: internal set its inscribed ball (the
// oracle's exact distance from the centre to the faces), cover its circumscribed ball grown by
// 1% (the certificate's finest cells near a vertex need that room), certified; delta from the
// certificate.
std::unique_ptr<Model> BallModel(double radius) {
  const Mesh mesh = testing::Icosphere(2, Vector3::Zero(), radius);
  absl::StatusOr<Solid> solid = PrepareSolid(mesh);
  EXPECT_TRUE(solid.ok()) << solid.status();
  if (!solid.ok()) return nullptr;
  const double inradius = solid->oracle.ClosestPoint(Vector3::Zero()).distance;
  const Sphere outer{Vector3::Zero(), radius * 1.01};
  absl::StatusOr<CoverCertificate> certificate = CertifyCover(*solid, {outer});
  EXPECT_TRUE(certificate.ok() && certificate->certified);
  if (!certificate.ok()) return nullptr;
  return MakeModel("ball", mesh, {Sphere{Vector3::Zero(), inradius * (1.0 - 1e-12)}}, {outer},
                   certificate->delta);
}

RigidPose RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  RigidPose pose;
  pose.rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng));
  pose.rotation.normalize();
  return pose;
}

Vector3 RandomDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return Vector3(normal(rng), normal(rng), normal(rng)).normalized();
}

enum class PoseKind { kFar, kNear, kContained };
const char* PoseKindName(PoseKind kind) {
  return kind == PoseKind::kFar ? "far" : kind == PoseKind::kNear ? "near" : "contained";
}

struct Posed {
  RigidPose a, b;
  PoseKind kind;
};

// Poses of b relative to a (both rotated at random, a's box centred on the origin):
//  far:       box centres 0.6 to 1.5 times the mean diagonal apart;
//  near:      along a random direction, the contact distance found by bisection on
//             fcl::collide, then moved by -3% to +5% of the larger side (a fifth of them left
//             at the last bisection steps: touching within 1e-6 of the side, or barely crossing);
//  contained: b's box centre at a random point inside a's solid (b may lie wholly inside).
std::vector<Posed> RandomPoses(const Model& a, const Model& b, int far, int near, int contained,
                               std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double reach = 0.5 * (a.diagonal + b.diagonal);
  const double side = std::max(a.largest, b.largest);
  std::vector<Posed> poses;
  for (int i = 0; i < far; ++i) {
    Posed p{RandomRotation(rng), RandomRotation(rng), PoseKind::kFar};
    p.b.translation = RandomDirection(rng) * reach * (0.6 + 0.9 * unit(rng));
    poses.push_back(p);
  }
  for (int i = 0; i < near; ++i) {
    Posed p{RandomRotation(rng), RandomRotation(rng), PoseKind::kNear};
    const Vector3 u = RandomDirection(rng);
    double lo = 0.0, hi = 1.01 * reach;  // hi: the boxes' spheres are apart
    p.b.translation = Vector3::Zero();
    if (testing::SurfacesCollide(a.fcl, p.a, b.fcl, p.b)) {
      for (int step = 0; step < 20; ++step) {
        const double mid = 0.5 * (lo + hi);
        p.b.translation = mid * u;
        (testing::SurfacesCollide(a.fcl, p.a, b.fcl, p.b) ? lo : hi) = mid;
      }
    } else {
      hi = lo;
    }
    const double draw = unit(rng);
    const double at = draw < 0.1 ? hi : draw < 0.2 ? lo : hi + side * (-0.03 + 0.08 * unit(rng));
    p.b.translation = std::max(0.0, at) * u;
    poses.push_back(p);
  }
  const BoundingBox box = ComputeBoundingBox(a.solid.mesh().vertices);
  for (int i = 0; i < contained;) {
    Vector3 point;
    for (int k = 0; k < 3; ++k) point[k] = box.min[k] + unit(rng) * (box.max[k] - box.min[k]);
    if (a.solid.oracle.Classify(point) != Side::kInside) continue;
    Posed p{RandomRotation(rng), RandomRotation(rng), PoseKind::kContained};
    p.b.translation = p.a * point;
    poses.push_back(p);
    ++i;
  }
  return poses;
}

std::vector<CertifiedPair> Pairs(const Model& a, const Model& b, const std::vector<Posed>& poses) {
  std::vector<CertifiedPair> pairs;
  for (const Posed& p : poses) pairs.push_back({&a.object, &b.object, p.a, p.b});
  return pairs;
}

struct PairCase {
  const char* a;
  const char* b;
  double b_side;  // b's largest side, a's being 1
  int far, near, contained;
};

void PrintTo(const PairCase& c, std::ostream* os) { *os << c.a << " & " << c.b; }

class AgainstFcl : public ::testing::TestWithParam<PairCase> {};

// Every pose: lower <= exact <= upper (FCL's slack aside), lower <= upper <= lower + delta_a +
// delta_b (+ margins), the closer-than answers at several d never wrong, and the interval's
// sphere queries equal the brute-force minima.
TEST_P(AgainstFcl, ExactDistanceLiesInEveryInterval) {
  const PairCase& c = GetParam();
  for (const char* name : {c.a, c.b}) {
    if (IsDemoMesh(name)) INSCRIBE_REQUIRE_MESH(name);
  }
  const std::unique_ptr<Model> a = GeneratedModel(c.a, 1.0);
  // A ball has one medial point: no internal set reaches a budget; it gets hand-made sets.
  const std::unique_ptr<Model> b =
      std::string(c.b) == "ball" ? BallModel(0.5 * c.b_side) : GeneratedModel(c.b, c.b_side);
  ASSERT_TRUE(a && b);
  const std::vector<Posed> poses = RandomPoses(*a, *b, c.far, c.near, c.contained, 22);
  const std::vector<CertifiedPair> pairs = Pairs(*a, *b, poses);
  absl::StatusOr<std::vector<CertifiedDistanceResult>> intervals = CertifiedDistances(pairs);
  ASSERT_TRUE(intervals.ok()) << intervals.status();
  ASSERT_EQ(intervals->size(), poses.size());

  const double side = std::max(a->largest, b->largest);
  const double slack = kFclSlack * side;
  const double deltas = a->delta + b->delta;
  const std::vector<double> thresholds = {0.0, 1e-3 * side, 0.01 * side, 0.05 * side, 0.2 * side};
  std::vector<std::vector<CertifiedDistanceResult>> answers;
  for (const double d : thresholds) {
    absl::StatusOr<std::vector<CertifiedDistanceResult>> r = CertifiedDistances(pairs, d);
    ASSERT_TRUE(r.ok()) << r.status();
    answers.push_back(*std::move(r));
  }

  int misses = 0, wrong = 0, surfaces = 0, contained = 0, decided = 0;
  double width = 0.0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Posed& p = poses[i];
    const CertifiedDistanceResult& r = (*intervals)[i];
    const testing::ExactSolidDistance exact = testing::SolidDistance(a->fcl, p.a, b->fcl, p.b);
    surfaces += exact.contact == testing::SolidContact::kSurfaces;
    contained += exact.contact == testing::SolidContact::kContained;
    width += r.upper - r.lower;
    const auto where = [&] {
      return ::testing::Message() << PoseKindName(p.kind) << " pose " << i << ": exact "
                                  << exact.distance << " (contact "
                                  << static_cast<int>(exact.contact) << "), interval [" << r.lower
                                  << ", " << r.upper << "], covers " << r.cover.distance
                                  << ", internal " << r.internal.distance;
    };
    ASSERT_TRUE(std::isfinite(exact.distance)) << where();
    if (!(r.lower <= exact.distance + slack && exact.distance <= r.upper + slack)) {
      if (++misses <= 5) ADD_FAILURE() << "the exact distance is outside the interval: " << where();
    }
    EXPECT_LE(0.0, r.lower) << where();
    EXPECT_LE(r.lower, r.upper) << where();
    EXPECT_LE(r.upper - r.lower, deltas + 1e-9 * side) << where();
    EXPECT_EQ(r.closer, CloserAnswer::kUndecided);

    for (std::size_t k = 0; k < thresholds.size(); ++k) {
      const CertifiedDistanceResult& q = answers[k][i];
      EXPECT_EQ(q.lower, r.lower);
      EXPECT_EQ(q.upper, r.upper);
      EXPECT_EQ(q.closer, DecideCloser(r.lower, r.upper, thresholds[k]));
      const bool right = q.closer == CloserAnswer::kUndecided ||
                         (q.closer == CloserAnswer::kYes ? exact.distance < thresholds[k] + slack
                                                         : exact.distance >= thresholds[k] - slack);
      decided += q.closer != CloserAnswer::kUndecided;
      if (!right && ++wrong <= 5) {
        ADD_FAILURE() << "closer than " << thresholds[k] << " answered "
                      << CloserAnswerName(q.closer) << ": " << where();
      }
    }

    const std::pair<const std::vector<Sphere>*, const std::vector<Sphere>*> sets[] = {
        {&a->internal_spheres, &b->internal_spheres}, {&a->cover_spheres, &b->cover_spheres}};
    const DistanceResult* queried[] = {&r.internal, &r.cover};
    for (int s = 0; s < 2; ++s) {
      absl::StatusOr<DistanceResult> brute =
          BruteForceSeparationDistance(*sets[s].first, p.a, *sets[s].second, p.b);
      ASSERT_TRUE(brute.ok()) << brute.status();
      EXPECT_NEAR(queried[s]->distance, brute->distance, 1e-12 * side) << where();
    }
  }
  EXPECT_EQ(misses, 0);
  EXPECT_EQ(wrong, 0);
  // The poses reach every case they are meant to.
  EXPECT_GT(surfaces, 0);
  if (c.contained > 0) {
    EXPECT_GT(contained + surfaces, c.contained / 2);
  }
  std::printf(
      "%s & %s: %zu poses (%d surfaces in contact, %d contained), delta %.3g%% + %.3g%%, "
      "mean width %.3g%% of the largest side, %.1f%% of closer-than tests decided\n",
      c.a, c.b, poses.size(), surfaces, contained, 100.0 * a->delta / side, 100.0 * b->delta / side,
      100.0 * width / static_cast<double>(poses.size()) / side,
      100.0 * decided / static_cast<double>(poses.size() * thresholds.size()));
}

INSTANTIATE_TEST_SUITE_P(Pairs, AgainstFcl,
                         ::testing::Values(PairCase{"eight.off", "eight.off", 1.0, 500, 1500, 0},
                                           PairCase{"cow.off", "elephant.off", 0.8, 500, 1500, 0},
                                           PairCase{"fandisk.off", "knot1.off", 1.0, 500, 1500, 0},
                                           PairCase{"bunny00.off", "cow.off", 1.0, 300, 1200, 0},
                                           PairCase{"elephant.off", "eight.off", 0.15, 200, 800,
                                                    1000},
                                           PairCase{"plate", "needle", 1.0, 500, 1500, 0},
                                           PairCase{"cavity", "ball", 0.25, 200, 800, 1000},
                                           PairCase{"two shells", "plate", 0.5, 300, 1200, 500}),
                         [](const ::testing::TestParamInfo<PairCase>& param) {
                           std::string name = std::string(param.param.a) + "_" + param.param.b;
                           std::replace_if(
                               name.begin(), name.end(), [](char ch) { return !std::isalnum(ch); },
                               '_');
                           return name;
                         });

// A small ball (with its own certified sets) put where `a`'s interval is tight, `a` at the
// identity: its exact distance and the interval with a's object replaced by `mutant`.
struct Probe {
  double exact;
  CertifiedDistanceResult sound, mutated;
};

Probe ProbeAt(const Model& a, const CertifiedObject& mutant, const Model& ball,
              const Vector3& centre) {
  RigidPose pose_b;
  pose_b.translation = centre;
  const double exact = testing::SolidDistance(a.fcl, RigidPose(), ball.fcl, pose_b).distance;
  absl::StatusOr<std::vector<CertifiedDistanceResult>> r =
      CertifiedDistances({{&a.object, &ball.object, RigidPose(), pose_b},
                          {&mutant, &ball.object, RigidPose(), pose_b}});
  EXPECT_TRUE(r.ok()) << r.status();
  return Probe{exact, (*r)[0], (*r)[1]};
}

// Mutation check (the test has teeth): with a sphere of the cover removed, a probe ball put
// just outside the boundary point that only that sphere held gets a lower bound above its
// exact distance. The point is the face centroid farthest (gap g) from the remaining spheres;
// the ball has radius g/10 and its surface sits g/10 off the face, so the exact distance is
// about g/10 while the mutated covers are at least about 0.7 g apart.
TEST(AgainstFclMutation, ACoverMissingASphereGivesALowerBoundAboveTheExactDistance) {
  INSCRIBE_REQUIRE_MESH("fandisk.off");
  const std::unique_ptr<Model> a = GeneratedModel("fandisk.off", 1.0);
  ASSERT_TRUE(a);
  const Mesh& mesh = a->solid.mesh();
  const std::vector<Sphere>& cover = a->cover_spheres;
  double best_gap = 0.0;
  std::size_t best_sphere = 0;
  Eigen::Index best_face = -1;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    Vector3 p = Vector3::Zero();
    for (int k = 0; k < 3; ++k) p += mesh.vertices.row(mesh.triangles(t, k)).transpose() / 3.0;
    int holders = 0;
    std::size_t holder = 0;
    double gap = std::numeric_limits<double>::infinity();  // to the spheres not holding p
    for (std::size_t s = 0; s < cover.size(); ++s) {
      const double d = (p - cover[s].center).norm() - cover[s].radius;
      if (d <= 0.0) {
        ++holders;
        holder = s;
      } else {
        gap = std::min(gap, d);
      }
    }
    if (holders == 1 && gap > best_gap) {
      best_gap = gap;
      best_sphere = holder;
      best_face = t;
    }
  }
  ASSERT_GE(best_face, 0) << "no face centroid is held by a single sphere";
  ASSERT_GT(best_gap, 1e-4 * a->largest);
  std::vector<Sphere> without = cover;
  without.erase(without.begin() + static_cast<std::ptrdiff_t>(best_sphere));
  const SphereHierarchy mutated_cover = Build(without, HierarchyVolume::kSphere);
  const CertifiedObject mutant{&a->internal, &mutated_cover, a->delta};

  const std::unique_ptr<Model> ball = BallModel(0.1 * best_gap);
  ASSERT_TRUE(ball);
  Vector3 p = Vector3::Zero();
  for (int k = 0; k < 3; ++k)
    p += mesh.vertices.row(mesh.triangles(best_face, k)).transpose() / 3.0;
  const Vector3 normal = a->solid.oracle.face_normals()[static_cast<std::size_t>(best_face)];
  const Probe probe = ProbeAt(*a, mutant, *ball, p + normal * (0.2 * best_gap));
  const double slack = kFclSlack * a->largest;
  EXPECT_LE(probe.sound.lower, probe.exact + slack);
  EXPECT_GE(probe.sound.upper, probe.exact - slack);
  EXPECT_GT(probe.mutated.lower, probe.exact + 0.3 * best_gap)
      << "exact " << probe.exact << ", gap " << best_gap;
}

// Mutation check: with a delta below the cover's real reach, a probe ball just beyond the
// sphere that reaches farthest out (to tau outside the solid) gets an upper bound below its
// exact distance: the covers nearly touch (about tau/20 apart), the ball is about 0.85 tau from
// the solid, and the mutated upper bound is at most covers + tau/4 + the ball's delta.
TEST(AgainstFclMutation, ADeltaBelowTheCoversReachGivesAnUpperBoundBelowTheExactDistance) {
  INSCRIBE_REQUIRE_MESH("cow.off");
  const std::unique_ptr<Model> a = GeneratedModel("cow.off", 1.0);
  ASSERT_TRUE(a);
  double tau = 0.0;
  Vector3 tip = Vector3::Zero(), out = Vector3::UnitX();
  for (const Sphere& s : a->cover_spheres) {
    const BoundaryPoint b = a->solid.oracle.ClosestPoint(s.center);
    const bool inside = a->solid.oracle.Classify(s.center, b) == Side::kInside;
    if (b.distance == 0.0) continue;
    const Vector3 u = (inside ? b.point - s.center : s.center - b.point) / b.distance;
    const Vector3 q = s.center + s.radius * u;
    const double reach = a->solid.oracle.SignedDistance(q);
    if (reach > tau) {
      tau = reach;
      tip = q;
      out = u;
    }
  }
  ASSERT_GT(tau, 1e-4 * a->largest);
  ASSERT_LE(tau, a->delta);  // the real reach is within the certified bound
  const SphereHierarchy& cover = a->cover;
  const CertifiedObject mutant{&a->internal, &cover, 0.25 * tau};
  const std::unique_ptr<Model> ball = BallModel(tau / 20.0);
  ASSERT_TRUE(ball);
  const Probe probe = ProbeAt(*a, mutant, *ball, tip + out * (tau / 10.0));
  const double slack = kFclSlack * a->largest;
  EXPECT_LE(probe.sound.lower, probe.exact + slack);
  EXPECT_GE(probe.sound.upper, probe.exact - slack);
  EXPECT_LT(probe.mutated.upper, probe.exact - 0.3 * tau)
      << "exact " << probe.exact << ", tau " << tau << ", covers " << probe.mutated.cover.distance;
}

}  // namespace
}  // namespace inscribe
