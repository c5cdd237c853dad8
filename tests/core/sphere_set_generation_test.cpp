// GenerateSphereSet, the one pipeline: the same set and figures, bit for bit, as its stages
// called by hand (the slow obvious path); defaults and checks in one place; cancellation.
#include "inscribe/generation/sphere_set_generation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <string>

#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

using ::testing::HasSubstr;

Solid MakeSolidOf(const Mesh& mesh) {
  absl::StatusOr<Solid> solid = PrepareSolid(mesh);
  EXPECT_TRUE(solid.ok()) << solid.status();
  return *std::move(solid);
}

void ExpectSameSet(const SphereSet& a, const SphereSet& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.contacts.size(), b.contacts.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.spheres[i].center, b.spheres[i].center) << i;
    EXPECT_EQ(a.spheres[i].radius, b.spheres[i].radius) << i;
  }
  for (std::size_t i = 0; i < a.contacts.size(); ++i) {
    EXPECT_EQ(a.contacts[i].triangle, b.contacts[i].triangle) << i;
    EXPECT_EQ(a.contacts[i].barycentric, b.contacts[i].barycentric) << i;
  }
}

// The stages by hand: sigma or the budget search, then dilation, then evaluation.
struct ByHand {
  SphereSet set;
  double voxel_size = 0.0;
  int runs = 0;
  QualityReport quality;
};

ByHand RunByHand(const Solid& solid, const SphereSetParameters& p) {
  ByHand out;
  MedialSphereResult medial;
  if (p.voxel_size) {
    MedialSphereOptions options = p.medial;
    options.voxel_size = *p.voxel_size;
    absl::StatusOr<MedialSphereResult> run = GenerateMedialSpheres(solid.oracle, options);
    EXPECT_TRUE(run.ok()) << run.status();
    medial = *std::move(run);
    out.runs = 1;
  } else if (p.selection == SphereSelection::kOptimised) {
    OptimisedSphereOptions optimised;
    optimised.max_spheres = p.max_spheres.value_or(kDefaultMaxSpheres);
    optimised.base = p.medial;
    absl::StatusOr<OptimisedSphereResult> chosen =
        GenerateOptimisedSpheres(solid.oracle, optimised);
    EXPECT_TRUE(chosen.ok()) << chosen.status();
    medial = std::move(chosen->best);
    out.runs = chosen->runs;
  } else {
    SphereBudgetOptions budget;
    budget.max_spheres = p.max_spheres.value_or(kDefaultMaxSpheres);
    budget.base = p.medial;
    absl::StatusOr<SphereBudgetResult> found = GenerateWithSphereBudget(solid.oracle, budget);
    EXPECT_TRUE(found.ok()) << found.status();
    medial = std::move(found->best);
    out.runs = found->runs;
  }
  out.set = medial.set;
  out.voxel_size = medial.voxel_size;
  if (p.kind == SphereSetKind::kDilated) {
    absl::StatusOr<DilationResult> dilated = DilateSpheres(solid.oracle, out.set, p.dilation);
    EXPECT_TRUE(dilated.ok()) << dilated.status();
    out.set = dilated->set;
  }
  QualityOptions quality = p.quality;
  quality.voxel_size = out.voxel_size;
  absl::StatusOr<QualityReport> report = EvaluateSpheres(solid.oracle, out.set.spheres, quality);
  EXPECT_TRUE(report.ok()) << report.status();
  out.quality = *report;
  return out;
}

void ExpectPipelineEqualsStages(const Solid& solid, const SphereSetParameters& p) {
  absl::StatusOr<GeneratedSphereSet> g = GenerateSphereSet(solid, p);
  ASSERT_TRUE(g.ok()) << g.status();
  const ByHand hand = RunByHand(solid, p);
  ExpectSameSet(g->set, hand.set);
  EXPECT_EQ(g->voxel_size, hand.voxel_size);
  EXPECT_EQ(g->runs, hand.runs);
  EXPECT_EQ(g->dilation.has_value(), p.kind == SphereSetKind::kDilated);
  EXPECT_EQ(g->kind, p.kind);
  EXPECT_EQ(g->set.has_contacts(), p.kind == SphereSetKind::kInternal);
  ASSERT_TRUE(g->quality.has_value());
  EXPECT_EQ(g->quality->nerr, hand.quality.nerr);
  EXPECT_EQ(g->quality->volume_union, hand.quality.volume_union);
  EXPECT_EQ(g->quality->coverage, hand.quality.coverage);
  EXPECT_EQ(g->quality->surface_samples, p.quality.surface_samples);
  EXPECT_GT(g->epsilon, 0.0);
  EXPECT_GE(g->seconds, g->generation_seconds);
  EXPECT_GT(g->stats.visited_voxels, 0);
}

