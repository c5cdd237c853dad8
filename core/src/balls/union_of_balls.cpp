// Dual complex of a union of balls: CGAL's regular triangulation classified at alpha = 0 (the
// volume over it: union_volume.cpp). The only CGAL translation unit of this feature: a regular
// triangulation instantiation costs ~12 s and 1 GB to compile.
#include "inscribe/balls/union_of_balls.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Spatial_lock_grid_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_data_structure_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <numeric>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "balls/union_ball_checks.h"
#include "base/parallel.h"

namespace inscribe {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using WeightedPoint = Kernel::Weighted_point_3;
// Regular_triangulation_cell_base_3's hidden point container when hidden points are
// discarded: never filled, and 8 bytes per cell instead of an empty std::list's 24.
struct NoHiddenPoints {
  using iterator = WeightedPoint*;
  using const_iterator = const WeightedPoint*;
  iterator begin() { return nullptr; }
  iterator end() { return nullptr; }
  const_iterator begin() const { return nullptr; }
  const_iterator end() const { return nullptr; }
};
// Hidden points are not needed (the redundant balls are found by elimination), so not kept.
using RegularCellBase =
    CGAL::Regular_triangulation_cell_base_3<Kernel, CGAL::Triangulation_cell_base_3<Kernel>,
                                            CGAL::Discard_hidden_points, NoHiddenPoints>;
// Vertex info: the vertex's slot in the inserted point list (ball_of_vertex maps it to the
// input). Cell info: the cell's number in ClassifyAtAlphaZero. 72 bytes per cell.
using VertexBase =
    CGAL::Triangulation_vertex_base_with_info_3<std::int32_t, Kernel,
                                                CGAL::Regular_triangulation_vertex_base_3<Kernel>>;
using CellBase = CGAL::Triangulation_cell_base_with_info_3<std::int32_t, Kernel, RegularCellBase>;
// Few balls go in one by one (SequentialTriangulation); many are inserted on the TBB pool, which
// needs CGAL's concurrent containers and a lock grid (ParallelTriangulation). The concurrent
// containers cost about 15% more at 1,000 balls inserted in order, hence both.
using SequentialTriangulation =
    CGAL::Regular_triangulation_3<Kernel,
                                  CGAL::Triangulation_data_structure_3<VertexBase, CellBase>>;
using LockGrid = CGAL::Spatial_lock_grid_3<CGAL::Tag_priority_blocking>;
using ParallelTriangulation = CGAL::Regular_triangulation_3<
    Kernel, CGAL::Triangulation_data_structure_3<VertexBase, CellBase, CGAL::Parallel_tag>,
    LockGrid>;

constexpr std::int32_t kPadding = -1;
// Indices per parallel chunk of the classification and the sort.
constexpr std::size_t kGrain = 1024;
// Input indices in lexicographic order of (centre, radius, index); exact duplicates after the
// first go to `duplicates`. CGAL would merge them too, but keep whichever it met first.
std::vector<std::int32_t> DistinctBalls(const std::vector<Sphere>& balls,
                                        std::vector<std::int32_t>* duplicates) {
  std::vector<std::int32_t> order(balls.size());
  std::iota(order.begin(), order.end(), 0);
  const auto key = [&balls](std::int32_t i) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    return std::make_tuple(b.center.x(), b.center.y(), b.center.z(), b.radius);
  };
  std::sort(order.begin(), order.end(), [&key](std::int32_t i, std::int32_t j) {
    return std::make_pair(key(i), i) < std::make_pair(key(j), j);
  });
  std::vector<std::int32_t> distinct;
  distinct.reserve(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && key(order[k]) == key(order[k - 1])) {
      duplicates->push_back(order[k]);
    } else {
      distinct.push_back(order[k]);
    }
  }
  return distinct;
}

