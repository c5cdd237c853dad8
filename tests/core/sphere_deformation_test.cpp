#include "inscribe/medial/sphere_deformation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <tuple>

#include "base/parallel.h"
#include "deformation_sequences.h"
#include "inscribe/balls/union_of_balls.h"
#include "inscribe/medial/medial_spheres.h"
#include "support/brute_force_closest_point.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"
#include "support/union_volume_reference.h"

namespace inscribe {
namespace {

using sequences::DeformationKind;
using testing::BruteForceDistance;
using testing::LoadTestMesh;

BoundaryOracle BuildOracle(const Mesh& mesh) {
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  EXPECT_TRUE(oracle.ok()) << oracle.status();
  return *std::move(oracle);
}

// Depth of x below the boundary of a freshly built oracle: positive inside.
double Depth(const BoundaryOracle& oracle, const Vector3& x) { return -oracle.SignedDistance(x); }

// A reference: a real mesh and its medial spheres at a voxel size giving a few hundred, made
// once per mesh for the whole binary.
struct Reference {
  Mesh mesh;
  SphereSet spheres;
};

const Reference& ReferenceFor(const std::string& name) {
  static std::map<std::string, Reference> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  Reference ref;
  ref.mesh = LoadTestMesh(name);
  BoundaryOracle oracle = BuildOracle(ref.mesh);
  MedialSphereOptions options;
  options.voxel_size = ComputeBoundingBox(ref.mesh.vertices).diagonal() / 30.0;
  absl::StatusOr<MedialSphereResult> result = GenerateMedialSpheres(oracle, options);
  EXPECT_TRUE(result.ok()) << result.status();
  if (result.ok()) ref.spheres = result->set;
  return cache.emplace(name, std::move(ref)).first->second;
}

SphereDeformer MakeDeformer(const Reference& ref, const DeformationOptions& options = {}) {
  absl::StatusOr<SphereDeformer> deformer = SphereDeformer::Create(ref.mesh, ref.spheres, options);
  EXPECT_TRUE(deformer.ok()) << deformer.status();
  return *std::move(deformer);
}

// The point of `mesh` a contact names: its barycentric combination of the triangle's corners.
Vector3 PointOf(const Mesh& mesh, const SurfaceContact& contact) {
  Vector3 point = Vector3::Zero();
  for (int k = 0; k < 3; ++k) {
    point +=
        contact.barycentric[k] * mesh.vertices.row(mesh.triangles(contact.triangle, k)).transpose();
  }
  return point;
}

Mesh WithVertices(const Mesh& mesh, const Vertices& vertices) {
  return Mesh{vertices, mesh.triangles};
}

// ---- Rigid motion -----------------------------------------------------------------------

class RigidMotion : public ::testing::TestWithParam<std::string> {};

TEST_P(RigidMotion, MovesEverySphereExactly) {
  INSCRIBE_REQUIRE_MESH(GetParam());
  const Reference& ref = ReferenceFor(GetParam());
  ASSERT_GT(ref.spheres.size(), 50u);
  const double scale = ComputeBoundingBox(ref.mesh.vertices).diagonal();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal;
  for (bool strict : {false, true}) {
    DeformationOptions options;
    options.strict = strict;
    SphereDeformer deformer = MakeDeformer(ref, options);
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::Matrix3d rotation =
          Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
              .normalized()
              .toRotationMatrix();
      const Vector3 shift(normal(rng) * scale, normal(rng) * scale, normal(rng) * scale);
      Vertices moved(ref.mesh.num_vertices(), 3);
      for (Eigen::Index v = 0; v < moved.rows(); ++v) {
        moved.row(v) = (rotation * ref.mesh.vertices.row(v).transpose() + shift).transpose();
      }
      absl::StatusOr<DeformedSpheres> out = deformer.Update(moved);
      ASSERT_TRUE(out.ok()) << out.status();
      ASSERT_EQ(out->set.size(), ref.spheres.size());
      EXPECT_EQ(out->shrunk, 0);
      for (std::size_t i = 0; i < ref.spheres.size(); ++i) {
        const Sphere& before = ref.spheres.spheres[i];
        const Sphere& after = out->set.spheres[i];
        const Vector3 expected = rotation * before.center + shift;
        EXPECT_LE((after.center - expected).norm(), 1e-9 * scale)
            << GetParam() << " sphere " << i << (strict ? " strict" : "");
        EXPECT_NEAR(after.radius, before.radius, 1e-9 * scale) << "sphere " << i;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, RigidMotion,
                         ::testing::Values("eight.off", "elephant.off", "fandisk.off"));

TEST(SphereDeformer, IdentityChangesNothing) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Reference& ref = ReferenceFor("eight.off");
  SphereDeformer deformer = MakeDeformer(ref);
  absl::StatusOr<DeformedSpheres> out = deformer.Update(ref.mesh.vertices);
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(out->set.size(), ref.spheres.size());
  EXPECT_EQ(out->shrunk, 0);
  for (std::size_t i = 0; i < ref.spheres.size(); ++i) {
    EXPECT_LE((out->set.spheres[i].center - ref.spheres.spheres[i].center).norm(), 1e-12);
    EXPECT_EQ(out->set.spheres[i].radius, ref.spheres.spheres[i].radius);
    EXPECT_EQ(out->set.contacts[i].triangle, ref.spheres.contacts[i].triangle);
    EXPECT_EQ(out->reference_index[i], static_cast<std::int32_t>(i));
  }
}

// ---- Protrusion and tangency on the deformation sequences -------------------------------

using SequenceCase = std::tuple<std::string, DeformationKind>;

// "knot1_bend" for (knot1.off, kBend).
std::string SequenceCaseName(const ::testing::TestParamInfo<SequenceCase>& param) {
  std::string model = std::get<0>(param.param);
  model = model.substr(0, model.find('.'));
  return model + "_" + sequences::DeformationKindName(std::get<1>(param.param));
}

class DeformationSequence : public ::testing::TestWithParam<SequenceCase> {};

// After every update no sphere sticks out xi or more: r - depth(c) < xi (1 + 1e-9), with the
// depth from an oracle built afresh on the deformed mesh, and a brute-force distance scan for
// every tenth sphere. Frames are updated out of order to show that nothing carries over.
TEST_P(DeformationSequence, NoSphereProtrudesXi) {
  const auto& [name, kind] = GetParam();
  INSCRIBE_REQUIRE_MESH(name);
  const Reference& ref = ReferenceFor(name);
  for (ContactDirection direction :
       {ContactDirection::kCarriedFrame, ContactDirection::kInterpolatedNormal}) {
    DeformationOptions options;
    options.direction = direction;
    SphereDeformer deformer = MakeDeformer(ref, options);
    const double xi = deformer.options().xi;
    EXPECT_NEAR(xi, 0.0025 * ComputeBoundingBox(ref.mesh.vertices).extent().maxCoeff(), 1e-15);
    for (double t : {1.0, 0.4, 0.7}) {
      const Mesh deformed = WithVertices(ref.mesh, sequences::Deform(ref.mesh.vertices, kind, t));
      absl::StatusOr<DeformedSpheres> out = deformer.Update(deformed.vertices);
      ASSERT_TRUE(out.ok()) << out.status();
      ASSERT_EQ(out->set.size(), ref.spheres.size());
      EXPECT_LT(out->max_protrusion, xi * (1 + 1e-9));
      const BoundaryOracle fresh = BuildOracle(deformed);
      for (std::size_t i = 0; i < out->set.size(); ++i) {
        const Sphere& s = out->set.spheres[i];
        const double depth = Depth(fresh, s.center);
        ASSERT_LT(s.radius - depth, xi * (1 + 1e-9)) << name << " t=" << t << " sphere " << i;
        ASSERT_GT(s.radius, 0.0);
        if (i % 10 == 0) {
          EXPECT_NEAR(std::abs(depth), BruteForceDistance(deformed, s.center), 1e-12);
        }
        // The contact rides along: |c - A'| = r.
        const SurfaceContact& contact = out->set.contacts[i];
        const Vector3 a = PointOf(deformed, contact);
        EXPECT_NEAR((s.center - a).norm(), s.radius, 1e-9 * s.radius);
      }
    }
  }
}

// Strict mode: every sphere internal (centre inside) and tangent (radius = the brute-force
// distance from its centre to the deformed boundary, contact at that distance).
TEST_P(DeformationSequence, StrictModeIsInternalAndTangent) {
  const auto& [name, kind] = GetParam();
  INSCRIBE_REQUIRE_MESH(name);
  const Reference& ref = ReferenceFor(name);
  DeformationOptions options;
  options.strict = true;
  SphereDeformer deformer = MakeDeformer(ref, options);
  const Mesh deformed = WithVertices(ref.mesh, sequences::Deform(ref.mesh.vertices, kind, 1.0));
  absl::StatusOr<DeformedSpheres> out = deformer.Update(deformed.vertices);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->set.size() + static_cast<std::size_t>(out->dropped), ref.spheres.size());
  EXPECT_LE(out->max_protrusion, 0.0);
  const BoundaryOracle fresh = BuildOracle(deformed);
  for (std::size_t i = 0; i < out->set.size(); ++i) {
    const Sphere& s = out->set.spheres[i];
    ASSERT_EQ(fresh.Classify(s.center), Side::kInside) << name << " sphere " << i;
    if (i % 4 == 0) {
      EXPECT_NEAR(s.radius, BruteForceDistance(deformed, s.center), 1e-12 * (1 + s.radius))
          << "sphere " << i;
    }
    const SurfaceContact& contact = out->set.contacts[i];
    const Vector3 a = PointOf(deformed, contact);
    EXPECT_NEAR((s.center - a).norm(), s.radius, 1e-9 * s.radius) << "sphere " << i;
  }
  // Internal spheres: the bounds meet at the exact error.
  absl::StatusOr<DeformationErrorBounds> bounds =
      BoundDeformationError(deformer.oracle(), out->set.spheres, out->xi);
  ASSERT_TRUE(bounds.ok()) << bounds.status();
  EXPECT_TRUE(bounds->exact);
  EXPECT_EQ(bounds->nerr_lower, bounds->nerr_upper);
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, DeformationSequence,
                         ::testing::Values(SequenceCase{"knot1.off", DeformationKind::kBend},
                                           SequenceCase{"elephant.off", DeformationKind::kBend},
                                           SequenceCase{"eight.off", DeformationKind::kTwist},
                                           SequenceCase{"fandisk.off", DeformationKind::kTwist},
                                           SequenceCase{"eight.off", DeformationKind::kPinch},
                                           SequenceCase{"knot1.off", DeformationKind::kPinch}),
                         SequenceCaseName);

// ---- The error bounds against Monte Carlo -----------------------------------------------

struct ErrorEstimate {
  double nerr;
  double standard_error;
};

// nerr = vol(solid XOR union) / vol(solid) by uniform samples in the box around both, the
// solid's side from `oracle` (built afresh), the union's from a ball grid. Fixed seeds per
// block, so the estimate does not depend on the thread schedule.
ErrorEstimate MonteCarloError(const BoundaryOracle& oracle, const std::vector<Sphere>& spheres,
                              double volume_mesh, std::int64_t samples) {
  const testing::BallGrid grid(spheres);
  const BoundingBox box = ComputeBoundingBox(oracle.mesh().vertices);
  const Vector3 lo = box.min.cwiseMin(grid.lo());
  const Vector3 hi = box.max.cwiseMax(grid.hi());
  constexpr std::int64_t kBlock = 4096;
  const std::int64_t blocks = (samples + kBlock - 1) / kBlock;
  const std::int64_t hits = internal::ParallelReduce(
      std::int64_t{0}, blocks, 1, std::int64_t{0},
      [&](std::int64_t begin, std::int64_t end, std::int64_t count) {
        for (std::int64_t b = begin; b < end; ++b) {
          std::mt19937_64 rng(977 + static_cast<std::uint64_t>(b));
          std::uniform_real_distribution<double> unit(0.0, 1.0);
          for (std::int64_t k = 0; k < kBlock; ++k) {
            const Vector3 p(lo[0] + unit(rng) * (hi[0] - lo[0]),
                            lo[1] + unit(rng) * (hi[1] - lo[1]),
                            lo[2] + unit(rng) * (hi[2] - lo[2]));
            const bool in_solid = oracle.Classify(p) == Side::kInside;
            count += in_solid != grid.Contains(p);
          }
        }
        return count;
      },
      [](std::int64_t a, std::int64_t b) { return a + b; });
  const double n = static_cast<double>(blocks * kBlock);
  const double fraction = static_cast<double>(hits) / n;
  const double box_volume = (hi - lo).prod();
  return {fraction * box_volume / volume_mesh,
          std::sqrt(fraction * (1.0 - fraction) / n) * box_volume / volume_mesh};
}

class BoundsBracket : public ::testing::TestWithParam<SequenceCase> {};

TEST_P(BoundsBracket, TrueErrorByMonteCarlo) {
  const auto& [name, kind] = GetParam();
  INSCRIBE_REQUIRE_MESH(name);
  const Reference& ref = ReferenceFor(name);
  for (bool strict : {false, true}) {
    DeformationOptions options;
    options.strict = strict;
    SphereDeformer deformer = MakeDeformer(ref, options);
    const Mesh deformed = WithVertices(ref.mesh, sequences::Deform(ref.mesh.vertices, kind, 1.0));
    absl::StatusOr<DeformedSpheres> out = deformer.Update(deformed.vertices);
    ASSERT_TRUE(out.ok()) << out.status();
    absl::StatusOr<DeformationErrorBounds> bounds =
        BoundDeformationError(deformer.oracle(), out->set.spheres, out->xi);
    ASSERT_TRUE(bounds.ok()) << bounds.status();
    EXPECT_LE(bounds->nerr_lower, bounds->nerr_upper);
    EXPECT_TRUE(bounds->uniform_xi_holds);
    EXPECT_LE(bounds->nerr_upper, bounds->nerr_upper_uniform_xi);
    EXPECT_NEAR(bounds->volume_mesh, SignedVolume(deformed), 1e-12 * bounds->volume_mesh);

    const BoundaryOracle fresh = BuildOracle(deformed);
    const ErrorEstimate mc = MonteCarloError(fresh, out->set.spheres, bounds->volume_mesh, 600'000);
    const double slack = 4.0 * mc.standard_error;
    EXPECT_GE(mc.nerr, bounds->nerr_lower - slack)
        << name << (strict ? " strict" : "") << ": MC " << mc.nerr << " +- " << mc.standard_error;
    EXPECT_LE(mc.nerr, bounds->nerr_upper + slack)
        << name << (strict ? " strict" : "") << ": MC " << mc.nerr << " +- " << mc.standard_error
        << ", bounds " << bounds->nerr_lower << " .. " << bounds->nerr_upper;
    if (strict) {
      EXPECT_TRUE(bounds->exact);
    } else {
      // Spheres that stick out make the error exceed Lemma 1's value: the bounds must not
      // be equal then, and Monte Carlo must see the difference.
      EXPECT_FALSE(bounds->exact);
      EXPECT_GT(mc.nerr, bounds->nerr_lower);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(RealMeshes, BoundsBracket,
                         ::testing::Values(SequenceCase{"knot1.off", DeformationKind::kBend},
                                           SequenceCase{"eight.off", DeformationKind::kPinch},
                                           SequenceCase{"fandisk.off", DeformationKind::kTwist}),
                         SequenceCaseName);

// Random smooth displacement fields (sums of three sinusoids of random direction, wavelength
// and phase, amplitude 1.5% of the diagonal): no sphere protrudes xi (fresh oracle), strict
// spheres are tangent (brute force), and the bounds bracket Monte Carlo's error.
TEST(SphereDeformer, RandomSmoothFields) {
  for (const char* name : {"eight.off", "knot1.off"}) {
    INSCRIBE_REQUIRE_MESH(name);
    const Reference& ref = ReferenceFor(name);
    const double diagonal = ComputeBoundingBox(ref.mesh.vertices).diagonal();
    std::mt19937_64 rng(23);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int field = 0; field < 3; ++field) {
      Vertices moved = ref.mesh.vertices;
      for (int wave = 0; wave < 3; ++wave) {
        const Vector3 k = Vector3(normal(rng), normal(rng), normal(rng)).normalized() *
                          (2.0 + 4.0 * unit(rng)) / diagonal;
        const Vector3 direction = Vector3(normal(rng), normal(rng), normal(rng)).normalized();
        const double phase = 6.283185307179586 * unit(rng);
        for (Eigen::Index v = 0; v < moved.rows(); ++v) {
          const double s = std::sin(k.dot(ref.mesh.vertices.row(v).transpose()) + phase);
          moved.row(v) += (0.005 * diagonal * s * direction).transpose();
        }
      }
      const Mesh deformed = WithVertices(ref.mesh, moved);
      const BoundaryOracle fresh = BuildOracle(deformed);
      for (bool strict : {false, true}) {
        DeformationOptions options;
        options.strict = strict;
        SphereDeformer deformer = MakeDeformer(ref, options);
        absl::StatusOr<DeformedSpheres> out = deformer.Update(moved);
        ASSERT_TRUE(out.ok()) << out.status();
        for (std::size_t i = 0; i < out->set.size(); ++i) {
          const Sphere& sphere = out->set.spheres[i];
          ASSERT_LT(sphere.radius - Depth(fresh, sphere.center), out->xi * (1 + 1e-9))
              << name << " field " << field << " sphere " << i;
          if (strict && i % 8 == 0) {
            EXPECT_NEAR(sphere.radius, BruteForceDistance(deformed, sphere.center), 1e-12);
          }
        }
        if (field > 0) continue;
        absl::StatusOr<DeformationErrorBounds> bounds =
            BoundDeformationError(deformer.oracle(), out->set.spheres, out->xi);
        ASSERT_TRUE(bounds.ok());
        const ErrorEstimate mc =
            MonteCarloError(fresh, out->set.spheres, bounds->volume_mesh, 300'000);
        EXPECT_GE(mc.nerr, bounds->nerr_lower - 4 * mc.standard_error) << name;
        EXPECT_LE(mc.nerr, bounds->nerr_upper + 4 * mc.standard_error) << name;
      }
    }
  }
}

// ---- Synthetic cases with known answers -------------------------------------------------

// A box scaled by 1/2 about its centre: every contact moves to half its distance from the
// centre while radii stay, so every sphere sticks out and Algorithm 1 must shrink it below xi
// (strict mode: to internal and tangent), in a logarithmic number of halvings.
TEST(SphereDeformer, UniformShrinkOfABox) {
  const Mesh ball = testing::Box(Vector3(-1.0, -0.5, -0.3), Vector3(1.0, 0.5, 0.3));
  BoundaryOracle oracle = BuildOracle(ball);
  MedialSphereOptions generation;
  generation.voxel_size = 0.1;
  absl::StatusOr<MedialSphereResult> generated = GenerateMedialSpheres(oracle, generation);
  ASSERT_TRUE(generated.ok()) << generated.status();
  ASSERT_GT(generated->set.size(), 20u);
  const Reference ref{ball, generated->set};
  Vertices half = 0.5 * ball.vertices;
  for (bool strict : {false, true}) {
    DeformationOptions options;
    options.strict = strict;
    options.xi = 1e-3;
    SphereDeformer deformer = MakeDeformer(ref, options);
    absl::StatusOr<DeformedSpheres> out = deformer.Update(half);
    ASSERT_TRUE(out.ok()) << out.status();
    const Mesh deformed = WithVertices(ball, half);
    EXPECT_EQ(out->shrunk, static_cast<std::int64_t>(ref.spheres.size()));
    for (std::size_t i = 0; i < out->set.size(); ++i) {
      const Sphere& s = out->set.spheres[i];
      const double distance = BruteForceDistance(deformed, s.center);
      if (strict) {
        EXPECT_NEAR(s.radius, distance, 1e-12);
      } else {
        EXPECT_LT(s.radius - distance, 1e-3 * (1 + 1e-9));
      }
    }
    // The halving count is logarithmic: at most log2(r / xi) + 2 for r <= 1.
    EXPECT_LE(out->max_shrink_steps, static_cast<int>(std::log2(1.0 / 1e-3)) + 2);
  }
}

TEST(BoundDeformationError, SingleSphereInACube) {
  const Mesh cube = testing::UnitCube();
  const BoundaryOracle oracle = BuildOracle(cube);
  const double pi = 3.14159265358979323846;
  {  // Internal: exact, nerr = 1 - 4/3 pi r^3.
    const std::vector<Sphere> inside = {{Vector3(0.5, 0.5, 0.5), 0.4}};
    absl::StatusOr<DeformationErrorBounds> b = BoundDeformationError(oracle, inside, 0.01);
    ASSERT_TRUE(b.ok()) << b.status();
    EXPECT_TRUE(b->exact);
    EXPECT_NEAR(b->nerr_lower, 1.0 - 4.0 / 3.0 * pi * 0.064, 1e-12);
    EXPECT_EQ(b->nerr_lower, b->nerr_upper);
  }
  {  // Protruding by 0.05 through one face (centre 0.45 from it): U_in has radius 0.45, and
     // the true error is 1 - vol(ball inside) + vol(cap outside).
    const double r = 0.5;
    const std::vector<Sphere> out_sphere = {{Vector3(0.5, 0.5, 0.55), r}};
    absl::StatusOr<DeformationErrorBounds> b = BoundDeformationError(oracle, out_sphere, 0.1);
    ASSERT_TRUE(b.ok()) << b.status();
    EXPECT_FALSE(b->exact);
    EXPECT_TRUE(b->uniform_xi_holds);
    EXPECT_NEAR(b->volume_union_inner, 4.0 / 3.0 * pi * std::pow(0.45, 3), 1e-12);
    EXPECT_NEAR(b->volume_union_shrunk, 4.0 / 3.0 * pi * std::pow(0.4, 3), 1e-12);
    const double h = 0.05;  // cap height above the face z = 1
    const double cap = pi * h * h * (3 * r - h) / 3.0;
    const double ball = 4.0 / 3.0 * pi * r * r * r;
    const double truth = 1.0 - (ball - cap) + cap;
    EXPECT_LE(b->nerr_lower, truth);
    EXPECT_GE(b->nerr_upper, truth);
    EXPECT_LE(b->nerr_upper, b->nerr_upper_uniform_xi);
    // xi below the protrusion: Lemma 2's premise fails and its bound is refused.
    absl::StatusOr<DeformationErrorBounds> small = BoundDeformationError(oracle, out_sphere, 0.01);
    ASSERT_TRUE(small.ok());
    EXPECT_FALSE(small->uniform_xi_holds);
    EXPECT_TRUE(std::isinf(small->nerr_upper_uniform_xi));
    EXPECT_EQ(small->nerr_upper, b->nerr_upper);
  }
  {  // A centre outside: no inner ball at all.
    const std::vector<Sphere> outside = {{Vector3(0.5, 0.5, 1.2), 0.3}};
    absl::StatusOr<DeformationErrorBounds> b = BoundDeformationError(oracle, outside, 0.01);
    ASSERT_TRUE(b.ok());
    EXPECT_EQ(b->volume_union_inner, 0.0);
  }
  EXPECT_FALSE(BoundDeformationError(oracle, {{Vector3(0.5, 0.5, 0.5), -1.0}}, 0.1).ok());
  EXPECT_FALSE(BoundDeformationError(oracle, {{Vector3(0.5, 0.5, 0.5), 0.1}}, -1.0).ok());
  EXPECT_FALSE(BoundDeformationError(oracle, {{Vector3(std::nan(""), 0.5, 0.5), 0.1}}, 0.1).ok());
}

// ---- Bad input --------------------------------------------------------------------------

TEST(SphereDeformer, RefusesBadReferences) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Reference& ref = ReferenceFor("eight.off");
  auto expect_refused = [&](SphereSet set, const std::string& fragment,
                            const DeformationOptions& options = {}) {
    absl::StatusOr<SphereDeformer> d = SphereDeformer::Create(ref.mesh, std::move(set), options);
    ASSERT_FALSE(d.ok()) << fragment;
    EXPECT_EQ(d.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_NE(d.status().message().find(fragment), std::string::npos) << d.status();
  };
  SphereSet no_contacts = ref.spheres;
  no_contacts.contacts.clear();
  expect_refused(no_contacts, "one contact each");
  SphereSet bad_triangle = ref.spheres;
  bad_triangle.contacts[3].triangle = static_cast<std::int32_t>(ref.mesh.num_triangles());
  expect_refused(bad_triangle, "reference sphere 3: contact triangle");
  SphereSet bad_weights = ref.spheres;
  bad_weights.contacts[4].barycentric = Vector3(0.5, 0.5, 0.5);
  expect_refused(bad_weights, "sum to 1");
  SphereSet nan_weights = ref.spheres;
  nan_weights.contacts[4].barycentric[0] = std::nan("");
  expect_refused(nan_weights, "reference sphere 4");
  SphereSet not_tangent = ref.spheres;
  not_tangent.spheres[5].radius *= 1.5;
  expect_refused(not_tangent, "must touch the boundary at its contact");
  SphereSet nan_radius = ref.spheres;
  nan_radius.spheres[6].radius = std::nan("");
  expect_refused(nan_radius, "reference sphere 6");
  DeformationOptions negative_xi;
  negative_xi.xi = -1.0;
  expect_refused(ref.spheres, "xi", negative_xi);
  absl::StatusOr<SphereDeformer> inverted =
      SphereDeformer::Create(testing::Inverted(ref.mesh), ref.spheres);
  EXPECT_FALSE(inverted.ok());
}

TEST(SphereDeformer, RefusesBadFramesAndStaysUsable) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Reference& ref = ReferenceFor("eight.off");
  SphereDeformer deformer = MakeDeformer(ref);
  const Vertices twisted = sequences::Deform(ref.mesh.vertices, DeformationKind::kTwist, 0.5);
  absl::StatusOr<DeformedSpheres> good = deformer.Update(twisted);
  ASSERT_TRUE(good.ok());

  Vertices short_frame = twisted.topRows(twisted.rows() - 1);
  absl::StatusOr<DeformedSpheres> r = deformer.Update(short_frame);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("vertices"), std::string::npos) << r.status();

  Vertices nan_frame = twisted;
  nan_frame(7, 1) = std::numeric_limits<double>::quiet_NaN();
  r = deformer.Update(nan_frame);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("deformed vertex 7"), std::string::npos) << r.status();

  // A mirror image turns the solid inside out.
  Vertices mirrored = twisted;
  mirrored.col(0) *= -1.0;
  r = deformer.Update(mirrored);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("inverts"), std::string::npos) << r.status();

  Vertices flat = twisted;
  flat.col(2).setZero();
  EXPECT_FALSE(deformer.Update(flat).ok());

  // None of that touched the deformer: the oracle still holds the last good frame, and the
  // same frame gives the same spheres bit for bit.
  EXPECT_EQ(deformer.oracle().mesh().vertices, twisted);
  absl::StatusOr<DeformedSpheres> again = deformer.Update(twisted);
  ASSERT_TRUE(again.ok());
  ASSERT_EQ(again->set.size(), good->set.size());
  for (std::size_t i = 0; i < good->set.size(); ++i) {
    EXPECT_EQ(again->set.spheres[i].center, good->set.spheres[i].center);
    EXPECT_EQ(again->set.spheres[i].radius, good->set.spheres[i].radius);
  }
}

// Every update starts from the reference: a frame's result does not depend on the frames
// updated before it.
TEST(SphereDeformer, UpdatesDoNotAccumulate) {
  INSCRIBE_REQUIRE_MESH("knot1.off");
  const Reference& ref = ReferenceFor("knot1.off");
  const Vertices frame = sequences::Deform(ref.mesh.vertices, DeformationKind::kBend, 0.6);
  SphereDeformer fresh = MakeDeformer(ref);
  absl::StatusOr<DeformedSpheres> direct = fresh.Update(frame);
  ASSERT_TRUE(direct.ok());
  SphereDeformer used = MakeDeformer(ref);
  for (double t : {0.2, 1.0, 0.9}) {
    ASSERT_TRUE(used.Update(sequences::Deform(ref.mesh.vertices, DeformationKind::kBend, t)).ok());
  }
  absl::StatusOr<DeformedSpheres> after = used.Update(frame);
  ASSERT_TRUE(after.ok());
  ASSERT_EQ(after->set.size(), direct->set.size());
  for (std::size_t i = 0; i < direct->set.size(); ++i) {
    EXPECT_EQ(after->set.spheres[i].center, direct->set.spheres[i].center) << i;
    EXPECT_EQ(after->set.spheres[i].radius, direct->set.spheres[i].radius) << i;
  }
}

}  // namespace
}  // namespace inscribe
