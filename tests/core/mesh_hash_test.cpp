#include "inscribe/mesh_hash.h"

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

}  // namespace
}  // namespace inscribe
