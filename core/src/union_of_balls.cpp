// Dual complex of a union of balls (CGAL regular triangulation + fixed alpha shape at 0) and
// the union's volume by inclusion-exclusion over it. The only CGAL translation unit of this
// feature: a regular triangulation instantiation costs ~12 s and 1 GB to compile.
#include "inscribe/union_of_balls.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Fixed_alpha_shape_3.h>
#include <CGAL/Fixed_alpha_shape_cell_base_3.h>
#include <CGAL/Fixed_alpha_shape_vertex_base_3.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_data_structure_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <numeric>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "ball_intersection_volumes.h"

namespace inscribe {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using WeightedPoint = Kernel::Weighted_point_3;
// Vertex info: index into the input, or kPadding for the far points added to reach dimension 3.
using VertexBase = CGAL::Fixed_alpha_shape_vertex_base_3<
    Kernel, CGAL::Triangulation_vertex_base_with_info_3<
                std::int32_t, Kernel, CGAL::Regular_triangulation_vertex_base_3<Kernel>>>;
// Hidden points are not needed (the redundant balls are found by elimination), so not kept.
using CellBase = CGAL::Fixed_alpha_shape_cell_base_3<
    Kernel, CGAL::Regular_triangulation_cell_base_3<Kernel, CGAL::Triangulation_cell_base_3<Kernel>,
                                                    CGAL::Discard_hidden_points>>;
using Tds = CGAL::Triangulation_data_structure_3<VertexBase, CellBase>;
using RegularTriangulation = CGAL::Regular_triangulation_3<Kernel, Tds>;
using AlphaShape = CGAL::Fixed_alpha_shape_3<RegularTriangulation>;

constexpr std::int32_t kPadding = -1;
constexpr double kMaxMagnitude = 1e150;

absl::Status ValidateBalls(const std::vector<Sphere>& balls) {
  if (balls.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return absl::InvalidArgumentError(
        absl::StrCat("too many balls: ", balls.size(), " (at most 2^31 - 1)"));
  }
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Sphere& b = balls[i];
    if (absl::Status valid = CheckSphere(b, i); !valid.ok()) return valid;
    // Weights r^2 and squared distances must not overflow.
    if (b.radius > kMaxMagnitude || b.center.cwiseAbs().maxCoeff() > kMaxMagnitude) {
      return absl::InvalidArgumentError(absl::StrCat("ball ", i, ": centre or radius above ",
                                                     kMaxMagnitude, " (squares would overflow)"));
    }
  }
  return absl::OkStatus();
}

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
// alpha shape needs a 3-dimensional triangulation). They change the regular triangulation but
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

// Fills the simplices of `complex` from the alpha shape: every finite simplex not EXTERIOR,
// i.e. INTERIOR, REGULAR or SINGULAR at alpha = 0. Returns false if one has a padding vertex
// (impossible by construction; checked rather than assumed).
bool ExtractComplex(const AlphaShape& shape, DualComplex* complex) {
  bool padding_in_complex = false;
  const auto id = [&padding_in_complex](const AlphaShape::Vertex_handle& v) {
    if (v->info() == kPadding) padding_in_complex = true;
    return v->info();
  };
  for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v) {
    if (v->info() == kPadding) continue;  // isolated points by construction
    if (shape.classify(v) != AlphaShape::EXTERIOR) complex->vertices.push_back(v->info());
  }
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e) {
    if (shape.classify(*e) == AlphaShape::EXTERIOR) continue;
    complex->edges.push_back(
        SortedTuple<2>({id(e->first->vertex(e->second)), id(e->first->vertex(e->third))}));
  }
  for (auto f = shape.finite_facets_begin(); f != shape.finite_facets_end(); ++f) {
    if (shape.classify(*f) == AlphaShape::EXTERIOR) continue;
    std::array<std::int32_t, 3> t;
    for (int k = 0, j = 0; k < 4; ++k) {
      if (k != f->second) t[static_cast<std::size_t>(j++)] = id(f->first->vertex(k));
    }
    complex->triangles.push_back(SortedTuple(t));
  }
  for (auto c = shape.finite_cells_begin(); c != shape.finite_cells_end(); ++c) {
    if (shape.classify(c) == AlphaShape::EXTERIOR) continue;
    complex->tetrahedra.push_back(
        SortedTuple<4>({id(c->vertex(0)), id(c->vertex(1)), id(c->vertex(2)), id(c->vertex(3))}));
  }
  return !padding_in_complex;
}

