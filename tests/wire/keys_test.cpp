// The key scheme: keys of sets made before an option existed stay what they were (the literals
// below were computed from the version-1 canonical text by a separate script), every parameter
// changes the key, and a mesh and everything derived from it route alike.
#include "inscribe/wire/keys.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace inscribe::wire {
namespace {

const std::string kMesh =
    "sha256:"
    "0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";

TEST(Keys, GeneratedKeysMatchVersionOneText) {
  SphereSetParameters by_size;
  by_size.voxel_size = 0.1;
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, by_size, MeshRepair::kSafe),
            "spheres/v1/0123456789abcdeff9791a86a7a609b2b9c0cb9cf97e7688efd65e9bf382ee05");

  SphereSetParameters dilated;  // neither given: core's default budget, 500
  dilated.max_spheres = 500;
  dilated.kind = SphereSetKind::kDilated;
  dilated.dilation.growth = 0.5;
  dilated.evaluate = false;
  dilated.selection = SphereSelection::kPaper;  // sets made before the choice existed
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, dilated, MeshRepair::kFill),
            "spheres/v1/0123456789abcdefe4f0ed8ca1ed48e91844bf8870a4bcde1685ca90d28e3de1");
  // Without repair levels a mesh was taken as it was; "none" and "safe" keep that key.
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, by_size, MeshRepair::kNone),
            GeneratedSphereSetKey(kMesh, by_size, MeshRepair::kSafe));
}

TEST(Keys, EveryParameterChangesTheKey) {
  SphereSetParameters base;
  base.max_spheres = 100;
  std::set<std::string> keys;
  const auto add = [&](const SphereSetParameters& p, MeshRepair repair = MeshRepair::kSafe) {
    const std::string key = GeneratedSphereSetKey(kMesh, p, repair);
    EXPECT_EQ(key.size(), std::string("spheres/v1/").size() + 64);
    EXPECT_EQ(RouteKey(key), RouteKey(kMesh));
    keys.insert(key);
  };
  add(base);
  add(base, MeshRepair::kFill);
  add(base, MeshRepair::kWrap);
  add(base, MeshRepair::kAuto);
  SphereSetParameters p = base;
  p.max_spheres = 101;
  add(p);
  p = base;
  p.max_spheres.reset();
  p.voxel_size = 0.25;
  add(p);
  p = base, p.medial.object_angle = 0.5, add(p);
  p = base, p.medial.epsilon = 1e-3, add(p);
  p = base, p.medial.samples = 16, add(p);
  p = base, p.medial.subdivide_boundary = true, add(p);
  p = base, p.medial.screen_samples = 0, add(p);
  p = base, p.medial.corner_screen = false, add(p);
  p = base, p.medial.pair_angle_margin = 0.1, add(p);
  p = base, p.kind = SphereSetKind::kDilated, add(p);
  p = base, p.kind = SphereSetKind::kDilated, p.dilation.growth = 0.0, add(p);
  p = base, p.evaluate = false, add(p);
  p = base, p.quality.surface_samples = 5000, add(p);
  p = base, p.selection = SphereSelection::kPaper, add(p);
  EXPECT_EQ(keys.size(), 18u);
  // Growth means nothing without dilation, nor quality samples without evaluation.
  p = base, p.dilation.growth = 0.3;
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, p, MeshRepair::kSafe),
            GeneratedSphereSetKey(kMesh, base, MeshRepair::kSafe));
  SphereSetParameters unevaluated = base;
  unevaluated.evaluate = false;
  p = unevaluated, p.quality.surface_samples = 7;
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, p, MeshRepair::kSafe),
            GeneratedSphereSetKey(kMesh, unevaluated, MeshRepair::kSafe));
}

TEST(Keys, CoversHaveTheirOwnKeysAndLeaveOthersAlone) {
  SphereSetParameters base;
  base.max_spheres = 100;
  // A cover's settings mean nothing for other kinds: their keys stay the version-1 ones.
  SphereSetParameters unused = base;
  unused.cover_resolution = 1.0 / 64;
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, unused, MeshRepair::kSafe),
            GeneratedSphereSetKey(kMesh, base, MeshRepair::kSafe));
  SphereSetParameters by_size;
  by_size.voxel_size = 0.1;
  by_size.cover_resolution = 1.0 / 64;
  EXPECT_EQ(GeneratedSphereSetKey(kMesh, by_size, MeshRepair::kSafe),
            "spheres/v1/0123456789abcdeff9791a86a7a609b2b9c0cb9cf97e7688efd65e9bf382ee05");

  std::set<std::string> keys = {GeneratedSphereSetKey(kMesh, base, MeshRepair::kSafe)};
  SphereSetParameters cover = base;
  cover.kind = SphereSetKind::kCover;
  keys.insert(GeneratedSphereSetKey(kMesh, cover, MeshRepair::kSafe));
  SphereSetParameters p = cover;
  p.cover_resolution = 1.0 / 64;
  keys.insert(GeneratedSphereSetKey(kMesh, p, MeshRepair::kSafe));
  p = cover;
  p.max_spheres.reset();
  p.max_protrusion = 0.01;
  keys.insert(GeneratedSphereSetKey(kMesh, p, MeshRepair::kSafe));
  p.max_protrusion = 0.02;
  keys.insert(GeneratedSphereSetKey(kMesh, p, MeshRepair::kSafe));
  p = base, p.kind = SphereSetKind::kDilated;
  keys.insert(GeneratedSphereSetKey(kMesh, p, MeshRepair::kSafe));
  EXPECT_EQ(keys.size(), 6u);
  for (const std::string& key : keys) EXPECT_EQ(RouteKey(key), RouteKey(kMesh));
}

