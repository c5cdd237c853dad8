// Private: edge and component structure of a triangle soup, shared by validation and the
// boundary oracle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "inscribe/geometry/mesh.h"

namespace inscribe::internal {

// One undirected edge and the triangle sides that use it.
struct EdgeUse {
  std::int32_t lo, hi;    // vertex indices, lo < hi
  std::int32_t triangle;  // triangle using it
  std::int8_t side;       // k: the side from corner k to corner (k + 1) % 3
  bool forward;           // true when the triangle walks it lo -> hi
};

// All sides of all triangles with three distinct corners, sorted by (lo, hi, triangle, side)
// so that the uses of one edge are adjacent. Cost O(#T + #V) when every corner is a vertex
// index (a counting sort by lo, then each vertex's uses by hi), O(#T log #T) otherwise.
std::vector<EdgeUse> SortedEdgeUses(const Mesh& mesh);

// The uses of each undirected edge in SortedEdgeUses' output: index ranges [begin, end), one
// per edge, in order.
struct EdgeGroups {
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
};
EdgeGroups GroupEdges(const std::vector<EdgeUse>& uses);

// Disjoint sets with path halving and union by size.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n);
  std::size_t Find(std::size_t x);
  void Union(std::size_t a, std::size_t b);

 private:
  std::vector<std::size_t> parent_;
  std::vector<std::size_t> size_;
};

// True when the triangle's three corners are distinct (regardless of position).
inline bool HasDistinctCorners(const Mesh& mesh, Eigen::Index t) {
  const auto& tri = mesh.triangles;
  return tri(t, 0) != tri(t, 1) && tri(t, 1) != tri(t, 2) && tri(t, 0) != tri(t, 2);
}

}  // namespace inscribe::internal