// (A sphere's medial axis is a point: a budget search on it refines to the voxel limit, so
// budgets are tried on a box.)
TEST(GenerateSphereSet, EqualsItsStagesOnASphereAndABox) {
  SphereSetParameters by_size;
  by_size.voxel_size = 0.3;
  by_size.quality.surface_samples = 2000;
  ExpectPipelineEqualsStages(MakeSolidOf(testing::Icosphere(3)), by_size);
  const Solid solid = MakeSolidOf(testing::Box(Vector3::Zero(), Vector3(4, 2, 1)));
  SphereSetParameters dilated;
  dilated.max_spheres = 40;
  dilated.kind = SphereSetKind::kDilated;
  dilated.dilation.growth = 0.5;
  dilated.quality.surface_samples = 2000;
  ExpectPipelineEqualsStages(solid, dilated);
}

TEST(GenerateSphereSet, EqualsItsStagesOnRealMeshes) {
  for (const std::string name : {"eight.off", "fandisk.off"}) {
    SCOPED_TRACE(name);
    if (testing::TestMeshPath(name).empty()) GTEST_SKIP() << name << " missing";
    const Solid solid = MakeSolidOf(testing::LoadTestMesh(name));
    SphereSetParameters budget;
    budget.max_spheres = 90;
    budget.medial.subdivide_boundary = true;
    budget.quality.surface_samples = 5000;
    for (SphereSelection selection : {SphereSelection::kPaper, SphereSelection::kOptimised}) {
      budget.selection = selection;
      ExpectPipelineEqualsStages(solid, budget);
    }
    SphereSetParameters dilated;
    dilated.voxel_size = 0.1;
    dilated.kind = SphereSetKind::kDilated;
    dilated.quality.surface_samples = 5000;
    ExpectPipelineEqualsStages(solid, dilated);
  }
}

TEST(GenerateSphereSet, NeitherSizeNorBudgetMeansTheDefaultBudget) {
  SphereSetParameters none;
  EXPECT_EQ(EffectiveMaxSpheres(none), kDefaultMaxSpheres);
  none.voxel_size = 0.5;
  EXPECT_FALSE(EffectiveMaxSpheres(none).has_value());
  const Solid solid = MakeSolidOf(testing::Box(Vector3::Zero(), Vector3(4, 2, 1)));
  SphereSetParameters defaults;
  defaults.evaluate = false;
  absl::StatusOr<GeneratedSphereSet> g = GenerateSphereSet(solid, defaults);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_LE(g->set.size(), static_cast<std::size_t>(kDefaultMaxSpheres));
  EXPECT_EQ(g->selection, kDefaultSphereSelection);
  EXPECT_GE(g->runs, 1);
  EXPECT_FALSE(g->quality.has_value());
}

TEST(GenerateSphereSet, BadParametersAreRefusedNamingTheField) {
  const struct {
    void (*set)(SphereSetParameters&);
    const char* mentions;
  } cases[] = {
      {[](SphereSetParameters& p) { p.voxel_size = 0.1, p.max_spheres = 10; }, "not both"},
      {[](SphereSetParameters& p) { p.voxel_size = -1.0; }, "voxel size"},
      {[](SphereSetParameters& p) { p.voxel_size = std::nan(""); }, "voxel size"},
      {[](SphereSetParameters& p) { p.max_spheres = 0; }, "sphere budget"},
      {[](SphereSetParameters& p) { p.medial.object_angle = 4.0; }, "object angle"},
      {[](SphereSetParameters& p) { p.medial.epsilon = -1.0; }, "epsilon"},
      {[](SphereSetParameters& p) { p.medial.samples = 1; }, "samples per voxel"},
      {[](SphereSetParameters& p) { p.medial.screen_samples = 5000; }, "screening samples"},
      {[](SphereSetParameters& p) { p.medial.pair_angle_margin = -0.1; }, "pair-angle margin"},
      {[](SphereSetParameters& p) { p.medial.max_voxels = 0; }, "voxel limit"},
      {[](SphereSetParameters& p) { p.kind = SphereSetKind::kDilated, p.dilation.growth = 1.5; },
       "growth"},
      {[](SphereSetParameters& p) { p.quality.surface_samples = -2; }, "surface samples"},
      {[](SphereSetParameters& p) { p.kind = SphereSetKind::kCover, p.voxel_size = 0.1; },
       "not a voxel size"},
      {[](SphereSetParameters& p) { p.max_protrusion = 0.1; }, "max_protrusion"},
      {[](SphereSetParameters& p) { p.kind = SphereSetKind::kDilated, p.max_protrusion = 0.1; },
       "dilated spheres"},
      {[](SphereSetParameters& p) {
         p.kind = SphereSetKind::kCover, p.max_spheres = 10, p.max_protrusion = 0.1;
       },
       "not both"},
      {[](SphereSetParameters& p) { p.kind = SphereSetKind::kCover, p.max_protrusion = -1.0; },
       "max_protrusion"},
      {[](SphereSetParameters& p) {
         p.kind = SphereSetKind::kCover, p.max_protrusion = std::nan("");
       },
       "max_protrusion"},
      {[](SphereSetParameters& p) { p.kind = SphereSetKind::kCover, p.cover_resolution = 0.0; },
       "resolution"},
      {[](SphereSetParameters& p) { p.kind = SphereSetKind::kCover, p.cover_resolution = 2.0; },
       "resolution"},
  };
  const Solid solid = MakeSolidOf(testing::UnitCube());
  for (const auto& c : cases) {
    SphereSetParameters p;
    c.set(p);
    const absl::Status checked = CheckSphereSetParameters(p);
    EXPECT_EQ(checked.code(), absl::StatusCode::kInvalidArgument) << c.mentions;
    EXPECT_THAT(checked.message(), HasSubstr(c.mentions));
    EXPECT_EQ(GenerateSphereSet(solid, p).status(), checked);
  }
  // Growth is not checked without dilation, the certificate's resolution without a cover,
  // nor quality options without evaluation.
  SphereSetParameters unused;
  unused.dilation.growth = 7.0;
  unused.cover_resolution = -1.0;
  unused.evaluate = false;
  unused.quality.surface_samples = -1;
  EXPECT_TRUE(CheckSphereSetParameters(unused).ok());
}

