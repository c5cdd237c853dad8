// Sphere sets, certified covers and certified distance intervals of adversarial solids
// (support/adversarial_assemblies.h), through the public pipeline (GenerateSphereSet,
// CertifyCover, SphereProtrusions, CertifiedDistances), against the brute-force winding number
// and distance of the shells as meant (support/winding_oracle.h) and FCL: an internal sphere
// holds only points of the solid (none in a cavity, none outside a thin wall); a cover holds
// every sampled point of the solid and reaches no farther than its delta outside it; a cover
// missing the spheres around a point next to a cavity or a wall is refused; protrusion bounds
// are sound; the interval between a hollow box and a ball in its cavity holds the exact gap.
// Classification itself: adversarial_solids_test.cpp.
#include <gtest/gtest.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/solid/solid.h"
#include "support/adversarial_assemblies.h"
#include "support/fcl_solid_distance.h"
#include "support/synthetic_meshes.h"
#include "support/winding_oracle.h"

namespace inscribe {
namespace {

using testing::Assembly;
using testing::WindingOracle;
using testing::WindingSample;

// Relative tolerance (times the largest coordinate magnitude) for comparisons with the brute
// force's long-double distances: far above both sides' rounding, far below any feature here.
constexpr double kRelativeSlack = 1e-9;

struct SphereCase {
  std::string name;
  std::function<Assembly()> make;
  std::int64_t internal_budget = 0;
  std::int64_t cover_budget = 0;
  // A point of the solid next to a cavity, an overlap, a thin wall or a degenerate seam.
  Vector3 probe = Vector3::Zero();
};

std::ostream& operator<<(std::ostream& out, const SphereCase& c) { return out << c.name; }

double LargestCoordinate(const Mesh& mesh) { return mesh.vertices.cwiseAbs().maxCoeff(); }

// r - depth(centre) by the brute force: how far the ball reaches outside the shells as meant
// (depth negative outside). Centres the brute force cannot decide count as on the boundary.
double TrueProtrusion(const WindingOracle& oracle, const Sphere& s) {
  const WindingSample w = oracle.At(s.center);
  const double d = oracle.Distance(s.center);
  return s.radius - (w.reliable && w.inside() ? d : -d);
}

std::vector<Vector3> Centres(const std::vector<Sphere>& spheres) {
  std::vector<Vector3> out;
  for (const Sphere& s : spheres) out.push_back(s.center);
  return out;
}
std::vector<double> Radii(const std::vector<Sphere>& spheres) {
  std::vector<double> out;
  for (const Sphere& s : spheres) out.push_back(s.radius);
  return out;
}

bool InSomeSphere(const std::vector<Sphere>& spheres, const Vector3& p) {
  return std::any_of(spheres.begin(), spheres.end(), [&p](const Sphere& s) {
    return (p - s.center).squaredNorm() <= s.radius * s.radius;
  });
}

// Rows of `points` in no sphere, counted in parallel; the first such row in `first`.
std::int64_t CountUncovered(const std::vector<Sphere>& spheres, const Vertices& points,
                            const std::vector<char>& wanted, Eigen::Index* first) {
  *first = -1;
  std::int64_t count = 0;
  std::vector<char> uncovered(static_cast<std::size_t>(points.rows()), 0);
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, points.rows(), 64),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
                        uncovered[static_cast<std::size_t>(i)] =
                            wanted[static_cast<std::size_t>(i)] &&
                            !InSomeSphere(spheres, points.row(i).transpose());
                      }
                    });
  for (std::size_t i = 0; i < uncovered.size(); ++i) {
    if (!uncovered[i]) continue;
    if (count++ == 0) *first = static_cast<Eigen::Index>(i);
  }
  return count;
}

std::string Format(const Vector3& p) {
  std::ostringstream out;
  out.precision(17);
  out << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return out.str();
}

class AdversarialSpheres : public ::testing::TestWithParam<SphereCase> {
 protected:
  void SetUp() override {
    assembly_ = GetParam().make();
    absl::StatusOr<Solid> solid = PrepareSolid(assembly_.input);
    ASSERT_TRUE(solid.ok()) << solid.status();
    solid_.emplace(*std::move(solid));
    oracle_.emplace(assembly_.intended);
    scale_ = LargestCoordinate(assembly_.intended);
    const WindingSample probe = oracle_->At(GetParam().probe);
    ASSERT_TRUE(probe.reliable && probe.inside()) << "the probe must be a point of the solid";
  }