// Every index in [0, num_balls), each tuple strictly increasing (the formulas need distinct
// balls).
template <std::size_t N>
absl::Status CheckIndices(const std::vector<std::array<std::int32_t, N>>& simplices,
                          std::size_t num_balls, const char* what) {
  for (std::size_t s = 0; s < simplices.size(); ++s) {
    for (std::size_t k = 0; k < N; ++k) {
      const std::int32_t i = simplices[s][k];
      if (i < 0 || static_cast<std::size_t>(i) >= num_balls) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, " ", s, ": ball index ", i, " out of range [0, ", num_balls, ")"));
      }
      if (k > 0 && simplices[s][k - 1] >= i) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, " ", s, ": ball indices not strictly increasing"));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<DualComplex> ComputeDualComplex(const std::vector<Sphere>& balls) {
  if (absl::Status s = ValidateBalls(balls); !s.ok()) return s;
  DualComplex complex;
  if (balls.empty()) return complex;

  const std::vector<std::int32_t> distinct = DistinctBalls(balls, &complex.redundant);
  std::vector<std::pair<WeightedPoint, std::int32_t>> points;
  points.reserve(distinct.size() + 4);
  for (std::int32_t i : distinct) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    points.emplace_back(WeightedPoint(Kernel::Point_3(b.center.x(), b.center.y(), b.center.z()),
                                      b.radius * b.radius),
                        i);
  }
  try {
    RegularTriangulation triangulation;
    // Range insertion: spatial sort (Hilbert order) first, then insertion.
    triangulation.insert(points.begin(), points.end());
    if (triangulation.dimension() < 3) {
      const auto padding = PaddingPoints(balls);
      triangulation.insert(padding.begin(), padding.end());
    }
    // CGAL's alpha shape classifies nothing below dimension 3 (reading it then is undefined).
    if (triangulation.dimension() < 3) {
      return absl::InternalError("dual complex: the padded triangulation is not 3-dimensional");
    }
    const AlphaShape shape(triangulation, 0.0);  // takes the triangulation's content
    if (!ExtractComplex(shape, &complex)) {
      return absl::InternalError("dual complex: a padding point entered the complex");
    }
  } catch (const std::exception& e) {
    return absl::InternalError(absl::StrCat("CGAL: ", e.what()));
  }

  std::sort(complex.vertices.begin(), complex.vertices.end());
  std::sort(complex.edges.begin(), complex.edges.end());
  std::sort(complex.triangles.begin(), complex.triangles.end());
  std::sort(complex.tetrahedra.begin(), complex.tetrahedra.end());
  // Redundant: duplicates (already listed) plus distinct balls that are not vertices.
  for (std::int32_t i : distinct) {
    if (!std::binary_search(complex.vertices.begin(), complex.vertices.end(), i)) {
      complex.redundant.push_back(i);
    }
  }
  std::sort(complex.redundant.begin(), complex.redundant.end());
  return complex;
}

absl::StatusOr<double> UnionVolume(const std::vector<Sphere>& balls, const DualComplex& complex) {
  if (absl::Status s = ValidateBalls(balls); !s.ok()) return s;
  std::vector<std::array<std::int32_t, 1>> vertices(complex.vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) vertices[v][0] = complex.vertices[v];
  if (absl::Status s = CheckIndices(vertices, balls.size(), "vertex"); !s.ok()) return s;
  if (absl::Status s = CheckIndices(complex.edges, balls.size(), "edge"); !s.ok()) return s;
  if (absl::Status s = CheckIndices(complex.triangles, balls.size(), "triangle"); !s.ok()) {
    return s;
  }
  if (absl::Status s = CheckIndices(complex.tetrahedra, balls.size(), "tetrahedron"); !s.ok()) {
    return s;
  }

  const auto ball = [&balls](std::int32_t i) -> const Sphere& {
    return balls[static_cast<std::size_t>(i)];
  };
  // One long double accumulator per dimension: the terms have like signs within a dimension,
  // and the alternating sum of the four totals is formed once at the end.
  long double sum[4] = {0, 0, 0, 0};
  for (std::int32_t i : complex.vertices) sum[0] += internal::BallVolume(ball(i));
  for (const auto& e : complex.edges) {
    sum[1] += internal::TwoBallIntersectionVolume(ball(e[0]), ball(e[1]));
  }
  for (const auto& t : complex.triangles) {
    sum[2] += internal::ThreeBallIntersectionVolume(ball(t[0]), ball(t[1]), ball(t[2]));
  }
  for (const auto& t : complex.tetrahedra) {
    sum[3] += internal::FourBallIntersectionVolume(ball(t[0]), ball(t[1]), ball(t[2]), ball(t[3]));
  }
  return static_cast<double>(sum[0] - sum[1] + sum[2] - sum[3]);
}

absl::StatusOr<double> UnionVolume(const std::vector<Sphere>& balls) {
  absl::StatusOr<DualComplex> complex = ComputeDualComplex(balls);
  if (!complex.ok()) return complex.status();
  return UnionVolume(balls, *complex);
}

}  // namespace inscribe
