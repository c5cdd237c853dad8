#include "solid/mesh_orientation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <iterator>
#include <limits>
#include <utility>

#include "solid/triangle_bvh.h"

namespace inscribe::internal {
namespace {

// The corners of triangle t, relative to `origin`.
std::array<Vector3, 3> CornersFrom(const Mesh& mesh, std::int32_t t, const Vector3& origin) {
  std::array<Vector3, 3> corners;
  for (int k = 0; k < 3; ++k) {
    corners[static_cast<std::size_t>(k)] =
        mesh.vertices.row(mesh.triangles(t, k)).transpose() - origin;
  }
  return corners;
}

double ComponentVolume(const Mesh& mesh, const std::vector<std::int32_t>& triangles,
                       const Vector3& origin) {
  double six_volume = 0.0;
  for (std::int32_t t : triangles) {
    const auto [a, b, c] = CornersFrom(mesh, t, origin);
    six_volume += a.dot(b.cross(c));
  }
  return six_volume / 6.0;
}

// A shell's box.
BoundingBox ShellBox(const Mesh& mesh, const std::vector<std::int32_t>& triangles) {
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::int32_t t : triangles) {
    for (int k = 0; k < 3; ++k) {
      lo = lo.cwiseMin(mesh.vertices.row(mesh.triangles(t, k)).transpose());
      hi = hi.cwiseMax(mesh.vertices.row(mesh.triangles(t, k)).transpose());
    }
  }
  return BoundingBox{lo, hi};
}

// Below this fraction of its box's largest side cubed, a shell is flat: the floating-point
// sign of its volume, and the pseudonormals of its nearly coincident sheets, are not trusted.
constexpr double kFlatVolume = 1e-9;

void FlipTriangle(Mesh& mesh, Eigen::Index t) {
  std::swap(mesh.triangles(t, 1), mesh.triangles(t, 2));
}

// How many other shells enclose each component: shell o encloses c when every vertex of c lies
// strictly inside o (o's winding number around it is not zero, and it lies on no triangle of
// o). Shells that overlap or touch (a self-intersecting union, bodies meeting at a vertex) do
// not enclose; a shell whose vertices are all inside another but whose triangles pass out of
// it intersects it, and is taken as enclosed. Every winding number is exact (XRayCrossing
// along one ray per vertex, crossings added up per component), so the answer holds for any
// number of components. Cost: one ray for a component that no shell holds its first vertex,
// one per vertex while some shell holds all so far; O(#T log #T) for the tree, nothing for a
// single component.
std::vector<int> NestingDepths(const Mesh& mesh, const std::vector<std::int32_t>& component,
                               const std::vector<std::vector<std::int32_t>>& members) {
  std::vector<int> depth(members.size(), 0);
  if (members.size() < 2) return depth;
  const TriangleBvh bvh = TriangleBvh::Build(mesh);
  // Per sample: the components other than `own` whose winding around it is not zero.
  std::vector<std::pair<std::int32_t, int>> crossings;  // (component, crossing)
  auto enclosing = [&](const Vector3& p, std::int32_t own) {
    crossings.clear();
    std::vector<std::int32_t> touching;
    bvh.ForEachXRayCrossing(p, [&](std::int32_t t, int crossing) {
      const std::int32_t c = component[static_cast<std::size_t>(t)];
      if (c < 0 || c == own) return;
      if (crossing == kOnTriangle) {
        touching.push_back(c);
      } else {
        crossings.emplace_back(c, crossing);
      }
    });
    std::sort(crossings.begin(), crossings.end());
    std::sort(touching.begin(), touching.end());
    std::vector<std::int32_t> out;
    for (std::size_t i = 0; i < crossings.size();) {
      std::size_t j = i;
      int winding = 0;
      for (; j < crossings.size() && crossings[j].first == crossings[i].first; ++j) {
        winding += crossings[j].second;
      }
      if (winding != 0 &&
          !std::binary_search(touching.begin(), touching.end(), crossings[i].first)) {
        out.push_back(crossings[i].first);
      }
      i = j;
    }
    return out;  // sorted
  };
  for (std::size_t c = 0; c < members.size(); ++c) {
    const auto own = static_cast<std::int32_t>(c);
    std::vector<std::int32_t> vertices;
    vertices.reserve(3 * members[c].size());
    for (const std::int32_t t : members[c]) {
      for (int k = 0; k < 3; ++k) vertices.push_back(mesh.triangles(t, k));
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    std::vector<std::int32_t> enclosers;
    for (std::size_t n = 0; n < vertices.size(); ++n) {
      const Vector3 p = mesh.vertices.row(vertices[n]).transpose();
      std::vector<std::int32_t> here = enclosing(p, own);
      if (n == 0) {
        enclosers = std::move(here);
      } else {
        std::vector<std::int32_t> both;
        std::set_intersection(enclosers.begin(), enclosers.end(), here.begin(), here.end(),
                              std::back_inserter(both));
        enclosers = std::move(both);
      }
      if (enclosers.empty()) break;
    }
    depth[c] = static_cast<int>(enclosers.size());
  }
  return depth;
}

}  // namespace

bool MakeOrientationConsistent(Mesh& mesh, const std::vector<EdgeUse>& uses,
                               const EdgeGroups& groups, const std::vector<std::int32_t>& component,
                               std::int64_t num_components, std::vector<char>& flip,
                               std::int64_t* non_orientable_triangle) {
  const std::size_t nt = static_cast<std::size_t>(mesh.num_triangles());
  // Adjacency through manifold edges: neighbour and whether the pair currently agrees. A
  // triangle's sides lie on three different edges, so it has at most three neighbours.
  struct Neighbours {
    std::array<std::pair<std::int32_t, bool>, 3> list;
    int count = 0;
  };
  std::vector<Neighbours> adjacent(nt);
  auto add = [&adjacent](std::int32_t t, std::int32_t u, bool agree) {
    Neighbours& n = adjacent[static_cast<std::size_t>(t)];
    n.list[static_cast<std::size_t>(n.count++)] = {u, agree};
  };
  for (const auto& [begin, end] : groups.ranges) {
    if (end - begin != 2) continue;
    const EdgeUse& a = uses[begin];
    const EdgeUse& b = uses[begin + 1];
    const bool agree = a.forward != b.forward;
    add(a.triangle, b.triangle, agree);
    add(b.triangle, a.triangle, agree);
  }
  flip.assign(nt, 0);
  std::vector<char> seen(nt, 0);
  std::vector<std::int64_t> flips_in(static_cast<std::size_t>(num_components), 0);
  std::vector<std::int64_t> size_of(static_cast<std::size_t>(num_components), 0);
  std::deque<std::int32_t> queue;
  for (std::size_t start = 0; start < nt; ++start) {
    if (seen[start] || component[start] < 0) continue;
    seen[start] = 1;
    queue.push_back(static_cast<std::int32_t>(start));
    while (!queue.empty()) {
      const std::int32_t t = queue.front();
      queue.pop_front();
      const auto c = static_cast<std::size_t>(component[static_cast<std::size_t>(t)]);
      ++size_of[c];
      flips_in[c] += flip[static_cast<std::size_t>(t)];
      const Neighbours& neighbours = adjacent[static_cast<std::size_t>(t)];
      for (int i = 0; i < neighbours.count; ++i) {
        const auto [u, agree] = neighbours.list[static_cast<std::size_t>(i)];
        // After flipping, t and u agree iff (agree XOR flip[t] XOR flip[u]).
        const char wanted = static_cast<char>(flip[static_cast<std::size_t>(t)] ^ !agree);
        if (!seen[static_cast<std::size_t>(u)]) {
          seen[static_cast<std::size_t>(u)] = 1;
          flip[static_cast<std::size_t>(u)] = wanted;
          queue.push_back(u);
        } else if (flip[static_cast<std::size_t>(u)] != wanted) {
          *non_orientable_triangle = t;
          return false;
        }
      }
    }
  }
  for (std::size_t t = 0; t < nt; ++t) {
    if (component[t] < 0) continue;
    const auto c = static_cast<std::size_t>(component[t]);
    if (2 * flips_in[c] > size_of[c]) flip[t] ^= 1;  // keep the majority as it is
    if (flip[t]) FlipTriangle(mesh, static_cast<Eigen::Index>(t));
  }
  return true;
}

std::int64_t OrientComponentsOutward(Mesh& mesh, const std::vector<std::int32_t>& component,
                                     std::int64_t num_components, std::vector<char>& flip) {
  std::vector<std::vector<std::int32_t>> members(static_cast<std::size_t>(num_components));
  for (std::size_t t = 0; t < component.size(); ++t) {
    if (component[t] >= 0)
      members[static_cast<std::size_t>(component[t])].push_back(static_cast<std::int32_t>(t));
  }
  const std::vector<int> depth = NestingDepths(mesh, component, members);
  std::int64_t flat = 0;
  for (std::size_t c = 0; c < members.size(); ++c) {
    // About the shell's own centre, so that its rounding is relative to the shell's size.
    const BoundingBox box = ShellBox(mesh, members[c]);
    const double volume = ComponentVolume(mesh, members[c], 0.5 * (box.min + box.max));
    const double side = (box.max - box.min).maxCoeff();
    if (!(std::abs(volume) > kFlatVolume * side * side * side)) ++flat;
    const bool want_positive = depth[c] % 2 == 0;
    if ((volume > 0) != want_positive && volume != 0.0) {
      for (std::int32_t t : members[c]) {
        FlipTriangle(mesh, t);
        flip[static_cast<std::size_t>(t)] ^= 1;
      }
    }
  }
  return flat;
}

}  // namespace inscribe::internal