  std::optional<Solid> solid_;
  std::optional<WindingOracle> oracle_;
  Assembly assembly_;
  double scale_ = 1.0;
};

TEST_P(AdversarialSpheres, InternalSpheresHoldOnlyPointsOfTheSolid) {
  SphereSetParameters parameters;
  parameters.kind = SphereSetKind::kInternal;
  parameters.max_spheres = GetParam().internal_budget;
  parameters.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> set = GenerateSphereSet(*solid_, parameters);
  ASSERT_TRUE(set.ok()) << set.status();
  const std::vector<Sphere>& spheres = set->set.spheres;
  ASSERT_FALSE(spheres.empty());
  const Vertices points = testing::PointsInBalls(Centres(spheres), Radii(spheres), 64, 21);
  const std::vector<WindingSample> truth = oracle_->AtAll(points);
  std::int64_t outside = 0, checked = 0;
  Eigen::Index first = -1;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!truth[i].reliable) continue;
    ++checked;
    if (!truth[i].inside() && outside++ == 0) first = static_cast<Eigen::Index>(i);
  }
  EXPECT_EQ(outside, 0) << outside << " of " << checked << " points of the " << spheres.size()
                        << " internal spheres lie outside the solid (in a cavity or beyond a "
                           "wall), first "
                        << (first >= 0 ? Format(points.row(first).transpose()) : "");
  EXPECT_GT(checked, points.rows() / 2);

  // Protrusion: at most 0 (plus the bound's margin), and no less than the brute force's.
  absl::StatusOr<std::vector<double>> bound = SphereProtrusions(*solid_, spheres);
  ASSERT_TRUE(bound.ok()) << bound.status();
  ASSERT_EQ(bound->size(), spheres.size());
  const double slack = kRelativeSlack * scale_;
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const double truth_i = TrueProtrusion(*oracle_, spheres[i]);
    EXPECT_LE((*bound)[i], slack) << "sphere " << i << " at " << Format(spheres[i].center);
    EXPECT_LE(truth_i, slack) << "sphere " << i << " at " << Format(spheres[i].center);
    EXPECT_GE((*bound)[i], truth_i - slack) << "sphere " << i << ": unsound protrusion bound";
  }
}

