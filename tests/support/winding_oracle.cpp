#include "support/winding_oracle.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace inscribe::testing {
namespace {

using Point = std::array<long double, 3>;

Point Sub(const Point& a, const Point& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
long double Dot(const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Point Cross(const Point& a, const Point& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
long double Norm(const Point& a) { return std::sqrt(Dot(a, a)); }

Point ToPoint(const Vector3& v) {
  return {static_cast<long double>(v.x()), static_cast<long double>(v.y()),
          static_cast<long double>(v.z())};
}

long double SegmentDistanceSquared(const Point& p, const Point& a, const Point& b) {
  const Point ab = Sub(b, a), ap = Sub(p, a);
  const long double length2 = Dot(ab, ab);
  long double t = length2 > 0 ? Dot(ap, ab) / length2 : 0;
  t = std::clamp<long double>(t, 0, 1);
  const Point d = {ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]};
  return Dot(d, d);
}

// Root of i in a union-find forest, with path halving.
std::size_t Root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

}  // namespace

long double PointTriangleDistanceSquared(const Point& p, const Point& a, const Point& b,
                                         const Point& c) {
  const Point n = Cross(Sub(b, a), Sub(c, a));
  const long double n2 = Dot(n, n);
  if (n2 > 0) {
    // The projection of p lies in the closed triangle when p is on the inner side of all three
    // edges (seen along n): the plane distance is then the distance.
    const bool inside = Dot(Cross(Sub(b, a), Sub(p, a)), n) >= 0 &&
                        Dot(Cross(Sub(c, b), Sub(p, b)), n) >= 0 &&
                        Dot(Cross(Sub(a, c), Sub(p, c)), n) >= 0;
    if (inside) {
      const long double h = Dot(Sub(p, a), n);
      return h * h / n2;
    }
  }
  return std::min({SegmentDistanceSquared(p, a, b), SegmentDistanceSquared(p, b, c),
                   SegmentDistanceSquared(p, c, a)});
}

WindingOracle::WindingOracle(const Mesh& mesh) {
  // Shells: vertices joined by triangles (union-find over vertex indices).
  const auto nv = static_cast<std::size_t>(mesh.num_vertices());
  std::vector<std::size_t> parent(nv);
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int k = 1; k < 3; ++k) {
      parent[Root(parent, static_cast<std::size_t>(mesh.triangles(t, k)))] =
          Root(parent, static_cast<std::size_t>(mesh.triangles(t, 0)));
    }
  }
  std::vector<int> shell_of(nv, -1);
  double largest = 0.0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    const std::size_t root = Root(parent, static_cast<std::size_t>(mesh.triangles(t, 0)));
    if (shell_of[root] < 0) {
      shell_of[root] = static_cast<int>(shells_.size());
      Shell shell;
      shell.lo.fill(std::numeric_limits<long double>::infinity());
      shell.hi.fill(-std::numeric_limits<long double>::infinity());
      shells_.push_back(shell);
    }
    Shell& shell = shells_[static_cast<std::size_t>(shell_of[root])];
    Corners corners;
    for (int k = 0; k < 3; ++k) {
      const Vector3 v = mesh.vertices.row(mesh.triangles(t, k)).transpose();
      largest = std::max(largest, v.cwiseAbs().maxCoeff());
      corners[static_cast<std::size_t>(k)] = ToPoint(v);
      for (int axis = 0; axis < 3; ++axis) {
        shell.lo[static_cast<std::size_t>(axis)] =
            std::min(shell.lo[static_cast<std::size_t>(axis)], corners[k][axis]);
        shell.hi[static_cast<std::size_t>(axis)] =
            std::max(shell.hi[static_cast<std::size_t>(axis)], corners[k][axis]);
      }
    }
    const long double diameter2 =
        std::max({Dot(Sub(corners[1], corners[0]), Sub(corners[1], corners[0])),
                  Dot(Sub(corners[2], corners[1]), Sub(corners[2], corners[1])),
                  Dot(Sub(corners[0], corners[2]), Sub(corners[0], corners[2]))});
    shell.triangles.push_back(Triangle{corners, std::sqrt(diameter2)});
  }
  near_distance_ = kWindingNearRelative * largest;
}

long double WindingOracle::BoxDistanceSquared(const Shell& shell, const Point& p) {
  long double d2 = 0;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    const long double below = shell.lo[axis] - p[axis], above = p[axis] - shell.hi[axis];
    const long double gap = std::max<long double>({below, above, 0});
    d2 += gap * gap;
  }
  return d2;
}

WindingSample WindingOracle::At(const Vector3& query) const {
  const Point p = ToPoint(query);
  const long double near2 =
      static_cast<long double>(near_distance_) * static_cast<long double>(near_distance_);
  long double angles = 0;  // sum of half solid angles
  bool near = false;
  for (const Shell& shell : shells_) {
    if (BoxDistanceSquared(shell, p) > near2) continue;  // adds 0, holds no near triangle
    for (const Triangle& t : shell.triangles) {
      const Point a = Sub(t.corners[0], p), b = Sub(t.corners[1], p), c = Sub(t.corners[2], p);
      const long double la = Norm(a), lb = Norm(b), lc = Norm(c);
      // Only a triangle with a corner within its longest side plus near_distance can be near.
      if (!near) {
        near = std::min({la, lb, lc}) <= t.diameter + static_cast<long double>(near_distance_) &&
               PointTriangleDistanceSquared(p, t.corners[0], t.corners[1], t.corners[2]) <= near2;
      }
      // Numerator and denominator carry the cancellation, so they are formed in long double;
      // the angle of the rounded pair is then good to about 1e-16 rad.
      const long double numerator = Dot(a, Cross(b, c));
      const long double denominator =
          la * lb * lc + Dot(a, b) * lc + Dot(b, c) * la + Dot(c, a) * lb;
      angles += std::atan2(static_cast<double>(numerator), static_cast<double>(denominator));
    }
  }
  // Solid angle = 2 * atan2(...); winding = total solid angle / (4 pi).
  const long double raw = angles / (2 * 3.141592653589793238462643383279502884L);
  WindingSample sample;
  sample.raw = static_cast<double>(raw);
  sample.winding = static_cast<int>(std::lround(raw));
  sample.reliable = !near && std::fabs(raw - sample.winding) <= kWindingIntegerSlack;
  return sample;
}

std::vector<WindingSample> WindingOracle::AtAll(const Vertices& points) const {
  std::vector<WindingSample> out(static_cast<std::size_t>(points.rows()));
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, points.rows(), 256),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
                        out[static_cast<std::size_t>(i)] = At(points.row(i).transpose());
                      }
                    });
  return out;
}

double WindingOracle::Distance(const Vector3& query) const {
  const Point p = ToPoint(query);
  long double best2 = std::numeric_limits<long double>::infinity();
  for (const Shell& shell : shells_) {
    if (BoxDistanceSquared(shell, p) >= best2) continue;  // no triangle of it is nearer
    for (const Triangle& t : shell.triangles) {
      best2 = std::min(best2,
                       PointTriangleDistanceSquared(p, t.corners[0], t.corners[1], t.corners[2]));
    }
  }
  return static_cast<double>(std::sqrt(best2));
}

std::vector<double> WindingOracle::Distances(const Vertices& points) const {
  std::vector<double> out(static_cast<std::size_t>(points.rows()));
  tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, points.rows(), 64),
                    [&](const tbb::blocked_range<Eigen::Index>& range) {
                      for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
                        out[static_cast<std::size_t>(i)] = Distance(points.row(i).transpose());
                      }
                    });
  return out;
}

}  // namespace inscribe::testing
