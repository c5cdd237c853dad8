#include "solid/closest_point_triangle.h"

namespace inscribe::internal {
namespace {

// Closest point on segment [a, b]; t in [0, 1] is the weight of b.
Vector3 ClosestOnSegment(const Vector3& p, const Vector3& a, const Vector3& b, double* t) {
  const Vector3 ab = b - a;
  const double len2 = ab.squaredNorm();
  double s = len2 > 0.0 ? (p - a).dot(ab) / len2 : 0.0;
  s = s < 0.0 ? 0.0 : (s > 1.0 ? 1.0 : s);
  *t = s;
  if (s == 0.0) return a;
  if (s == 1.0) return b;
  return a + s * ab;
}

}  // namespace

Vector3 ClosestPointOnTriangle(const Vector3& p, const Vector3& a, const Vector3& b,
                               const Vector3& c, Vector3* barycentric) {
  const Vector3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    *barycentric = Vector3(1, 0, 0);
    return a;
  }
  const Vector3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    *barycentric = Vector3(0, 1, 0);
    return b;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    *barycentric = Vector3(1.0 - v, v, 0);
    return a + v * ab;
  }
  const Vector3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    *barycentric = Vector3(0, 0, 1);
    return c;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    *barycentric = Vector3(1.0 - w, 0, w);
    return a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    *barycentric = Vector3(0, 1.0 - w, w);
    return b + w * (c - b);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) {
    // Zero-area triangle whose regions did not classify p: take the best of its three edges.
    double t0, t1, t2;
    const Vector3 q0 = ClosestOnSegment(p, a, b, &t0);
    const Vector3 q1 = ClosestOnSegment(p, b, c, &t1);
    const Vector3 q2 = ClosestOnSegment(p, c, a, &t2);
    const double e0 = (p - q0).squaredNorm(), e1 = (p - q1).squaredNorm(),
                 e2 = (p - q2).squaredNorm();
    if (e0 <= e1 && e0 <= e2) {
      *barycentric = Vector3(1.0 - t0, t0, 0);
      return q0;
    }
    if (e1 <= e2) {
      *barycentric = Vector3(0, 1.0 - t1, t1);
      return q1;
    }
    *barycentric = Vector3(t2, 0, 1.0 - t2);
    return q2;
  }
  const double denom = 1.0 / sum;
  const double v = vb * denom, w = vc * denom;
  *barycentric = Vector3(1.0 - v - w, v, w);
  return a + ab * v + ac * w;
}

}  // namespace inscribe::internal
