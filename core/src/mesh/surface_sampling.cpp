#include "mesh/surface_sampling.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"

namespace inscribe::internal {

Vertices SampleBoundaryByArea(const Mesh& mesh, std::int64_t count, std::uint64_t seed) {
  const std::int64_t triangles = mesh.num_triangles();
  std::vector<double> cumulative(static_cast<std::size_t>(triangles));
  double total = 0.0;
  for (std::int64_t t = 0; t < triangles; ++t) {
    const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0));
    const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1));
    const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2));
    total += 0.5 * (b - a).cross(c - a).norm();
    cumulative[static_cast<std::size_t>(t)] = total;
  }
  if (!(total > 0.0)) return Vertices(0, 3);
  Vertices points(count, 3);
  ParallelForRange(std::int64_t{0}, count, 1024, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i != end; ++i) {
      std::mt19937_64 random(seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(i));
      auto uniform = [&random] { return static_cast<double>(random() >> 11) * 0x1.0p-53; };
      const double pick = uniform() * total;
      const std::int64_t t = std::min<std::int64_t>(
          triangles - 1,
          std::upper_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin());
      double u = uniform();
      double v = uniform();
      if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
      }
      const Vector3 a = mesh.vertices.row(mesh.triangles(t, 0));
      const Vector3 b = mesh.vertices.row(mesh.triangles(t, 1));
      const Vector3 c = mesh.vertices.row(mesh.triangles(t, 2));
      points.row(i) = a + u * (b - a) + v * (c - a);
    }
  });
  return points;
}

}  // namespace inscribe::internal