// A cover through the pipeline is GenerateCover's, certified, then evaluated like any set.
TEST(GenerateSphereSet, ACoverIsCertifiedAndRecordsItsKind) {
  const Solid solid = MakeSolidOf(testing::Box(Vector3::Zero(), Vector3(4, 2, 1)));
  SphereSetParameters p;
  p.kind = SphereSetKind::kCover;
  p.max_spheres = 40;
  p.cover_resolution = 1.0 / 256;
  p.quality.surface_samples = 2000;
  absl::StatusOr<GeneratedSphereSet> g = GenerateSphereSet(solid, p);
  ASSERT_TRUE(g.ok()) << g.status();
  EXPECT_EQ(g->kind, SphereSetKind::kCover);
  EXPECT_STREQ(SphereSetKindName(g->kind), "cover");
  ASSERT_TRUE(g->cover.has_value());
  EXPECT_TRUE(g->cover->certificate.certified);
  EXPECT_GE(g->cover->certificate.delta, 0.0);
  // 1/256 of the largest side (4), rounded down to a power-of-two division of the cube.
  EXPECT_LE(g->cover->certificate.resolution, 4.0 / 256);
  EXPECT_GE(g->cover->certificate.resolution, 4.0 / 512);
  EXPECT_TRUE(g->cover->set.spheres.empty());
  EXPECT_FALSE(g->dilation.has_value());
  EXPECT_FALSE(g->set.has_contacts());

  absl::StatusOr<GeneratedCover> by_hand = GenerateCover(solid, CoverParametersOf(p));
  ASSERT_TRUE(by_hand.ok()) << by_hand.status();
  ExpectSameSet(g->set, by_hand->set);
  EXPECT_EQ(g->cover->certificate.delta, by_hand->certificate.delta);
  EXPECT_EQ(g->cover->certificate.cells, by_hand->certificate.cells);

  // Evaluated like any set: every boundary sample lies in the certified union.
  ASSERT_TRUE(g->quality.has_value());
  EXPECT_EQ(g->quality->coverage, 1.0);
  EXPECT_FALSE(g->quality->nerr_is_exact);  // the spheres protrude
  EXPECT_GE(g->seconds, g->generation_seconds);
}

TEST(GenerateSphereSet, ReportsProgressAndStopsWhenCancelled) {
  const Solid solid = MakeSolidOf(testing::Box(Vector3::Zero(), Vector3(4, 2, 1)));
  SphereSetParameters p;
  p.max_spheres = 60;
  p.evaluate = false;
  double last = 0.0;
  GenerationControl control;
  control.on_progress = [&last](double f) {
    EXPECT_GE(f, last);
    last = f;
  };
  ASSERT_TRUE(GenerateSphereSet(solid, p, control).ok());
  EXPECT_EQ(last, 1.0);
  const std::atomic<bool> cancel{true};
  GenerationControl cancelled;
  cancelled.cancel = &cancel;
  EXPECT_EQ(GenerateSphereSet(solid, p, cancelled).status().code(), absl::StatusCode::kCancelled);
}

}  // namespace
}  // namespace inscribe