TEST_P(AdversarialSpheres, CoverHoldsTheSolidAndStaysWithinDelta) {
  SphereSetParameters parameters;
  parameters.kind = SphereSetKind::kCover;
  parameters.max_spheres = GetParam().cover_budget;
  parameters.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> set = GenerateSphereSet(*solid_, parameters);
  ASSERT_TRUE(set.ok()) << set.status();
  ASSERT_TRUE(set->cover.has_value());
  const CoverCertificate& certificate = set->cover->certificate;
  EXPECT_TRUE(certificate.certified);
  const std::vector<Sphere>& spheres = set->set.spheres;
  const double delta = certificate.delta;
  const double slack = kRelativeSlack * scale_;

  // Every sampled point of the solid (the brute force's inside, and the boundary) is covered.
  const Vertices volume = testing::AssemblyPoints(assembly_, 10'000, 10'000, 5'000, 31);
  const std::vector<WindingSample> volume_truth = oracle_->AtAll(volume);
  std::vector<char> of_solid(volume_truth.size());
  for (std::size_t i = 0; i < volume_truth.size(); ++i) {
    of_solid[i] = volume_truth[i].reliable && volume_truth[i].inside();
  }
  Eigen::Index first = -1;
  EXPECT_EQ(CountUncovered(spheres, volume, of_solid, &first), 0)
      << "a point of the solid in no sphere of the certified cover: "
      << (first >= 0 ? Format(volume.row(first).transpose()) : "");
  const Vertices boundary = testing::BoundaryPoints(assembly_.intended, 10'000, 32);
  EXPECT_EQ(CountUncovered(spheres, boundary, std::vector<char>(boundary.rows(), 1), &first), 0)
      << "a boundary point in no sphere of the certified cover: "
      << (first >= 0 ? Format(boundary.row(first).transpose()) : "");

  // Every sampled point of a sphere is in the solid or within delta of it.
  const Vertices in_spheres = testing::PointsInBalls(Centres(spheres), Radii(spheres), 32, 33);
  const std::vector<WindingSample> truth = oracle_->AtAll(in_spheres);
  std::int64_t too_far = 0;
  double farthest = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i].reliable && truth[i].inside()) continue;
    const double d = oracle_->Distance(in_spheres.row(static_cast<Eigen::Index>(i)).transpose());
    farthest = std::max(farthest, d);
    too_far += d > delta + slack;
  }
  EXPECT_EQ(too_far, 0) << "points of the cover lie up to " << farthest
                        << " outside the solid, beyond delta " << delta;

  // The per-sphere protrusions are sound bounds, and SphereProtrusions gives the same.
  ASSERT_EQ(certificate.protrusions.size(), spheres.size());
  absl::StatusOr<std::vector<double>> bound = SphereProtrusions(*solid_, spheres);
  ASSERT_TRUE(bound.ok()) << bound.status();
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const double truth_i = TrueProtrusion(*oracle_, spheres[i]);
    EXPECT_GE(certificate.protrusions[i], truth_i - slack) << "sphere " << i;
    EXPECT_GE((*bound)[i], truth_i - slack) << "sphere " << i;
    EXPECT_LE(truth_i, delta + slack) << "sphere " << i;
  }

  // Without the spheres around the probe (next to a cavity, overlap or wall), no cover.
  std::vector<Sphere> rest;
  for (const Sphere& s : spheres) {
    if ((GetParam().probe - s.center).norm() > s.radius) rest.push_back(s);
  }
  ASSERT_LT(rest.size(), spheres.size());
  absl::StatusOr<CoverCertificate> broken = CertifyCover(*solid_, rest);
  ASSERT_TRUE(broken.ok()) << broken.status();
  EXPECT_FALSE(broken->certified) << "certified without the " << spheres.size() - rest.size()
                                  << " spheres holding " << Format(GetParam().probe);
  if (broken->uncovered_point) {
    const Vector3 witness = *broken->uncovered_point;
    const WindingSample w = oracle_->At(witness);
    EXPECT_TRUE(!w.reliable || w.inside())
        << "the witness " << Format(witness) << " is not a point of the solid";
    EXPECT_FALSE(InSomeSphere(rest, witness)) << "the witness " << Format(witness);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Solids, AdversarialSpheres,
    ::testing::Values(SphereCase{"HollowBoxAmong300Shells",
                                 [] { return testing::HollowBoxWithDebris(false); }, 400, 700,
                                 Vector3(0.65, 0.05, -0.1)},
                      SphereCase{"OverlapWithTouchingTetrahedron",
                                 testing::OverlapWithTouchingTetrahedron, 150, 150,
                                 Vector3(0.75, 0.65, 0.6)},
                      SphereCase{"NestedShells", [] { return testing::NestedShells(false); }, 200,
                                 200, Vector3(0.55, 0.1, 0.1)},
                      SphereCase{"CollinearTriangles", testing::BoxWithCollinearTriangles, 100, 100,
                                 Vector3(0.5, 0.5, 0.01)},
                      SphereCase{"OverlappingIcospheres", testing::OverlappingIcospheres, 150, 150,
                                 Vector3(0.6, 0.1, 0.0)}),
    [](const ::testing::TestParamInfo<SphereCase>& param_info) { return param_info.param.name; });

// One solid of a certified query: its cover's cores (or internal set) and its cover.
struct CertifiedSolid {
  std::optional<Solid> solid;
  std::optional<SphereHierarchy> internal, cover;
  CertifiedObject object;
};

// The internal set within `internal_budget` spheres and the cover `cover` asks for (kind
// kCover, a budget or a max_protrusion).
void Certify(const Mesh& mesh, std::int64_t internal_budget, const SphereSetParameters& cover,
             CertifiedSolid* out) {
  absl::StatusOr<Solid> solid = PrepareSolid(mesh);
  ASSERT_TRUE(solid.ok()) << solid.status();
  out->solid.emplace(*std::move(solid));
  SphereSetParameters internal;
  internal.max_spheres = internal_budget;
  internal.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> set = GenerateSphereSet(*out->solid, internal);
  ASSERT_TRUE(set.ok()) << set.status();
  absl::StatusOr<GeneratedSphereSet> covered = GenerateSphereSet(*out->solid, cover);
  ASSERT_TRUE(covered.ok()) << covered.status();
  ASSERT_TRUE(covered->cover.has_value() && covered->cover->certificate.certified);
  absl::StatusOr<std::vector<Sphere>> upper = UpperBoundSpheres(
      set->set.spheres, covered->set.spheres, covered->cover->certificate.protrusions);
  ASSERT_TRUE(upper.ok()) << upper.status();
  absl::StatusOr<SphereHierarchy> a = SphereHierarchy::Build(*upper, HierarchyVolume::kRss);
  absl::StatusOr<SphereHierarchy> b =
      SphereHierarchy::Build(covered->set.spheres, HierarchyVolume::kSphere);
  ASSERT_TRUE(a.ok() && b.ok());
  out->internal.emplace(*std::move(a));
  out->cover.emplace(*std::move(b));
  out->object = CertifiedObject{&*out->internal, &*out->cover, covered->cover->certificate.delta};
}

