// The edge-use order of mesh_topology.h against a plain comparison sort.
#include "mesh/mesh_topology.h"  // private: core/src

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "inscribe/geometry/mesh.h"
#include "support/test_meshes.h"

namespace inscribe {
namespace {

// The slow obvious order: every use of every triangle with distinct corners, compared whole.
std::vector<internal::EdgeUse> ComparisonSortedEdgeUses(const Mesh& mesh) {
  std::vector<internal::EdgeUse> uses;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = mesh.triangles(t, k);
      const std::int32_t b = mesh.triangles(t, (k + 1) % 3);
      uses.push_back({std::min(a, b), std::max(a, b), static_cast<std::int32_t>(t),
                      static_cast<std::int8_t>(k), a < b});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const internal::EdgeUse& x, const internal::EdgeUse& y) {
    return std::tie(x.lo, x.hi, x.triangle, x.side) < std::tie(y.lo, y.hi, y.triangle, y.side);
  });
  return uses;
}

void ExpectSameUses(const Mesh& mesh) {
  const std::vector<internal::EdgeUse> fast = internal::SortedEdgeUses(mesh);
  const std::vector<internal::EdgeUse> slow = ComparisonSortedEdgeUses(mesh);
  ASSERT_EQ(fast.size(), slow.size());
  for (std::size_t i = 0; i < fast.size(); ++i) {
    ASSERT_EQ(std::tie(fast[i].lo, fast[i].hi, fast[i].triangle, fast[i].side, fast[i].forward),
              std::tie(slow[i].lo, slow[i].hi, slow[i].triangle, slow[i].side, slow[i].forward))
        << "use " << i;
  }
}

TEST(SortedEdgeUses, SameOrderAsTheComparisonSort) {
  for (const char* name : {"eight.off", "fandisk.off", "bunny00.off"}) {
    SCOPED_TRACE(name);
    ExpectSameUses(testing::LoadTestMesh(name));
  }
  // Random soups: repeated and degenerate triangles, a vertex shared by hundreds (its uses
  // sorted by comparison), indices out of range and negative (the comparison fallback).
  std::mt19937_64 rng(3);
  for (int round = 0; round < 6; ++round) {
    SCOPED_TRACE(round);
    Mesh soup;
    soup.vertices.resize(50, 3);
    soup.vertices.setZero();
    std::uniform_int_distribution<std::int32_t> vertex(0, round < 4 ? 49 : 60);
    soup.triangles.resize(900, 3);
    for (Eigen::Index t = 0; t < soup.triangles.rows(); ++t) {
      for (int k = 0; k < 3; ++k)
        soup.triangles(t, k) = t % 3 == 0 ? (k == 0 ? 7 : vertex(rng)) : vertex(rng);
    }
    if (round == 5) soup.triangles(4, 1) = -3;
    ExpectSameUses(soup);
  }
}

}  // namespace
}  // namespace inscribe
