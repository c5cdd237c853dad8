#include "mesh_orientation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>

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

// Generalized winding number of the closed surface made of `triangles` at `p`: the sum of the
// signed solid angles / 4 pi (Van Oosterom & Strackee). +-1 inside, 0 outside.
double WindingNumber(const Mesh& mesh, const std::vector<std::int32_t>& triangles,
                     const Vector3& p) {
  double total = 0.0;
  for (std::int32_t t : triangles) {
    const auto [a, b, c] = CornersFrom(mesh, t, p);
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2.0 * std::atan2(numerator, denominator);
  }
  return total / (4.0 * M_PI);
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

void FlipTriangle(Mesh& mesh, Eigen::Index t) {
  std::swap(mesh.triangles(t, 1), mesh.triangles(t, 2));
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

bool OrientComponentsOutward(Mesh& mesh, const std::vector<std::int32_t>& component,
                             std::int64_t num_components, std::vector<char>& flip) {
  std::vector<std::vector<std::int32_t>> members(static_cast<std::size_t>(num_components));
  for (std::size_t t = 0; t < component.size(); ++t) {
    if (component[t] >= 0)
      members[static_cast<std::size_t>(component[t])].push_back(static_cast<std::int32_t>(t));
  }
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const Vector3 origin = 0.5 * (box.min + box.max);
  const bool nesting = num_components <= kMaxComponentsForNesting;
  // Per component: its bounding box and up to kSamples of its vertices, spread over it.
  constexpr std::size_t kSamples = 16;
  std::vector<BoundingBox> boxes(members.size());
  std::vector<std::vector<Vector3>> samples(members.size());
  for (std::size_t c = 0; c < members.size(); ++c) {
    Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::int32_t t : members[c]) {
      for (int k = 0; k < 3; ++k) {
        lo = lo.cwiseMin(mesh.vertices.row(mesh.triangles(t, k)).transpose());
        hi = hi.cwiseMax(mesh.vertices.row(mesh.triangles(t, k)).transpose());
      }
    }
    boxes[c] = BoundingBox{lo, hi};
    const std::size_t step = std::max<std::size_t>(1, members[c].size() / kSamples);
    for (std::size_t i = 0; i < members[c].size() && samples[c].size() < kSamples; i += step) {
      samples[c].push_back(mesh.vertices.row(mesh.triangles(members[c][i], 0)).transpose());
    }
  }
  auto box_inside = [](const BoundingBox& a, const BoundingBox& b) {
    return (a.min.array() >= b.min.array()).all() && (a.max.array() <= b.max.array()).all();
  };
  for (std::size_t c = 0; c < members.size(); ++c) {
    const double volume = ComponentVolume(mesh, members[c], origin);
    // Depth = how many other shells enclose this one entirely (every sample inside). Shells
    // that merely overlap (a self-intersecting union) do not count: they are not cavities.
    int depth = 0;
    for (std::size_t other = 0; nesting && other < members.size(); ++other) {
      if (other == c || !box_inside(boxes[c], boxes[other])) continue;
      const bool enclosed = std::all_of(
          samples[c].begin(), samples[c].end(),
          [&](const Vector3& p) { return std::abs(WindingNumber(mesh, members[other], p)) > 0.5; });
      if (enclosed) ++depth;
    }
    const bool want_positive = depth % 2 == 0;
    if ((volume > 0) != want_positive && volume != 0.0) {
      for (std::int32_t t : members[c]) {
        FlipTriangle(mesh, t);
        flip[static_cast<std::size_t>(t)] ^= 1;
      }
    }
  }
  return nesting;
}

}  // namespace inscribe::internal
