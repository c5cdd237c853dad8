#include "inscribe/geometry/mesh_hash.h"

#include <gtest/gtest.h>
#include <openssl/sha.h>

#include <cstring>
#include <regex>
#include <vector>

#include "support/synthetic_meshes.h"

namespace inscribe {
namespace {

// The canonical encoding, written out the slow way from the header's description.
std::vector<unsigned char> CanonicalBytes(const Mesh& mesh) {
  std::vector<unsigned char> bytes;
  const char magic[] = "inscribe.mesh.v1";
  bytes.insert(bytes.end(), magic, magic + 16);
  auto put = [&](std::uint64_t value, int n) {
    for (int i = 0; i < n; ++i) bytes.push_back(static_cast<unsigned char>(value >> (8 * i)));
  };
  put(static_cast<std::uint64_t>(mesh.num_vertices()), 8);
  put(static_cast<std::uint64_t>(mesh.num_triangles()), 8);
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    for (int k = 0; k < 3; ++k) {
      double x = mesh.vertices(v, k) == 0.0 ? 0.0 : mesh.vertices(v, k);
      std::uint64_t bits;
      std::memcpy(&bits, &x, 8);
      put(bits, 8);
    }
  }
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) put(static_cast<std::uint32_t>(mesh.triangles(t, k)), 4);
  }
  return bytes;
}

TEST(MeshSha256, MatchesOneShotDigestOfCanonicalEncoding) {
  for (const Mesh& mesh : {testing::UnitCube(), testing::Icosphere(5)}) {
    const std::vector<unsigned char> bytes = CanonicalBytes(mesh);
    Sha256Digest expected{};
    SHA256(bytes.data(), bytes.size(), expected.data());
    EXPECT_EQ(MeshSha256(mesh), expected);
  }
}

TEST(MeshSha256, FormatIsPrefixedLowercaseHex) {
  const std::string text = FormatSha256(MeshSha256(testing::UnitCube()));
  EXPECT_TRUE(std::regex_match(text, std::regex("sha256:[0-9a-f]{64}"))) << text;
}

TEST(MeshSha256, AnyBitChangesTheDigest) {
  const Mesh cube = testing::UnitCube();
  const Sha256Digest base = MeshSha256(cube);
  Mesh moved = cube;
  moved.vertices(3, 1) = std::nextafter(moved.vertices(3, 1), 2.0);
  EXPECT_NE(MeshSha256(moved), base);
  Mesh reindexed = cube;
  std::swap(reindexed.triangles(0, 1), reindexed.triangles(0, 2));
  EXPECT_NE(MeshSha256(reindexed), base);
}

TEST(MeshSha256, NegativeZeroIsCanonical) {
  Mesh a = testing::UnitCube();
  Mesh b = a;
  b.vertices(0, 0) = -0.0;
  EXPECT_EQ(MeshSha256(a), MeshSha256(b));
}

TEST(MeshSha256, CountsAreHashed) {
  // Same bytes after the header, different split between vertices and triangles: the counts
  // in the header keep them apart.
  Mesh empty;
  empty.vertices.resize(0, 3);
  empty.triangles.resize(0, 3);
  EXPECT_NE(MeshSha256(empty), MeshSha256(testing::UnitCube()));
}

std::vector<Sphere> SomeSpheres() {
  return {Sphere{Vector3(0.0, 1.0, 2.0), 0.5}, Sphere{Vector3(-3.0, 0.25, 1e-300), 2.0},
          Sphere{Vector3(7.0, -8.0, 9.5), 1e-3}};
}

TEST(SpheresSha256, MatchesOneShotDigestOfCanonicalEncoding) {
  const std::vector<Sphere> spheres = SomeSpheres();
  std::vector<unsigned char> bytes;
  const char magic[] = "inscribe.spheres.v1";
  bytes.insert(bytes.end(), magic, magic + 19);
  auto put = [&](std::uint64_t value) {
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<unsigned char>(value >> (8 * i)));
  };
  put(spheres.size());
  for (const Sphere& s : spheres) {
    for (const double x : {s.center.x(), s.center.y(), s.center.z(), s.radius}) {
      std::uint64_t bits;
      std::memcpy(&bits, &x, 8);
      put(bits);
    }
  }
  Sha256Digest expected{};
  SHA256(bytes.data(), bytes.size(), expected.data());
  EXPECT_EQ(SpheresSha256(spheres), expected);
  // Stable: the same spheres, the same digest, and empty lists hash too.
  EXPECT_EQ(SpheresSha256(SomeSpheres()), SpheresSha256(spheres));
  EXPECT_NE(SpheresSha256({}), SpheresSha256(spheres));
}

TEST(SpheresSha256, AnyCoordinateRadiusOrderOrCountChangesTheDigest) {
  const std::vector<Sphere> base = SomeSpheres();
  const Sha256Digest digest = SpheresSha256(base);
  for (std::size_t i = 0; i < base.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      std::vector<Sphere> changed = base;
      double& x = k < 3 ? changed[i].center[k] : changed[i].radius;
      x = std::nextafter(x, 1e9);
      EXPECT_NE(SpheresSha256(changed), digest) << "sphere " << i << " number " << k;
    }
  }
  std::vector<Sphere> swapped = base;
  std::swap(swapped[0], swapped[2]);
  EXPECT_NE(SpheresSha256(swapped), digest);
  std::vector<Sphere> dropped = base;
  dropped.pop_back();
  EXPECT_NE(SpheresSha256(dropped), digest);
  // -0.0 and +0.0 are the same sphere.
  std::vector<Sphere> negative_zero = base;
  negative_zero[0].center.x() = -0.0;
  EXPECT_EQ(SpheresSha256(negative_zero), digest);
}

}  // namespace
}  // namespace inscribe