// Four zero-weight points far outside every ball, at the corners of a regular tetrahedron
// about the balls' bounding box. Added only when the centres span less than 3 dimensions (the
// classification needs a 3-dimensional triangulation). They change the regular triangulation but
// not the dual complex: each is a point ball disjoint from the union, so inside the union
// every power cell is unchanged (power to a padding point > 0 >= power to a covering ball), and
// no simplex with a padding vertex has a common point of its balls.
std::vector<std::pair<WeightedPoint, std::int32_t>> PaddingPoints(
    const std::vector<Sphere>& balls) {
  Vector3 lo = balls.front().center;
  Vector3 hi = lo;
  for (const Sphere& b : balls) {
    lo = lo.cwiseMin(b.center);
    hi = hi.cwiseMax(b.center);
  }
  const Vector3 mid = (lo + hi) / 2;
  double reach = 0.0;
  for (const Sphere& b : balls) reach = std::max(reach, (b.center - mid).norm() + b.radius);
  // Further out is as good (the padding only has to lie outside every ball), and it must be
  // far enough from `mid` to survive rounding: balls 1e-185 across near (1, 2, 1) would put all
  // four padding points on `mid` and leave the triangulation flat (found by fuzzing).
  reach = std::max(reach, 1e-6 * mid.cwiseAbs().maxCoeff());
  const double corners[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  std::vector<std::pair<WeightedPoint, std::int32_t>> out;
  for (const auto& c : corners) {
    const Vector3 p = mid + 4 * reach * Vector3(c[0], c[1], c[2]);
    out.emplace_back(WeightedPoint(Kernel::Point_3(p.x(), p.y(), p.z()), 0.0), kPadding);
  }
  return out;
}

template <std::size_t N>
std::array<std::int32_t, N> SortedTuple(std::array<std::int32_t, N> t) {
  std::sort(t.begin(), t.end());
  return t;
}

// From this many distinct balls on, they are inserted in parallel (CGAL's locking insertion on
// the TBB pool, which inserts its first 100 one by one anyway); fewer are inserted in order.
constexpr std::size_t kParallelInsertion = 2048;
// Lock cells per side of the lock grid's cube. On 10,000 random balls on 2 threads, 10-20 cells
// beat CGAL's examples' 50 (fewer failed locks and retries).
constexpr int kLockCellsPerSide = 20;

// The lock grid for the parallel insertion of these balls: a cube about their bounding box
// (centres and radii, so it has volume), or nothing when they are few, the pool has one
// thread, the build is ThreadSanitizer's, or the cube's cells per unit length are not finite (then
// insertion runs one ball at a time). CGAL clamps a point's cell to the grid, so only contention,
// not the triangulation, depends on the cube; but it computes the cell with an unchecked cast to
// int, so every point inserted under the locks must lie within a bounded multiple of the cube.
std::optional<LockGrid> LockGridFor(const std::vector<Sphere>& balls,
                                    const std::vector<std::int32_t>& distinct) {
  // CGAL's insertion runs its own TBB loop, whose threads ThreadSanitizer builds cannot follow
  // (parallel.h): there it runs in order.
  if (internal::kThreadSanitizer || distinct.size() < kParallelInsertion ||
      tbb::this_task_arena::max_concurrency() < 2) {
    return std::nullopt;
  }
  Vector3 lo = Vector3::Constant(std::numeric_limits<double>::infinity());
  Vector3 hi = -lo;
  for (std::int32_t i : distinct) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    lo = lo.cwiseMin(b.center - Vector3::Constant(b.radius));
    hi = hi.cwiseMax(b.center + Vector3::Constant(b.radius));
  }
  const Vector3 mid = 0.5 * (lo + hi);
  const double half = 0.5 * (hi - lo).maxCoeff();
  if (!(half > 0.0) || !std::isfinite(kLockCellsPerSide / half) || !mid.allFinite()) {
    return std::nullopt;
  }
  return std::make_optional<LockGrid>(CGAL::Bbox_3(mid.x() - half, mid.y() - half, mid.z() - half,
                                                   mid.x() + half, mid.y() + half, mid.z() + half),
                                      kLockCellsPerSide);
}

