// The repair ladder (MeshRepair): each broken mesh of the corpus usable at the level it needs
// and refused below it; the repaired solid checked against the solid the file means by the
// brute-force winding number of tests/support (no code shared with core); the wrap checked to
// enclose every input triangle and to lie within its reported reach, by sampling against the
// input triangles with the brute-force distance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "inscribe/generation/sphere_file_record.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "support/broken_meshes.h"
#include "support/brute_force_closest_point.h"
#include "support/mesh_issues.h"
#include "support/synthetic_meshes.h"
#include "support/winding_oracle.h"

namespace inscribe {
namespace {

using testing::BrokenMesh;
using testing::BrokenMeshCorpus;
using testing::WindingOracle;

// The wrap's alpha for these small meshes: a twentieth of the diagonal (the default, a
// fiftieth, makes thousands of triangles: TakesItsDefaultsFromTheMeshesSize).
ValidatedMesh Repaired(const Mesh& mesh, MeshRepair level) {
  ValidateOptions options;
  options.repair.level = level;
  options.repair.wrap_alpha = ComputeBoundingBox(mesh.vertices).diagonal() / 20;
  return ValidateMesh(mesh, options);
}

// Points spread over the triangles of `mesh` (`per_triangle` each, fixed seed).
std::vector<Vector3> SurfacePoints(const Mesh& mesh, int per_triangle, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vector3> out;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0)).transpose();
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1)).transpose();
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2)).transpose();
    for (int i = 0; i < per_triangle; ++i) {
      double s = u(rng), r = u(rng);
      if (s + r > 1.0) s = 1.0 - s, r = 1.0 - r;
      out.push_back(a + s * (b - a) + r * (c - a));
    }
  }
  return out;
}

// The fraction of random points of the intended solid's box (grown by a tenth) that the
// repaired solid and the intended one classify differently, among points farther than `margin`
// from both surfaces.
double Disagreement(const Mesh& repaired, const std::vector<Mesh>& intended, double margin) {
  const WindingOracle truth_repaired(repaired);
  std::vector<WindingOracle> parts;
  BoundingBox box = ComputeBoundingBox(intended.front().vertices);
  for (const Mesh& part : intended) {
    parts.emplace_back(part);
    const BoundingBox b = ComputeBoundingBox(part.vertices);
    box.min = box.min.cwiseMin(b.min);
    box.max = box.max.cwiseMax(b.max);
  }
  const Vector3 grow = 0.1 * (box.max - box.min);
  std::mt19937 rng(7);
  int compared = 0, differ = 0;
  for (int i = 0; i < 4000; ++i) {
    Vector3 p;
    for (int k = 0; k < 3; ++k) {
      p[k] =
          std::uniform_real_distribution<double>(box.min[k] - grow[k], box.max[k] + grow[k])(rng);
    }
    if (truth_repaired.Distance(p) < margin) continue;
    bool near = false, inside_intended = false, reliable = true;
    for (const WindingOracle& part : parts) {
      near = near || part.Distance(p) < margin;
      const testing::WindingSample w = part.At(p);
      reliable = reliable && w.reliable;
      inside_intended = inside_intended || w.inside();
    }
    const testing::WindingSample r = truth_repaired.At(p);
    if (near || !reliable || !r.reliable) continue;
    ++compared;
    if (r.inside() != inside_intended) ++differ;
  }
  EXPECT_GT(compared, 1000);
  return compared == 0 ? 1.0 : static_cast<double>(differ) / compared;
}

class CorpusRepair : public ::testing::TestWithParam<int> {};

