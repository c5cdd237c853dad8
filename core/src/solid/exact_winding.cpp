#include "solid/exact_winding.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>

namespace inscribe::internal {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point2 = Kernel::Point_2;
using Point3 = Kernel::Point_3;

// The (y, z) shadow of a point on the plane x = 0, where the ray projects to a point.
Point2 Shadow(const Vector3& v) { return Point2(v.y(), v.z()); }
Point3 AsPoint(const Vector3& v) { return Point3(v.x(), v.y(), v.z()); }

// Sign of orient2d(x, y, p*) for the perturbed p* = p + (e, e^2) (in shadow coordinates u, v):
// the exact sign when it is not zero, else the sign of the perturbation's first non-zero term,
// -(y_v - x_v) e + (y_u - x_u) e^2. x != y.
int PerturbedOrientation(const Point2& x, const Point2& y, const Point2& p) {
  const CGAL::Orientation o = CGAL::orientation(x, y, p);
  if (o != CGAL::COLLINEAR) return static_cast<int>(o);
  if (y.y() != x.y()) return y.y() < x.y() ? 1 : -1;
  return y.x() > x.x() ? 1 : -1;
}

}  // namespace

int XRayCrossing(const Vector3& p, const Vector3& a, const Vector3& b, const Vector3& c) {
  // Exact rejections in doubles: the perturbed origin's shadow (p_y + e, p_z + e^2) lies
  // outside the triangle's shadow box when p_y >= max y or p_y < min y (likewise z), and a
  // triangle wholly behind p is not met at t >= 0. p on such a triangle is then not reported;
  // the sum still classifies a point infinitesimally near p.
  if (std::max({a.x(), b.x(), c.x()}) < p.x()) return 0;
  if (p.y() < std::min({a.y(), b.y(), c.y()}) || p.y() >= std::max({a.y(), b.y(), c.y()})) {
    return 0;
  }
  if (p.z() < std::min({a.z(), b.z(), c.z()}) || p.z() >= std::max({a.z(), b.z(), c.z()})) {
    return 0;
  }
  const Point2 sa = Shadow(a), sb = Shadow(b), sc = Shadow(c), sp = Shadow(p);
  const int s = static_cast<int>(CGAL::orientation(sa, sb, sc));
  if (s == 0) return 0;  // the shadow has no area: parallel to x, or a zero-area triangle
  if (PerturbedOrientation(sa, sb, sp) != s || PerturbedOrientation(sb, sc, sp) != s ||
      PerturbedOrientation(sc, sa, sp) != s) {
    return 0;
  }
  // The line through p* meets the triangle's plane; ahead of p when p lies on the side the
  // normal's x component points away from: sign((p - a) . n) = -sign(n_x) = -s.
  const int side =
      static_cast<int>(CGAL::orientation(AsPoint(a), AsPoint(b), AsPoint(c), AsPoint(p)));
  if (side == 0) return kOnTriangle;
  return side == -s ? s : 0;
}

}  // namespace inscribe::internal
