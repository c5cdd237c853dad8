#include "mesh_topology.h"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace inscribe::internal {

std::vector<EdgeUse> SortedEdgeUses(const Mesh& mesh) {
  std::vector<EdgeUse> uses;
  uses.reserve(static_cast<std::size_t>(mesh.num_triangles()) * 3);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = mesh.triangles(t, k);
      const std::int32_t b = mesh.triangles(t, (k + 1) % 3);
      uses.push_back(EdgeUse{std::min(a, b), std::max(a, b), static_cast<std::int32_t>(t),
                             static_cast<std::int8_t>(k), a < b});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return std::tie(x.lo, x.hi, x.triangle, x.side) < std::tie(y.lo, y.hi, y.triangle, y.side);
  });
  return uses;
}

DisjointSets::DisjointSets(std::size_t n) : parent_(n), size_(n, 1) {
  std::iota(parent_.begin(), parent_.end(), std::size_t{0});
}

std::size_t DisjointSets::Find(std::size_t x) {
  while (parent_[x] != x) {
    parent_[x] = parent_[parent_[x]];
    x = parent_[x];
  }
  return x;
}

void DisjointSets::Union(std::size_t a, std::size_t b) {
  a = Find(a);
  b = Find(b);
  if (a == b) return;
  if (size_[a] < size_[b]) std::swap(a, b);
  parent_[b] = a;
  size_[a] += size_[b];
}

}  // namespace inscribe::internal