SphereSetParameters CoverParameters(std::optional<std::int64_t> max_spheres,
                                    std::optional<double> max_protrusion) {
  SphereSetParameters parameters;
  parameters.kind = SphereSetKind::kCover;
  parameters.max_spheres = max_spheres;
  parameters.max_protrusion = max_protrusion;
  parameters.evaluate = false;
  return parameters;
}

// A ball (icosphere, radius 0.2) in the cavity [-0.6, 0.6]^3 of `hollow`, its nearest point
// 0.075-0.1 from the cavity's wall x = 0.6. The exact gap: the nearest point of a convex
// polytope to the walls of the box around it is a vertex (min over axes of 0.6 - |coordinate|
// is concave), and FCL's triangle distance agrees. The interval must hold it, so it cannot be
// [0, 0] (internal spheres in the cavity would make it so); when the covers' deltas leave the
// gap open, it must exclude 0 too.
void ExpectIntervalHoldsTheGap(const Assembly& hollow, std::int64_t hollow_cover_budget) {
  const Mesh ball = testing::Icosphere(2, Vector3(0.325, 0.0, 0.0), 0.2);
  double exact = std::numeric_limits<double>::infinity();
  for (Eigen::Index v = 0; v < ball.num_vertices(); ++v) {
    exact = std::min(exact, 0.6 - ball.vertices.row(v).cwiseAbs().maxCoeff());
  }
  ASSERT_GT(exact, 0.075 - 1e-12);
  ASSERT_LT(exact, 0.1);

  CertifiedSolid a, b;
  ASSERT_NO_FATAL_FAILURE(
      Certify(hollow.input, 400, CoverParameters(hollow_cover_budget, std::nullopt), &a));
  ASSERT_NO_FATAL_FAILURE(Certify(ball, 10, CoverParameters(std::nullopt, 0.01), &b));
  const testing::FclSolid fcl_a = testing::MakeFclSolid(*a.solid);
  const testing::FclSolid fcl_b = testing::MakeFclSolid(*b.solid);
  EXPECT_NEAR(testing::SurfaceDistance(fcl_a, RigidPose{}, fcl_b, RigidPose{}), exact, 1e-9);

  const CertifiedPair pair{&a.object, &b.object, RigidPose{}, RigidPose{}};
  absl::StatusOr<std::vector<CertifiedDistanceResult>> result = CertifiedDistances({pair});
  ASSERT_TRUE(result.ok()) << result.status();
  const CertifiedDistanceResult& r = result->front();
  std::printf("[ interval ] %s: exact %.6f in [%.6f, %.6f]; cover deltas %.6f, %.6f\n",
              hollow.name.c_str(), exact, r.lower, r.upper, a.object.cover_delta,
              b.object.cover_delta);
  EXPECT_LE(r.lower, exact + 1e-9) << "[" << r.lower << ", " << r.upper << "]";
  EXPECT_GE(r.upper, exact - 1e-9)
      << "[" << r.lower << ", " << r.upper << "]: the internal spheres reach into the cavity";
  EXPECT_GT(r.upper, 0.0);
  if (a.object.cover_delta + b.object.cover_delta < 0.9 * exact) {
    EXPECT_GT(r.lower, 0.0) << "[" << r.lower << ", " << r.upper << "], deltas "
                            << a.object.cover_delta << " and " << b.object.cover_delta;
  }
  // "Closer than half the gap?" is never answered yes.
  EXPECT_NE(DecideCloser(r.lower, r.upper, 0.5 * exact), CloserAnswer::kYes);
}

// The cavity of the hollow box among 300 other shells (its nesting found among 302
// components).
TEST(AdversarialCertifiedDistance, BallInTheCavityOfAHollowBoxAmong300Shells) {
  ExpectIntervalHoldsTheGap(testing::HollowBoxWithDebris(false), 700);
}

}  // namespace
}  // namespace inscribe