// The regular triangulation of the distinct balls, padded to dimension 3 if the centres span
// less. Vertex info is the index into `ball_of_vertex`, which gives the input ball or kPadding.
// `locks`: the lock grid of a ParallelTriangulation's parallel insertion (LockGridFor), or null.
// The padding points can lie arbitrarily many lock cells outside the grid (tiny balls far from
// the origin), so a triangulation that needs them is rebuilt without locks (flat or collinear
// centres, rare at sizes that insert in parallel).
template <typename RegularTriangulation>
absl::Status Triangulate(const std::vector<Sphere>& balls,
                         const std::vector<std::int32_t>& distinct, LockGrid* locks,
                         RegularTriangulation* triangulation,
                         std::vector<std::int32_t>* ball_of_vertex) {
  std::vector<std::pair<WeightedPoint, std::int32_t>> points;
  points.reserve(distinct.size() + 4);
  for (std::int32_t i : distinct) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    points.emplace_back(WeightedPoint(Kernel::Point_3(b.center.x(), b.center.y(), b.center.z()),
                                      b.radius * b.radius),
                        static_cast<std::int32_t>(points.size()));
  }
  *ball_of_vertex = distinct;
  // Range insertion: spatial sort (Hilbert order) first, then insertion.
  if (locks != nullptr) triangulation->set_lock_data_structure(locks);
  triangulation->insert(points.begin(), points.end());
  if (triangulation->dimension() < 3) {
    if (locks != nullptr) {
      triangulation->clear();
      triangulation->set_lock_data_structure(nullptr);
      triangulation->insert(points.begin(), points.end());
    }
    auto padding = PaddingPoints(balls);
    for (auto& [point, slot] : padding) {
      slot = static_cast<std::int32_t>(ball_of_vertex->size());
      ball_of_vertex->push_back(kPadding);
    }
    triangulation->insert(padding.begin(), padding.end());
  }
  // ClassifyAtAlphaZero needs dimension 3.
  if (triangulation->dimension() < 3) {
    return absl::InternalError("dual complex: the padded triangulation is not 3-dimensional");
  }
  return absl::OkStatus();
}

