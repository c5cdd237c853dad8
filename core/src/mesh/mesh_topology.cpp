#include "mesh/mesh_topology.h"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace inscribe::internal {

namespace {

bool UseOrder(const EdgeUse& x, const EdgeUse& y) {
  return std::tie(x.lo, x.hi, x.triangle, x.side) < std::tie(y.lo, y.hi, y.triangle, y.side);
}

// Buckets of one lo vertex longer than this are sorted by comparison, not by insertion.
constexpr std::size_t kInsertionSortLimit = 32;

}  // namespace

std::vector<EdgeUse> SortedEdgeUses(const Mesh& mesh) {
  auto use_of = [&mesh](Eigen::Index t, int k) {
    const std::int32_t a = mesh.triangles(t, k);
    const std::int32_t b = mesh.triangles(t, (k + 1) % 3);
    return EdgeUse{std::min(a, b), std::max(a, b), static_cast<std::int32_t>(t),
                   static_cast<std::int8_t>(k), a < b};
  };
  // Uses come in (triangle, side) order, so a stable order by (lo, hi) is the full order: a
  // counting sort by lo straight from the triangles, then each vertex's few uses by hi.
  const std::int64_t vertices = mesh.num_vertices();
  std::vector<std::size_t> start(static_cast<std::size_t>(vertices) + 1, 0);
  bool in_range = true;
  for (Eigen::Index t = 0; t < mesh.triangles.rows() && in_range; ++t) {
    if (!HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const EdgeUse use = use_of(t, k);
      in_range = in_range && use.lo >= 0 && use.hi < vertices;
      if (in_range) ++start[static_cast<std::size_t>(use.lo) + 1];
    }
  }
  if (!in_range) {  // indices not validated: compare instead
    std::vector<EdgeUse> uses;
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      if (!HasDistinctCorners(mesh, t)) continue;
      for (int k = 0; k < 3; ++k) uses.push_back(use_of(t, k));
    }
    std::sort(uses.begin(), uses.end(), UseOrder);
    return uses;
  }
  for (std::size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
  std::vector<EdgeUse> uses(start.back());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      if (!HasDistinctCorners(mesh, t)) continue;
      for (int k = 0; k < 3; ++k) {
        const EdgeUse use = use_of(t, k);
        uses[next[static_cast<std::size_t>(use.lo)]++] = use;
      }
    }
  }
  for (std::size_t v = 0; v + 1 < start.size(); ++v) {
    const auto first = uses.begin() + static_cast<std::ptrdiff_t>(start[v]);
    const auto last = uses.begin() + static_cast<std::ptrdiff_t>(start[v + 1]);
    if (static_cast<std::size_t>(last - first) > kInsertionSortLimit) {
      std::sort(first, last, UseOrder);
      continue;
    }
    for (auto it = first + (first != last); it < last; ++it) {  // stable: by hi only
      const EdgeUse use = *it;
      auto hole = it;
      for (; hole != first && (hole - 1)->hi > use.hi; --hole) *hole = *(hole - 1);
      *hole = use;
    }
  }
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

EdgeGroups GroupEdges(const std::vector<EdgeUse>& uses) {
  EdgeGroups groups;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    groups.ranges.emplace_back(i, j);
    i = j;
  }
  return groups;
}

}  // namespace inscribe::internal
