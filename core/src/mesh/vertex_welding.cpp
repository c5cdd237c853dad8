#include "mesh/vertex_welding.h"

#include <CGAL/Fuzzy_sphere.h>
#include <CGAL/Kd_tree.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <vector>

#include "mesh/mesh_topology.h"

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using PointMap = CGAL::Pointer_property_map<Point>::type;
using Traits = CGAL::Search_traits_adapter<std::size_t, PointMap, CGAL::Search_traits_3<Kernel>>;
using Tree = CGAL::Kd_tree<Traits>;
using Sphere = CGAL::Fuzzy_sphere<Traits>;

// representative[v]: the vertex v is merged into (v itself when kept), for identical
// coordinates: vertices sorted by coordinates, each run of equal ones led by its lowest index.
std::vector<std::int32_t> ExactRepresentatives(const Mesh& mesh) {
  const auto n = static_cast<std::size_t>(mesh.num_vertices());
  std::vector<std::int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  auto coordinates = [&mesh](std::int32_t v) {
    return std::array<double, 3>{mesh.vertices(v, 0), mesh.vertices(v, 1), mesh.vertices(v, 2)};
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::int32_t a, std::int32_t b) { return coordinates(a) < coordinates(b); });
  std::vector<std::int32_t> representative(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool same = i > 0 && coordinates(order[i]) == coordinates(order[i - 1]);
    representative[static_cast<std::size_t>(order[i])] =
        same ? representative[static_cast<std::size_t>(order[i - 1])] : order[i];
  }
  return representative;
}

// The same within `tolerance`: in index order, each vertex not yet merged is kept and takes
// every later unmerged vertex within the tolerance (CGAL's kd-tree range search). With
// `only`, the vertices it does not mark are neither searched nor taken.
std::vector<std::int32_t> NearRepresentatives(const Mesh& mesh, double tolerance,
                                              const std::vector<char>* only) {
  const auto n = static_cast<std::size_t>(mesh.num_vertices());
  std::vector<Point> points;
  points.reserve(n);
  std::vector<std::size_t> searched;
  for (std::size_t v = 0; v < n; ++v) {
    const auto i = static_cast<Eigen::Index>(v);
    points.emplace_back(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2));
    if (only == nullptr || (*only)[v]) searched.push_back(v);
  }
  // With `only`, vertices an edge joins are never merged (that would collapse its triangles).
  std::vector<std::pair<std::int32_t, std::int32_t>> edges;
  if (only != nullptr) {
    for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const std::int32_t a = mesh.triangles(t, k), b = mesh.triangles(t, (k + 1) % 3);
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
    std::sort(edges.begin(), edges.end());
  }
  auto joined = [&edges](std::size_t a, std::size_t b) {
    const auto e = std::make_pair(static_cast<std::int32_t>(std::min(a, b)),
                                  static_cast<std::int32_t>(std::max(a, b)));
    return std::binary_search(edges.begin(), edges.end(), e);
  };
  const Traits traits(CGAL::make_property_map(points));
  Tree tree(searched.begin(), searched.end(), Tree::Splitter(), traits);
  tree.build();
  const double squared = tolerance * tolerance;
  std::vector<std::int32_t> representative(n, -1);
  std::vector<std::size_t> found, cluster;
  for (std::size_t v = 0; v < n; ++v) {
    if (representative[v] >= 0) continue;
    representative[v] = static_cast<std::int32_t>(v);
    if (only != nullptr && !(*only)[v]) continue;
    found.clear();
    tree.search(std::back_inserter(found), Sphere(v, tolerance, 0.0, traits));
    std::sort(found.begin(), found.end());
    cluster.assign(1, v);
    for (std::size_t w : found) {
      if (w > v && representative[w] < 0 &&
          CGAL::squared_distance(points[v], points[w]) <= squared &&
          (only == nullptr || std::none_of(cluster.begin(), cluster.end(), [&](std::size_t member) {
             return joined(member, w);
           }))) {
        representative[w] = static_cast<std::int32_t>(v);
        if (only != nullptr) cluster.push_back(w);
      }
    }
  }
  return representative;
}

}  // namespace

