#include "support/fixed_alpha_shape_dual_complex.h"

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
#include <cstdint>
#include <map>
#include <tuple>
#include <utility>

namespace inscribe::testing {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using WeightedPoint = Kernel::Weighted_point_3;
using Tds = CGAL::Triangulation_data_structure_3<
    CGAL::Fixed_alpha_shape_vertex_base_3<
        Kernel, CGAL::Triangulation_vertex_base_with_info_3<
                    std::int32_t, Kernel, CGAL::Regular_triangulation_vertex_base_3<Kernel>>>,
    CGAL::Fixed_alpha_shape_cell_base_3<Kernel, CGAL::Regular_triangulation_cell_base_3<Kernel>>>;
using AlphaShape = CGAL::Fixed_alpha_shape_3<CGAL::Regular_triangulation_3<Kernel, Tds>>;

constexpr std::int32_t kFar = -1;

template <std::size_t N>
std::array<std::int32_t, N> Sorted(std::array<std::int32_t, N> t) {
  std::sort(t.begin(), t.end());
  return t;
}

}  // namespace

DualComplex FixedAlphaShapeDualComplex(const std::vector<Sphere>& balls) {
  // One point per distinct (centre, radius), carrying its lowest input index.
  std::map<std::tuple<double, double, double, double>, std::int32_t> first;
  for (std::size_t i = balls.size(); i-- > 0;) {
    const Sphere& b = balls[i];
    first[{b.center.x(), b.center.y(), b.center.z(), b.radius}] = static_cast<std::int32_t>(i);
  }
  std::vector<std::pair<WeightedPoint, std::int32_t>> points;
  for (const auto& [key, i] : first) {
    const Sphere& b = balls[static_cast<std::size_t>(i)];
    points.emplace_back(WeightedPoint(Kernel::Point_3(b.center.x(), b.center.y(), b.center.z()),
                                      b.radius * b.radius),
                        i);
  }
  AlphaShape::Triangulation triangulation(points.begin(), points.end());
  if (triangulation.dimension() < 3) {
    // Zero-weight points at the corners of a tetrahedron far outside every ball.
    Vector3 lo = balls.front().center;
    Vector3 hi = lo;
    for (const Sphere& b : balls) {
      lo = lo.cwiseMin(b.center - Vector3::Constant(b.radius));
      hi = hi.cwiseMax(b.center + Vector3::Constant(b.radius));
    }
    const Vector3 mid = (lo + hi) / 2;
    const double reach = 10 * std::max((hi - lo).norm(), 1e-6 * mid.cwiseAbs().maxCoeff());
    for (const Vector3& corner :
         {Vector3(1, 1, 1), Vector3(1, -1, -1), Vector3(-1, 1, -1), Vector3(-1, -1, 1)}) {
      const Vector3 p = mid + reach * corner;
      triangulation.insert(WeightedPoint(Kernel::Point_3(p.x(), p.y(), p.z()), 0.0))->info() = kFar;
    }
  }
  const AlphaShape shape(triangulation, 0.0);

  DualComplex c;
  const auto id = [](const AlphaShape::Vertex_handle& v) { return v->info(); };
  for (auto v = shape.finite_vertices_begin(); v != shape.finite_vertices_end(); ++v) {
    if (id(v) != kFar && shape.classify(v) != AlphaShape::EXTERIOR) c.vertices.push_back(id(v));
  }
  for (auto e = shape.finite_edges_begin(); e != shape.finite_edges_end(); ++e) {
    if (shape.classify(*e) == AlphaShape::EXTERIOR) continue;
    c.edges.push_back(Sorted<2>({id(e->first->vertex(e->second)), id(e->first->vertex(e->third))}));
  }
  for (auto f = shape.finite_facets_begin(); f != shape.finite_facets_end(); ++f) {
    if (shape.classify(*f) == AlphaShape::EXTERIOR) continue;
    std::array<std::int32_t, 3> t;
    for (int k = 0, j = 0; k < 4; ++k) {
      if (k != f->second) t[static_cast<std::size_t>(j++)] = id(f->first->vertex(k));
    }
    c.triangles.push_back(Sorted(t));
  }
  for (auto t = shape.finite_cells_begin(); t != shape.finite_cells_end(); ++t) {
    if (shape.classify(t) == AlphaShape::EXTERIOR) continue;
    c.tetrahedra.push_back(
        Sorted<4>({id(t->vertex(0)), id(t->vertex(1)), id(t->vertex(2)), id(t->vertex(3))}));
  }
  std::sort(c.vertices.begin(), c.vertices.end());
  std::sort(c.edges.begin(), c.edges.end());
  std::sort(c.triangles.begin(), c.triangles.end());
  std::sort(c.tetrahedra.begin(), c.tetrahedra.end());
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (!std::binary_search(c.vertices.begin(), c.vertices.end(), static_cast<std::int32_t>(i))) {
      c.redundant.push_back(static_cast<std::int32_t>(i));
    }
  }
  return c;
}

}  // namespace inscribe::testing
