// The one inside test of a solid against the winding number by brute force
// (support/winding_oracle.h), on assemblies built to break it (support/adversarial_assemblies.h):
// a cavity in either orientation among 300 other shells, overlapping bodies with a shell
// touching at one vertex, a shell poking out of another, nested shells, shells 1e-9 apart,
// coordinates near 1e5, a plate 1e-3 thick, collinear triangles, a shell flat to within
// rounding, overlapping icospheres. Inside is where the winding number of the shells as meant
// is nonzero (a cavity subtracts, an overlap stays inside); at every sampled point that the
// brute force can decide, Solid::oracle must agree (ClassifyAll), and validation must have
// oriented the shells as meant (the winding number of Solid::mesh() is nonzero at the same
// points). About 1.2 million points in all. The sphere sets, covers and distance intervals of
// such solids: adversarial_spheres_test.cpp.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "inscribe/solid/solid.h"
#include "support/adversarial_assemblies.h"
#include "support/synthetic_meshes.h"
#include "support/winding_oracle.h"

namespace inscribe {
namespace {

using testing::Assembly;
using testing::WindingOracle;
using testing::WindingSample;

// How many points the validated mesh's own winding number is computed at: every kOrientStride-th
// one (it checks orientation, which a fraction of the points already pins down).
constexpr int kOrientStride = 4;

struct Tally {
  std::int64_t checked = 0;        // points the brute force decided
  std::int64_t skipped = 0;        // too close to a triangle for it
  std::int64_t misclassified = 0;  // Classify disagrees with the shells as meant
  std::int64_t misoriented = 0;    // the validated mesh's winding disagrees with them
  std::int64_t inside = 0;         // of the checked points
  std::string examples;            // the first few disagreements
};

std::string Describe(const Vector3& p, const WindingSample& meant, Side side) {
  std::ostringstream out;
  out.precision(17);
  out << "  (" << p.x() << ", " << p.y() << ", " << p.z() << "): winding " << meant.winding
      << " (sum " << meant.raw << "), Classify "
      << (side == Side::kInside    ? "inside"
          : side == Side::kOutside ? "outside"
                                   : "on boundary")
      << "\n";
  return out.str();
}

Tally Classify(const Assembly& assembly, const Solid& solid, const Vertices& points) {
  const WindingOracle meant(assembly.intended);
  const WindingOracle validated(solid.mesh());
  const std::vector<WindingSample> truth = meant.AtAll(points);
  Vertices strided((points.rows() + kOrientStride - 1) / kOrientStride, 3);
  for (Eigen::Index i = 0; i < strided.rows(); ++i) strided.row(i) = points.row(i * kOrientStride);
  const std::vector<WindingSample> own = validated.AtAll(strided);
  const std::vector<Side> sides = solid.oracle.ClassifyAll(points);
  Tally tally;
  int shown = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (!truth[i].reliable) {
      ++tally.skipped;
      continue;
    }
    ++tally.checked;
    const bool inside = truth[i].inside();
    tally.inside += inside;
    const Vector3 p = points.row(static_cast<Eigen::Index>(i)).transpose();
    if (sides[i] != (inside ? Side::kInside : Side::kOutside)) {
      ++tally.misclassified;
      if (shown++ < 5) tally.examples += Describe(p, truth[i], sides[i]);
    }
    if (i % kOrientStride == 0) {
      const WindingSample& w = own[i / kOrientStride];
      if (w.reliable && w.inside() != inside) ++tally.misoriented;
    }
  }
  return tally;
}

// Classify of `solid` (prepared from assembly.input) at `uniform` + `focused` + `near_wall`
// points (AssemblyPoints) against the shells as meant.
Tally ExpectClassifiedAsMeant(const Assembly& assembly, const Solid& solid, int uniform,
                              int focused, int near_wall, std::uint64_t seed) {
  const Vertices points = testing::AssemblyPoints(assembly, uniform, focused, near_wall, seed);
  const Tally tally = Classify(assembly, solid, points);
  EXPECT_EQ(tally.misclassified, 0) << assembly.name << ": " << tally.misclassified << " of "
                                    << tally.checked << " points misclassified, e.g.\n"
                                    << tally.examples;
  EXPECT_EQ(tally.misoriented, 0)
      << assembly.name << ": at " << tally.misoriented
      << " points the validated mesh's winding number disagrees with the shells as meant "
         "(a shell oriented against the nesting rule)";
  // Most points decided, and both sides represented: the sampling means something.
  EXPECT_GT(tally.checked, 9 * (tally.checked + tally.skipped) / 10) << assembly.name;
  EXPECT_GT(tally.inside, tally.checked / 20) << assembly.name;
  EXPECT_LT(tally.inside, tally.checked - tally.checked / 20) << assembly.name;
  std::printf("[ points   ] %s: %lld checked (%lld inside), %lld skipped as too close\n",
              assembly.name.c_str(), static_cast<long long>(tally.checked),
              static_cast<long long>(tally.inside), static_cast<long long>(tally.skipped));
  ::testing::Test::RecordProperty("points_checked", std::to_string(tally.checked));
  return tally;
}

TEST(WindingOracle, CountsShellsAndNesting) {
  const WindingOracle nested(testing::NestedShells(false).intended);
  EXPECT_EQ(nested.shells(), 4);
  const double at[] = {1.75, 1.25, 0.75, 0.25, 2.5};
  const int expected[] = {1, 0, 1, 0, 0};
  for (int i = 0; i < 5; ++i) {
    const WindingSample w = nested.At(Vector3(at[i], 0.1, -0.2));
    EXPECT_TRUE(w.reliable) << at[i];
    EXPECT_EQ(w.winding, expected[i]) << at[i];
  }
  // Overlap: winding 2, still inside; a point on a face is not decided.
  const WindingOracle twins(testing::OffsetTwinBoxes().intended);
  EXPECT_EQ(twins.At(Vector3::Constant(0.5)).winding, 2);
  EXPECT_FALSE(twins.At(Vector3(0.5, 0.5, 0.0)).reliable);
  EXPECT_TRUE(twins.At(Vector3(0.5, 0.5, 5e-10)).reliable);
  EXPECT_EQ(twins.At(Vector3(0.5, 0.5, 5e-10)).winding, 1);
  // An inside-out shell counts -1.
  const WindingOracle inverted(testing::Inverted(testing::UnitCube()));
  EXPECT_EQ(inverted.At(Vector3::Constant(0.5)).winding, -1);
}

TEST(WindingOracle, DistanceMatchesBoxDistance) {
  const WindingOracle cube(testing::UnitCube());
  EXPECT_DOUBLE_EQ(cube.Distance(Vector3(0.5, 0.5, 0.25)), 0.25);
  EXPECT_DOUBLE_EQ(cube.Distance(Vector3(2.0, 0.5, 0.5)), 1.0);
  EXPECT_NEAR(cube.Distance(Vector3(2.0, 2.0, 2.0)), std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(cube.Distance(Vector3(-1.0, -1.0, 0.5)), std::sqrt(2.0), 1e-15);
  // A zero-area triangle is as far as its nearest side.
  const std::array<long double, 3> a{0, 0, 0}, b{1, 0, 0}, m{0.5, 0, 0}, p{0.5, 3, 4};
  EXPECT_NEAR(static_cast<double>(testing::PointTriangleDistanceSquared(p, a, b, m)), 25.0, 1e-15);
}

TEST(AdversarialSolids, HollowBoxAmong300ShellsCavityGivenInward) {
  const Assembly assembly = testing::HollowBoxWithDebris(true);
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_EQ(solid->report.components, 302);
  ExpectClassifiedAsMeant(assembly, *solid, 60'000, 60'000, 30'000, 1);
}

TEST(AdversarialSolids, HollowBoxAmong300ShellsCavityGivenOutward) {
  const Assembly assembly = testing::HollowBoxWithDebris(false);
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_EQ(solid->report.components, 302);
  ExpectClassifiedAsMeant(assembly, *solid, 60'000, 60'000, 30'000, 2);
}

TEST(AdversarialSolids, OverlappingBoxesWithTetrahedronOnACorner) {
  const Assembly assembly = testing::OverlapWithTouchingTetrahedron();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_EQ(solid->report.components, 3);
  EXPECT_EQ(solid->report.non_manifold_vertices, 1);
  ExpectClassifiedAsMeant(assembly, *solid, 40'000, 40'000, 20'000, 3);
}

// The tetrahedron's corners 0 and 1 lie inside the box, 2 and 3 outside: a nesting test that
// looks at some corners only may take it for a cavity of the box.
TEST(AdversarialSolids, TetrahedronPokingOutOfABox) {
  const Assembly assembly = testing::TetrahedronPokingOutOfABox();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_GT(solid->report.self_intersecting_pairs, 0);
  ExpectClassifiedAsMeant(assembly, *solid, 20'000, 30'000, 10'000, 15);
}

TEST(AdversarialSolids, NestedShellsGivenOutward) {
  const Assembly assembly = testing::NestedShells(false);
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 30'000, 40'000, 10'000, 4);
}

TEST(AdversarialSolids, NestedShellsGivenInsideOut) {
  const Assembly assembly = testing::NestedShells(true);
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 30'000, 40'000, 10'000, 5);
}

TEST(AdversarialSolids, OverlappingTwinBoxes1e9Apart) {
  const Assembly assembly = testing::OffsetTwinBoxes();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 30'000, 60'000, 10'000, 6);
}

TEST(AdversarialSolids, HollowBoxWith1e9Walls) {
  const Assembly assembly = testing::HairlineHollowBox();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 30'000, 60'000, 10'000, 7);
}

TEST(AdversarialSolids, NestedShellsTranslatedBy1e5) {
  const Assembly assembly =
      testing::TranslatedAssembly(testing::NestedShells(false), Vector3(1e5, -1e5, 1e5));
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 20'000, 30'000, 10'000, 8);
}

TEST(AdversarialSolids, OverlapWithTouchingTetrahedronTranslatedBy1e5) {
  const Assembly assembly = testing::TranslatedAssembly(testing::OverlapWithTouchingTetrahedron(),
                                                        Vector3(-1e5, 1e5, 1e5));
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 20'000, 30'000, 10'000, 9);
}

TEST(AdversarialSolids, ThinPlate) {
  const Assembly assembly = testing::ThinPlate();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 10'000, 50'000, 10'000, 10);
}

TEST(AdversarialSolids, BoxWithCollinearTriangles) {
  const Assembly assembly = testing::BoxWithCollinearTriangles();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  EXPECT_EQ(solid->report.degenerate_triangles, 5);
  ExpectClassifiedAsMeant(assembly, *solid, 20'000, 50'000, 10'000, 11);
}

TEST(AdversarialSolids, SliverTetrahedronBesideABox) {
  const Assembly assembly = testing::SliverTetrahedronBesideABox();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 20'000, 30'000, 10'000, 16);
}

TEST(AdversarialSolids, OverlappingIcospheres) {
  const Assembly assembly = testing::OverlappingIcospheres();
  const absl::StatusOr<Solid> solid = PrepareSolid(assembly.input);
  ASSERT_TRUE(solid.ok()) << solid.status();
  ExpectClassifiedAsMeant(assembly, *solid, 10'000, 15'000, 5'000, 12);
}

// The checks above have teeth: a solid whose cavity kept the orientation it was given (as when
// nesting went unchecked above 256 components) and the pseudonormal test on overlapping bodies
// (wrong near the buried faces) are both caught.
TEST(AdversarialSolids, CatchMisorientedCavityAndPseudonormalOnOverlaps) {
  const Assembly hollow = testing::HollowBoxWithDebris(false);
  ValidatedMesh as_given = ValidateMesh(hollow.input);
  as_given.mesh = hollow.input;
  absl::StatusOr<Solid> unfixed = MakeSolid(std::move(as_given));
  ASSERT_TRUE(unfixed.ok()) << unfixed.status();
  const Tally cavity = Classify(hollow, *unfixed, testing::AssemblyPoints(hollow, 0, 5'000, 0, 13));
  EXPECT_GT(cavity.misclassified, 500);
  EXPECT_GT(cavity.misoriented, 100);

  for (const Assembly& overlap :
       {testing::OverlapWithTouchingTetrahedron(), testing::OverlappingIcospheres()}) {
    absl::StatusOr<Solid> solid = PrepareSolid(overlap.input);
    ASSERT_TRUE(solid.ok()) << solid.status();
    BoundaryOracleOptions options;
    options.inside_test = InsideTest::kPseudonormal;
    absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(solid->mesh(), options);
    ASSERT_TRUE(oracle.ok()) << oracle.status();
    const Solid fast{solid->report, solid->sha256, *std::move(oracle)};
    const Tally tally = Classify(overlap, fast, testing::AssemblyPoints(overlap, 0, 5'000, 0, 14));
    EXPECT_GT(tally.misclassified, 0) << overlap.name;
    EXPECT_EQ(tally.misoriented, 0) << overlap.name;
  }
}

}  // namespace
}  // namespace inscribe