Weld WeldVertices(Mesh& mesh, double tolerance, const std::vector<char>* only) {
  Weld weld;
  const std::vector<std::int32_t> group =
      tolerance > 0.0 ? NearRepresentatives(mesh, tolerance, only) : ExactRepresentatives(mesh);
  const auto nv = static_cast<std::size_t>(mesh.num_vertices());
  bool any = false;
  for (std::size_t v = 0; v < nv && !any; ++v) any = group[v] != static_cast<std::int32_t>(v);
  if (!any) return weld;

  // The triangles on the merged vertices, less those that merging gives a repeated corner.
  Mesh merged;
  merged.triangles.resize(mesh.triangles.rows(), 3);
  std::vector<Eigen::Index> given;  // merged triangle -> triangle as given
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const bool distinct_before = HasDistinctCorners(mesh, t);
    const Eigen::Index row = static_cast<Eigen::Index>(given.size());
    for (int k = 0; k < 3; ++k) {
      merged.triangles(row, k) = group[static_cast<std::size_t>(mesh.triangles(t, k))];
    }
    if (distinct_before && !HasDistinctCorners(merged, row)) {
      ++weld.collapsed_triangles;
      continue;
    }
    given.push_back(t);
  }
  merged.triangles.conservativeResize(static_cast<Eigen::Index>(given.size()), 3);
  merged.vertices = mesh.vertices;

  // A merged vertex stays one vertex only where its triangles form one fan: corners are joined
  // through edges in exactly two triangles, and corners that were one vertex as given stay
  // one. Each resulting set of corners is a vertex, named by its lowest index as given; so a
  // merge that would pinch separate sheets or shells together at a point or an edge is undone
  // there (as CGAL's orient_polygon_soup splits such vertices), and a mesh whose coincident
  // vertices all belong to separate shells is left as it was.
  const std::size_t corners = static_cast<std::size_t>(merged.num_triangles()) * 3;
  DisjointSets sets(corners);
  const std::vector<EdgeUse> uses = SortedEdgeUses(merged);
  auto corner = [&](const EdgeUse& use, bool lo) {
    const bool first = use.forward == lo;  // the side runs from corner `side` to the next
    return static_cast<std::size_t>(use.triangle) * 3 +
           static_cast<std::size_t>(first ? use.side : (use.side + 1) % 3);
  };
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i + 1;
    while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
    if (j - i == 2) {
      sets.Union(corner(uses[i], true), corner(uses[i + 1], true));
      sets.Union(corner(uses[i], false), corner(uses[i + 1], false));
    }
    i = j;
  }
  std::vector<std::size_t> first_corner(nv, corners);
  for (std::size_t c = 0; c < corners; ++c) {
    const auto v =
        static_cast<std::size_t>(mesh.triangles(given[c / 3], static_cast<Eigen::Index>(c % 3)));
    if (first_corner[v] == corners) {
      first_corner[v] = c;
    } else {
      sets.Union(first_corner[v], c);
    }
  }
  std::vector<std::int32_t> lowest(corners, std::numeric_limits<std::int32_t>::max());
  for (std::size_t c = 0; c < corners; ++c) {
    const std::int32_t v = mesh.triangles(given[c / 3], static_cast<Eigen::Index>(c % 3));
    std::int32_t& low = lowest[sets.Find(c)];
    low = std::min(low, v);
  }
  // Kept: each corner set's lowest vertex, and the group of vertices in no triangle.
  std::vector<char> kept(nv, 0);
  std::vector<char> group_used(nv, 0);
  for (std::size_t c = 0; c < corners; ++c) {
    kept[static_cast<std::size_t>(lowest[sets.Find(c)])] = 1;
    group_used[static_cast<std::size_t>(
        merged.triangles(static_cast<Eigen::Index>(c / 3), static_cast<Eigen::Index>(c % 3)))] = 1;
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (group[v] == static_cast<std::int32_t>(v) && !group_used[v]) kept[v] = 1;
  }
  std::vector<std::int32_t> renumber(nv, -1);
  std::int32_t count = 0;
  for (std::size_t v = 0; v < nv; ++v) {
    if (kept[v]) renumber[v] = count++;
  }
  weld.merged_vertices = static_cast<std::int64_t>(nv) - count;
  if (weld.merged_vertices == 0 && weld.collapsed_triangles == 0) return weld;

  Vertices vertices(count, 3);
  for (std::size_t v = 0; v < nv; ++v) {
    if (kept[v]) vertices.row(renumber[v]) = mesh.vertices.row(static_cast<Eigen::Index>(v));
  }
  Triangles triangles(merged.num_triangles(), 3);
  for (std::size_t c = 0; c < corners; ++c) {
    triangles(static_cast<Eigen::Index>(c / 3), static_cast<Eigen::Index>(c % 3)) =
        renumber[static_cast<std::size_t>(lowest[sets.Find(c)])];
  }
  mesh.vertices = std::move(vertices);
  mesh.triangles = std::move(triangles);
  return weld;
}

}  // namespace inscribe::internal