TEST_P(CorpusRepair, UsableAtTheLevelItNeedsAndAutoAndRefusedBelow) {
  const BrokenMesh entry = BrokenMeshCorpus()[static_cast<std::size_t>(GetParam())];
  SCOPED_TRACE(entry.name);
  const MeshRepair order[] = {MeshRepair::kNone, MeshRepair::kSafe, MeshRepair::kFill,
                              MeshRepair::kWrap};
  for (const MeshRepair level : order) {
    const ValidatedMesh v = Repaired(entry.mesh, level);
    const bool expected =
        level == MeshRepair::kWrap || static_cast<int>(level) >= static_cast<int>(entry.needs);
    EXPECT_EQ(v.report.usable(), expected)
        << MeshRepairName(level) << ": " << v.report.first_error();
    if (!v.report.usable()) {
      // A refusal names the option that makes the mesh usable.
      EXPECT_NE(v.report.first_error().find("--repair"), std::string::npos)
          << MeshRepairName(level) << ": " << v.report.first_error();
    }
  }
  // auto stops at the mildest level that works: the wrap only when nothing milder does.
  const ValidatedMesh automatic = Repaired(entry.mesh, MeshRepair::kAuto);
  ASSERT_TRUE(automatic.report.usable()) << automatic.report.first_error();
  EXPECT_EQ(automatic.report.wrapped, entry.needs == MeshRepair::kWrap);
  EXPECT_EQ(automatic.report.holes_filled > 0, entry.needs == MeshRepair::kFill);
  // Every change is said: the mesh's solid is the file's only without geometry repairs.
  if (entry.needs == MeshRepair::kFill || entry.needs == MeshRepair::kWrap) {
    EXPECT_TRUE(automatic.report.geometry_repaired());
    EXPECT_FALSE(automatic.report.repairs().empty());
  }
  if (!entry.intended.empty()) {
    const BoundingBox box = ComputeBoundingBox(automatic.mesh.vertices);
    EXPECT_EQ(Disagreement(automatic.mesh, entry.intended, 1e-3 * box.diagonal()), 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, CorpusRepair,
                         ::testing::Range(0, static_cast<int>(BrokenMeshCorpus().size())),
                         [](const ::testing::TestParamInfo<int>& param) {
                           return testing::BrokenMeshTestName(param.param);
                         });

// The wrap, checked without core's code: every input triangle's sample points strictly inside
// the wrap (brute-force winding number), every wrap surface sample within the reported reach of
// the input triangles (brute-force distance), and the reach about the offset.
TEST(Wrap, EnclosesTheInputAndLiesWithinItsReach) {
  for (const BrokenMesh& entry : BrokenMeshCorpus()) {
    SCOPED_TRACE(entry.name);
    const ValidatedMesh v = Repaired(entry.mesh, MeshRepair::kWrap);
    ASSERT_TRUE(v.report.usable()) << v.report.first_error();
    ASSERT_TRUE(v.report.wrapped);
    EXPECT_TRUE(v.report.closed());
    EXPECT_GT(v.report.wrap_offset, 0.0);
    EXPECT_EQ(v.report.wrap_offset, DefaultWrapOffset(v.report.wrap_alpha));
    EXPECT_GE(v.report.wrap_reach, v.report.wrap_offset * 0.5);
    EXPECT_LE(v.report.wrap_reach, 4.0 * (v.report.wrap_alpha + v.report.wrap_offset));
    const WindingOracle wrap(v.mesh);
    for (const Vector3& p : SurfacePoints(entry.mesh, 8, 11)) {
      const testing::WindingSample w = wrap.At(p);
      ASSERT_TRUE(w.reliable) << p.transpose();
      ASSERT_TRUE(w.inside()) << p.transpose();
    }
    double farthest = 0.0;
    for (const Vector3& p : SurfacePoints(v.mesh, 2, 13)) {
      farthest = std::max(farthest, testing::BruteForceDistance(entry.mesh, p));
    }
    EXPECT_LE(farthest, v.report.wrap_reach);
    // The report keeps the input's counts and says what was done.
    EXPECT_EQ(v.report.triangles, entry.mesh.num_triangles());
    EXPECT_EQ(v.report.wrap_triangles, v.mesh.num_triangles());
    EXPECT_TRUE(testing::HasIssue(v.report, "wrapped", Severity::kFixed));
    EXPECT_TRUE(v.report.geometry_repaired());
  }
}

// An internal set of a wrapped mesh reaches past the input surface by at most the recorded
// protrusion_input: every point of its spheres (centres and 60 surface points each) is inside
// the intended solid (brute-force winding number) or within protrusion_input of an input
// triangle (brute-force distance).
TEST(Wrap, InternalSetsReachPastTheInputByAtMostTheirBound) {
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  int checked = 0;
  const std::vector<BrokenMesh> corpus = BrokenMeshCorpus();
  for (std::size_t e = 0; e < corpus.size(); ++e) {
    const BrokenMesh& entry = corpus[e];
    // Every other entry with a known solid (the suite's time), those needing a repair first.
    if (entry.intended.empty() || (entry.needs == MeshRepair::kNone && e % 2 == 1)) continue;
    SCOPED_TRACE(entry.name);
    absl::StatusOr<Solid> solid = MakeSolid(Repaired(entry.mesh, MeshRepair::kWrap));
    ASSERT_TRUE(solid.ok()) << solid.status();
    const std::optional<double> bound = InternalProtrusionOverInput(solid->report);
    ASSERT_TRUE(bound.has_value());
    EXPECT_EQ(*bound, solid->report.wrap_reach);
    SphereSetParameters parameters;
    parameters.max_spheres = 12;
    parameters.evaluate = false;
    absl::StatusOr<GeneratedSphereSet> set = GenerateSphereSet(*solid, parameters);
    ASSERT_TRUE(set.ok()) << set.status();
    const SphereFile file = GenerationSphereFile(parameters, *set, solid->sha256, solid->report);
    bool recorded = false;
    for (const auto& [name, value] : file.stats) {
      if (name == "protrusion_input") recorded = std::get<double>(value) == *bound;
    }
    EXPECT_TRUE(recorded);
    std::vector<WindingOracle> parts(entry.intended.begin(), entry.intended.end());
    for (const Sphere& sphere : set->set.spheres) {
      for (int i = 0; i <= 60; ++i) {
        Vector3 p = sphere.center;
        if (i > 0) {
          const Vector3 d(normal(rng), normal(rng), normal(rng));
          p += sphere.radius * d.normalized();
        }
        bool inside = false;
        for (const WindingOracle& part : parts) {
          const testing::WindingSample w = part.At(p);
          inside = inside || (w.reliable && w.inside());
        }
        if (inside) continue;
        ++checked;
        EXPECT_LE(testing::BruteForceDistance(entry.mesh, p), *bound * (1 + 1e-12))
            << p.transpose();
      }
    }
  }
  EXPECT_GT(checked, 0);  // points outside the intended solid were met and bounded
  std::printf("[ points   ] %d sphere points outside the intended solids, all bounded\n", checked);
}

TEST(Wrap, TakesItsDefaultsFromTheMeshesSize) {
  const Mesh cup = Repaired(testing::UnitCube(), MeshRepair::kNone).mesh;
  ValidateOptions options;
  options.repair.level = MeshRepair::kWrap;
  const ValidatedMesh v = ValidateMesh(cup, options);
  ASSERT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_EQ(v.report.wrap_alpha, DefaultWrapAlpha(std::sqrt(3.0)));
  EXPECT_EQ(v.report.wrap_offset, DefaultWrapOffset(v.report.wrap_alpha));
  EXPECT_LE(v.report.wrap_reach, v.report.wrap_offset + v.report.wrap_alpha);
}

TEST(Wrap, TakesItsParametersAndRefusesBadOnes) {
  const Mesh sheet = testing::Box(Vector3::Zero(), Vector3(1, 1, 0));
  ValidateOptions options;
  options.repair.level = MeshRepair::kWrap;
  options.repair.wrap_alpha = 0.05;
  options.repair.wrap_offset = 0.01;
  const ValidatedMesh v = ValidateMesh(testing::UnitCube(), options);
  ASSERT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_EQ(v.report.wrap_alpha, 0.05);
  EXPECT_EQ(v.report.wrap_offset, 0.01);
  // The wrap of a cube lies about the offset outside it.
  EXPECT_GT(v.report.volume, 1.0);
  EXPECT_LT(v.report.volume, 1.02 * 1.02 * 1.02 + 1e-3);
  for (const double bad : {-1.0, std::nan(""), HUGE_VAL}) {
    options.repair.wrap_alpha = bad;
    EXPECT_TRUE(testing::HasIssue(ValidateMesh(sheet, options).report, "invalid_wrap_parameters",
                                  Severity::kError))
        << bad;
  }
  options.repair.wrap_alpha = 1e-7;
  EXPECT_TRUE(testing::HasIssue(ValidateMesh(testing::UnitCube(), options).report,
                                "wrap_alpha_too_small", Severity::kError));
}

// The crack weld's tolerance follows the mesh's size, so a millimetre mesh gets the same
// treatment as the same mesh in metres, and never closes a gap wider than a feature.
TEST(CrackWeld, ScalesWithTheMeshAndLeavesWideGapsOpen) {
  const double metres = CrackWeldTolerance(testing::CrackedSphere(2e-5));
  const double millimetres = CrackWeldTolerance(testing::CrackedSphere(2e-2, 1000.0));
  EXPECT_NEAR(millimetres / metres, 1000.0, 1e-6 * 1000.0);
  // A gap of 1e-3 of the size is a feature, not a crack: safe leaves it open and says how to
  // close it.
  const ValidatedMesh wide = Repaired(testing::CrackedSphere(2e-3), MeshRepair::kSafe);
  EXPECT_FALSE(wide.report.usable());
  EXPECT_EQ(wide.report.crack_vertices_welded, 0);
  const ValidatedMesh crack = Repaired(testing::CrackedSphere(2e-6), MeshRepair::kSafe);
  ASSERT_TRUE(crack.report.usable()) << crack.report.first_error();
  EXPECT_GT(crack.report.crack_vertices_welded, 0);
  EXPECT_EQ(crack.report.weld_moved_within, crack.report.crack_weld_tolerance);
  EXPECT_TRUE(crack.report.geometry_repaired());
  EXPECT_TRUE(testing::HasIssue(crack.report, "cracks_welded", Severity::kFixed));
  // Only border vertices move: a closed mesh is never touched by it.
  EXPECT_EQ(Repaired(testing::Icosphere(2), MeshRepair::kSafe).report.crack_weld_tolerance, 0.0);
}

TEST(DoubleWalls, RemovedAsPairsLeavingTheUnion) {
  const ValidatedMesh v = Repaired(testing::BoxesSharingAWall(), MeshRepair::kSafe);
  ASSERT_TRUE(v.report.usable()) << v.report.first_error();
  EXPECT_EQ(v.report.double_walls_removed, 2);
  EXPECT_EQ(v.mesh.num_triangles(), 20);
  EXPECT_TRUE(testing::HasIssue(v.report, "double_walls_removed", Severity::kFixed));
  EXPECT_NEAR(v.report.volume, 2.0, 1e-12);
  // Removing walls changes no point of the solid.
  EXPECT_FALSE(v.report.geometry_repaired());
  // none refuses it and names the remedy.
  const ValidatedMesh refused = Repaired(testing::BoxesSharingAWall(), MeshRepair::kNone);
  EXPECT_FALSE(refused.report.usable());
}

}  // namespace
}  // namespace inscribe