// The six edges of a cell as pairs of vertex positions, and for each the two other positions.
constexpr int kEdgeEnds[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
constexpr int kEdgeOthers[6][2] = {{2, 3}, {1, 3}, {1, 2}, {0, 3}, {0, 2}, {0, 1}};

int PopCount(std::uint8_t bits) {
  int n = 0;
  for (; bits != 0; bits &= static_cast<std::uint8_t>(bits - 1)) ++n;
  return n;
}

// The alpha complex at alpha = 0 of `triangulation` (dimension 3), read straight off it with
// the same exact predicates and the same rules as CGAL's Fixed_alpha_shape_3, so the same
// complex (tests compare the two on random and degenerate input):
//  - a finite cell is in when its orthogonal sphere's weighted squared radius is <= 0;
//  - a finite facet is in when a cell on either side is in, or when its smallest orthogonal
//    sphere has weighted squared radius <= 0 and neither opposite vertex lies strictly inside
//    it (Gabriel);
//  - an edge is in when one of its facets is in, or under the same two conditions with every
//    vertex of its link;
//  - a vertex is in when one of its edges is in, or when it is Gabriel (its ball is nearest to
//    its centre in power).
// Finite cells are numbered through their info (infinite ones get -1). Each facet belongs to
// the lower-numbered of its finite cells and each edge to the lowest-numbered finite cell
// around it; flags are bytes per cell, filled in parallel, each by its own cell, so the
// result does not depend on the schedule. Memory beyond the triangulation: 12 bytes per cell
// (first touches of fresh pages are a large part of the cost here). Returns false if a simplex
// has a padding vertex (impossible by construction; checked). Cost O(#cells) predicates plus
// O(sum of edge degrees) walking around edges.
template <typename RegularTriangulation>
bool ClassifyAtAlphaZero(RegularTriangulation& triangulation,
                         const std::vector<std::int32_t>& ball_of_vertex, DualComplex* complex) {
  using CellHandle = typename RegularTriangulation::Cell_handle;
  using VertexHandle = typename RegularTriangulation::Vertex_handle;
  const Kernel& traits = triangulation.geom_traits();
  const auto radius_exceeds_zero = [cmp = traits.compare_weighted_squared_radius_3_object()](
                                       const auto&... p) { return cmp(p..., 0.0) == CGAL::LARGER; };
  const auto strictly_inside =
      [side = traits.power_side_of_bounded_power_sphere_3_object()](const auto&... p) {
        return side(p...) == CGAL::ON_BOUNDED_SIDE;
      };

  std::vector<CellHandle> cells;
  cells.reserve(triangulation.tds().number_of_cells());
  for (auto c = triangulation.all_cells_begin(); c != triangulation.all_cells_end(); ++c) {
    if (triangulation.is_infinite(c)) {
      c->info() = -1;
    } else {
      c->info() = static_cast<std::int32_t>(cells.size());
      cells.push_back(c);
    }
  }
  const std::size_t num_cells = cells.size();
  const auto number = [](const CellHandle& c) { return c->info(); };

  std::vector<std::uint8_t> cell_in(num_cells, 0);
  internal::ParallelFor(std::size_t{0}, num_cells, kGrain, [&](std::size_t c) {
    const CellHandle& h = cells[c];
    cell_in[c] = !radius_exceeds_zero(h->vertex(0)->point(), h->vertex(1)->point(),
                                      h->vertex(2)->point(), h->vertex(3)->point());
  });

  // Bit f: facet f (opposite vertex f) is in. `owned_facet_in` has the bits of the facets this
  // cell owns, `facet_in` all four.
  const auto owns_facet = [&number](std::size_t c, const CellHandle& neighbor) {
    const std::int32_t n = number(neighbor);
    return n < 0 || static_cast<std::int32_t>(c) < n;
  };
  std::vector<std::uint8_t> owned_facet_in(num_cells, 0);
  internal::ParallelFor(std::size_t{0}, num_cells, kGrain, [&](std::size_t c) {
    const CellHandle& h = cells[c];
    for (int f = 0; f < 4; ++f) {
      const CellHandle n = h->neighbor(f);
      if (!owns_facet(c, n)) continue;
      bool in = cell_in[c] || (number(n) >= 0 && cell_in[static_cast<std::size_t>(number(n))]);
      if (!in) {
        const auto& a = h->vertex((f + 1) % 4)->point();
        const auto& b = h->vertex((f + 2) % 4)->point();
        const auto& d = h->vertex((f + 3) % 4)->point();
        const VertexHandle far = n->vertex(n->index(h));
        in = !radius_exceeds_zero(a, b, d) && !strictly_inside(a, b, d, h->vertex(f)->point()) &&
             (triangulation.is_infinite(far) || !strictly_inside(a, b, d, far->point()));
      }
      if (in) owned_facet_in[c] |= static_cast<std::uint8_t>(1u << f);
    }
  });
  std::vector<std::uint8_t> facet_in(num_cells, 0);
  internal::ParallelFor(std::size_t{0}, num_cells, kGrain, [&](std::size_t c) {
    const CellHandle& h = cells[c];
    std::uint8_t bits = owned_facet_in[c];
    for (int f = 0; f < 4; ++f) {
      const CellHandle n = h->neighbor(f);
      if (owns_facet(c, n)) continue;
      if ((owned_facet_in[static_cast<std::size_t>(number(n))] >> n->index(h)) & 1u) {
        bits |= static_cast<std::uint8_t>(1u << f);
      }
    }
    facet_in[c] = bits;
  });

  // Bit e: edge kEdgeEnds[e] is in, set in the edge's lowest-numbered finite cell only.
  std::vector<std::uint8_t> owned_edge_in(num_cells, 0);
  internal::ParallelFor(std::size_t{0}, num_cells, kGrain, [&](std::size_t c) {
    const CellHandle& h = cells[c];
    const auto precedes = [c](std::int32_t n) { return n >= 0 && static_cast<std::size_t>(n) < c; };
    std::int32_t neighbor_number[4];
    for (int k = 0; k < 4; ++k) neighbor_number[k] = number(h->neighbor(k));
    for (int e = 0; e < 6; ++e) {
      // The cells across this cell's two facets around the edge: most edges end here.
      if (precedes(neighbor_number[kEdgeOthers[e][0]]) ||
          precedes(neighbor_number[kEdgeOthers[e][1]])) {
        continue;
      }
      const VertexHandle u = h->vertex(kEdgeEnds[e][0]);
      const VertexHandle w = h->vertex(kEdgeEnds[e][1]);
      // The two facets of a cell around the edge are those opposite its two other vertices.
      const auto others = [&u, &w](const CellHandle& cell) {
        const int iu = cell->index(u);
        const int iw = cell->index(w);
        int k[2];
        for (int i = 0, j = 0; i < 4; ++i) {
          if (i != iu && i != iw) k[j++] = i;
        }
        return std::make_pair(k[0], k[1]);
      };
      // One walk around the edge: is this cell the lowest-numbered, and is a facet in.
      const auto first = triangulation.incident_cells(h, kEdgeEnds[e][0], kEdgeEnds[e][1]);
      auto around = first;
      bool owned = true;
      bool in = false;
      do {
        const std::int32_t n = number(around);
        if (n < 0) continue;
        if (precedes(n)) {
          owned = false;
          break;
        }
        if (!in) {
          const auto [k, l] = others(around);
          const std::uint8_t bits = facet_in[static_cast<std::size_t>(n)];
          in = ((bits >> k) & 1u) || ((bits >> l) & 1u);
        }
      } while (++around != first);
      if (!owned) continue;
      if (!in && !radius_exceeds_zero(u->point(), w->point())) {
        in = true;
        do {
          if (number(around) < 0) continue;
          const auto [k, l] = others(around);
          in = !strictly_inside(u->point(), w->point(), around->vertex(k)->point()) &&
               !strictly_inside(u->point(), w->point(), around->vertex(l)->point());
        } while (in && ++around != first);
      }
      if (in) owned_edge_in[c] |= static_cast<std::uint8_t>(1u << e);
    }
  });

  bool padding_in_complex = false;
  const auto ball = [&](const VertexHandle& v) {
    const std::int32_t i = ball_of_vertex[static_cast<std::size_t>(v->info())];
    if (i == kPadding) padding_in_complex = true;
    return i;
  };
  std::size_t num_edges = 0;
  std::size_t num_triangles = 0;
  std::size_t num_tetrahedra = 0;
  for (std::size_t c = 0; c < num_cells; ++c) {
    num_edges += static_cast<std::size_t>(PopCount(owned_edge_in[c]));
    num_triangles += static_cast<std::size_t>(PopCount(owned_facet_in[c]));
    num_tetrahedra += cell_in[c];
  }
  complex->edges.reserve(num_edges);
  complex->triangles.reserve(num_triangles);
  complex->tetrahedra.reserve(num_tetrahedra);
  std::vector<std::uint8_t> vertex_in(ball_of_vertex.size(), 0);
  for (std::size_t c = 0; c < num_cells; ++c) {
    const CellHandle& h = cells[c];
    for (int e = 0; e < 6; ++e) {
      if (!((owned_edge_in[c] >> e) & 1u)) continue;
      const VertexHandle u = h->vertex(kEdgeEnds[e][0]);
      const VertexHandle w = h->vertex(kEdgeEnds[e][1]);
      complex->edges.push_back(SortedTuple<2>({ball(u), ball(w)}));
      vertex_in[static_cast<std::size_t>(u->info())] = 1;
      vertex_in[static_cast<std::size_t>(w->info())] = 1;
    }
    for (int f = 0; f < 4; ++f) {
      if (!((owned_facet_in[c] >> f) & 1u)) continue;
      complex->triangles.push_back(
          SortedTuple<3>({ball(h->vertex((f + 1) % 4)), ball(h->vertex((f + 2) % 4)),
                          ball(h->vertex((f + 3) % 4))}));
    }
    if (cell_in[c]) {
      complex->tetrahedra.push_back(SortedTuple<4>(
          {ball(h->vertex(0)), ball(h->vertex(1)), ball(h->vertex(2)), ball(h->vertex(3))}));
    }
  }
  for (auto v = triangulation.finite_vertices_begin(); v != triangulation.finite_vertices_end();
       ++v) {
    const std::int32_t i = ball_of_vertex[static_cast<std::size_t>(v->info())];
    if (i == kPadding) continue;  // isolated points by construction
    if (vertex_in[static_cast<std::size_t>(v->info())] ||
        (triangulation.is_Gabriel(v) && !radius_exceeds_zero(v->point()))) {
      complex->vertices.push_back(i);
    }
  }
  return !padding_in_complex;
}

// Sorts simplices (ascending tuples of ball indices in [0, num_balls)) lexicographically: a
// counting sort by the lowest index, then each bucket (the few simplices whose lowest ball is
// that one) by std::sort, in parallel. Entries are distinct, so the order is unique whatever
// the schedule. O(#simplices + num_balls), against O(#simplices log #simplices) comparisons of
// tuples for one sort of the whole list.
template <std::size_t N>
void SortSimplices(std::vector<std::array<std::int32_t, N>>* simplices, std::size_t num_balls) {
  std::vector<std::size_t> start(num_balls + 1, 0);
  for (const auto& s : *simplices) ++start[static_cast<std::size_t>(s[0]) + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::array<std::int32_t, N>> sorted(simplices->size());
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (const auto& s : *simplices) sorted[next[static_cast<std::size_t>(s[0])]++] = s;
  }
  internal::ParallelFor(std::size_t{0}, num_balls, kGrain, [&](std::size_t b) {
    std::sort(sorted.begin() + static_cast<std::ptrdiff_t>(start[b]),
              sorted.begin() + static_cast<std::ptrdiff_t>(start[b + 1]));
  });
  simplices->swap(sorted);
}

// The complex of the distinct balls (its simplices unsorted) from a regular triangulation of
// type RegularTriangulation, inserted under `locks` (null: one ball at a time).
template <typename RegularTriangulation>
absl::Status ClassifiedTriangulation(const std::vector<Sphere>& balls,
                                     const std::vector<std::int32_t>& distinct, LockGrid* locks,
                                     DualComplex* complex) {
  RegularTriangulation triangulation;
  std::vector<std::int32_t> ball_of_vertex;
  if (absl::Status s = Triangulate(balls, distinct, locks, &triangulation, &ball_of_vertex);
      !s.ok()) {
    return s;
  }
  if (!ClassifyAtAlphaZero(triangulation, ball_of_vertex, complex)) {
    return absl::InternalError("dual complex: a padding point entered the complex");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<DualComplex> ComputeDualComplex(const std::vector<Sphere>& balls) {
  if (absl::Status s = internal::CheckUnionBalls(balls); !s.ok()) return s;
  DualComplex complex;
  if (balls.empty()) return complex;

  const std::vector<std::int32_t> distinct = DistinctBalls(balls, &complex.redundant);
  try {
    std::optional<LockGrid> locks = LockGridFor(balls, distinct);
    const absl::Status built =
        locks
            ? ClassifiedTriangulation<ParallelTriangulation>(balls, distinct, &*locks, &complex)
            : ClassifiedTriangulation<SequentialTriangulation>(balls, distinct, nullptr, &complex);
    if (!built.ok()) return built;
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("CGAL: ", e.what()));
  }

  std::sort(complex.vertices.begin(), complex.vertices.end());
  SortSimplices(&complex.edges, balls.size());
  SortSimplices(&complex.triangles, balls.size());
  SortSimplices(&complex.tetrahedra, balls.size());
  // Redundant: duplicates (already listed) plus distinct balls that are not vertices.
  for (std::int32_t i : distinct) {
    if (!std::binary_search(complex.vertices.begin(), complex.vertices.end(), i)) {
      complex.redundant.push_back(i);
    }
  }
  std::sort(complex.redundant.begin(), complex.redundant.end());
  return complex;
}

}  // namespace inscribe
