#include "inscribe/medial/internal_refinement.h"

#include <gtest/gtest.h>

#include <vector>

#include "inscribe/balls/union_of_balls.h"
#include "inscribe/medial/sphere_selection.h"
#include "inscribe/solid/solid.h"
#include "support/brute_force_closest_point.h"
#include "support/test_meshes.h"
#include "support/winding_oracle.h"

namespace inscribe {
namespace {

using testing::LoadTestMesh;

Solid SolidOf(const char* name) {
  SolidOptions options;
  options.validate.repair.level = MeshRepair::kFill;
  absl::StatusOr<Solid> solid = PrepareSolid(LoadTestMesh(name), options);
  EXPECT_TRUE(solid.ok()) << solid.status();
  return *std::move(solid);
}

std::vector<Sphere> Selected(const Solid& solid, std::int64_t n) {
  OptimisedSphereOptions options;
  options.max_spheres = n;
  absl::StatusOr<OptimisedSphereResult> chosen = GenerateOptimisedSpheres(solid.oracle, options);
  EXPECT_TRUE(chosen.ok()) << chosen.status();
  return chosen->best.set.spheres;
}

TEST(InternalRefinement, StaysInsideByBruteForceAndNeverLosesVolume) {
  for (const char* name : {"eight.off", "cow.off"}) {
    const Solid solid = SolidOf(name);
    const std::vector<Sphere> before = Selected(solid, 64);
    InternalRefinementOptions options;
    options.iterations = 10;
    absl::StatusOr<InternalRefinement> refined =
        RefineInternalSpheres(solid.oracle, before, options);
    ASSERT_TRUE(refined.ok()) << refined.status();
    ASSERT_EQ(refined->spheres.size(), before.size());
    EXPECT_GE(refined->volume_after, refined->volume_before) << name;
    EXPECT_GT(refined->accepted, 0) << name;
    EXPECT_DOUBLE_EQ(refined->volume_before, *UnionVolume(before));
    EXPECT_DOUBLE_EQ(refined->volume_after, *UnionVolume(refined->spheres));
    const testing::WindingOracle winding(solid.mesh());
    for (std::size_t i = 0; i < before.size(); ++i) {
      const Sphere& b = refined->spheres[i];
      const testing::WindingSample w = winding.At(b.center);
      EXPECT_TRUE(w.reliable && w.inside()) << name << " sphere " << i;
      EXPECT_LE(b.radius, testing::BruteForceDistance(solid.mesh(), b.center))
          << name << " sphere " << i;
    }
    std::printf("%s: N=%zu volume %.9g -> %.9g (%d of %d steps)\n", name, before.size(),
                refined->volume_before, refined->volume_after, refined->accepted,
                refined->iterations);
  }
}

TEST(InternalRefinement, Deterministic) {
  const Solid solid = SolidOf("eight.off");
  const std::vector<Sphere> before = Selected(solid, 32);
  InternalRefinementOptions options;
  options.iterations = 5;
  absl::StatusOr<InternalRefinement> a = RefineInternalSpheres(solid.oracle, before, options);
  absl::StatusOr<InternalRefinement> b = RefineInternalSpheres(solid.oracle, before, options);
  ASSERT_TRUE(a.ok() && b.ok());
  ASSERT_EQ(a->spheres.size(), b->spheres.size());
  for (std::size_t i = 0; i < a->spheres.size(); ++i) {
    EXPECT_EQ(a->spheres[i].center, b->spheres[i].center);
    EXPECT_EQ(a->spheres[i].radius, b->spheres[i].radius);
  }
}

TEST(InternalRefinement, BadOptionsNameTheField) {
  const Solid solid = SolidOf("eight.off");
  InternalRefinementOptions options;
  options.samples_per_sphere = 4;
  EXPECT_NE(RefineInternalSpheres(solid.oracle, {}, options)
                .status()
                .message()
                .find("samples_per_sphere"),
            std::string::npos);
  options = {};
  options.iterations = -1;
  EXPECT_NE(RefineInternalSpheres(solid.oracle, {}, options).status().message().find("iterations"),
            std::string::npos);
}

}  // namespace
}  // namespace inscribe