TEST(Keys, RoutePrefixTakesLowercaseHexDigitsOfMeshAndSetKeys) {
  EXPECT_EQ(RoutePrefix(kMesh), "0123456789abcdef");
  EXPECT_EQ(RoutePrefix("spheres/v1/0123456789abcdefff"), "0123456789abcdef");
  EXPECT_EQ(RoutePrefix("sha256:0123456789ABCDEF0000"), "");
  EXPECT_EQ(RoutePrefix("sha256:0123"), "");
  EXPECT_EQ(RoutePrefix("hierarchy/v1/sphere/x"), "");
  EXPECT_EQ(RouteKey("other-key"), "other-key");
  EXPECT_EQ(RouteKey(kMesh), "0123456789abcdef");
}

TEST(Keys, UploadedAndDerivedKeys) {
  const std::string with_mesh = UploadedSphereSetKey(kMesh, "", "numbers");
  EXPECT_EQ(RouteKey(with_mesh), RouteKey(kMesh));
  const std::string derived = UploadedSphereSetKey("", with_mesh, "numbers");
  EXPECT_EQ(RouteKey(derived), RouteKey(kMesh));
  EXPECT_NE(derived, with_mesh);
  const std::string alone = UploadedSphereSetKey("", "", "numbers");
  EXPECT_EQ(alone.substr(0, 11), "spheres/v1/");
  EXPECT_EQ(RoutePrefix(alone), alone.substr(11, 16));
  EXPECT_NE(UploadedSphereSetKey("", "", "other numbers"), alone);
  EXPECT_EQ(ContentRouteKey("numbers").size(), kRouteDigits);

  DeformationOptions options;
  const std::string deformer = DeformerKey(kMesh, with_mesh, options);
  EXPECT_EQ(deformer.substr(0, 12), "deformer/v1/");
  EXPECT_EQ(deformer.substr(12, 16), RouteKey(kMesh));
  options.strict = true;
  EXPECT_NE(DeformerKey(kMesh, with_mesh, options), deformer);

  EXPECT_EQ(HierarchyKey(with_mesh, HierarchyVolume::kRss), "hierarchy/v1/rss/" + with_mesh);

  // A certificate uploaded with a set keys it apart; none keeps the key it had.
  EXPECT_EQ(UploadedSphereSetKey(kMesh, "", "numbers", ""), with_mesh);
  const std::string vouched = UploadedSphereSetKey(kMesh, "", "numbers", "certificate");
  EXPECT_NE(vouched, with_mesh);
  EXPECT_EQ(RouteKey(vouched), RouteKey(kMesh));
  EXPECT_NE(UploadedSphereSetKey(kMesh, "", "numbers", "another certificate"), vouched);

  CoverCertifyOptions certify;
  const std::string certificate = CoverCertificateKey(with_mesh, kMesh, certify);
  EXPECT_EQ(certificate.substr(0, 15), "certificate/v1/");
  EXPECT_EQ(certificate.substr(15, 16), RouteKey(kMesh));
  certify.max_failures_kept = 7;  // changes no verdict
  EXPECT_EQ(CoverCertificateKey(with_mesh, kMesh, certify), certificate);
  certify.resolution = 1.0 / 64;
  EXPECT_NE(CoverCertificateKey(with_mesh, kMesh, certify), certificate);
  EXPECT_NE(CoverCertificateKey(derived, kMesh, CoverCertifyOptions()), certificate);
  EXPECT_TRUE(IsMeshKey(kMesh));
  EXPECT_FALSE(IsMeshKey(with_mesh));
  EXPECT_TRUE(IsSphereSetKey(with_mesh));
  EXPECT_FALSE(IsSphereSetKey(kMesh));
}

}  // namespace
}  // namespace inscribe::wire
