#include "inscribe/distance/rss.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace inscribe {
namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// FitRss pads its radius by kRadiusPadUlps ulps of (radius + largest |coordinate| of the balls):
// covers the rounding of the rectangle's origin (mean + axes * local corner) and of a later
// distance computation from a centre to the rectangle (a projection into the RSS frame), each
// a few ulps of the coordinates involved.
constexpr double kRadiusPadUlps = 32.0;

// ---- Rectangle pair geometry ------------------------------------------------------------
//
// Everything below works in the local frame of one rectangle R = [0, l0] x [0, l1] x {0}
// (its origin at 0, its edges along x and y, its normal along z), where the closest point of
// R to x is a clamp and x's residual x - closest(x) is the gradient of dist(x, R)^2 / 2.

inline double Clamp(double x, double hi) { return std::min(std::max(x, 0.0), hi); }

// x - clamp(x, 0, l) for l >= 0, without branches.
inline double Excess(double x, double l) { return std::min(x, 0.0) + std::max(x - l, 0.0); }

inline Vector3 ClosestOnRectangle(const Vector3& x, const double l[2]) {
  return Vector3(Clamp(x.x(), l[0]), Clamp(x.y(), l[1]), 0.0);
}

inline Vector3 Residual(const Vector3& x, const double l[2]) {
  return Vector3(Excess(x.x(), l[0]), Excess(x.y(), l[1]), x.z());
}

// Three coordinates as plain scalars, for the hot path of RssDistance. With Eigen::Vector3d
// temporaries there, GCC's SLP vectoriser (on at -O2) wrote vectors as 8-byte halves and read
// them back as 16-byte pairs, stalling store forwarding: 40 ns per call against 24 ns (far
// pairs) with these.
struct Xyz {
  double x, y, z;
};
inline Xyz operator+(const Xyz& a, const Xyz& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Xyz operator*(double s, const Xyz& a) { return {s * a.x, s * a.y, s * a.z}; }
inline double Dot(const Xyz& a, const Xyz& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vector3 ToVector(const Xyz& a) { return Vector3(a.x, a.y, a.z); }
inline Xyz AsXyz(const Vector3& a) { return {a.x(), a.y(), a.z()}; }
inline Xyz Column(const Eigen::Matrix3d& m, int j) { return {m(0, j), m(1, j), m(2, j)}; }
// m * a and m^T * a for a 3x3 matrix m.
inline Xyz Times(const Eigen::Matrix3d& m, const Xyz& a) {
  return {m(0, 0) * a.x + m(0, 1) * a.y + m(0, 2) * a.z,
          m(1, 0) * a.x + m(1, 1) * a.y + m(1, 2) * a.z,
          m(2, 0) * a.x + m(2, 1) * a.y + m(2, 2) * a.z};
}
inline Xyz TransposeTimes(const Eigen::Matrix3d& m, const Xyz& a) {
  return {m(0, 0) * a.x + m(1, 0) * a.y + m(2, 0) * a.z,
          m(0, 1) * a.x + m(1, 1) * a.y + m(2, 1) * a.z,
          m(0, 2) * a.x + m(1, 2) * a.y + m(2, 2) * a.z};
}

// Rectangle B given in rectangle A's local frame: A = [0, la0] x [0, la1] x {0} and
// B = {p + s * u + t * v : s in [0, lb0], t in [0, lb1]}, u, v, n = u x v being B's axes in
// A's frame; so A's axes in B's frame are the rows of [u v n] and A's origin there is
// -(u.p, v.p, n.p).
struct LocalPair {
  Xyz u, v, p;
  double la[2];
  double lb[2];
};

// The closest pair found, in the local frame of rectangle A (in_b_frame false) or B (true):
// `on_own` on that frame's rectangle, `on_other` on the other one.
struct LocalWitness {
  bool in_b_frame = false;
  Vector3 on_own = Vector3::Zero();
  Vector3 on_other = Vector3::Zero();
};

// The four corners of one rectangle in the other's frame, with their residuals against the
// other rectangle and squared distances to it. Corner k is origin + (k & 1) * du +
// (k >> 1) * dv; edges are 0-1 and 2-3 (along du), 0-2 and 1-3 (along dv). Plain arrays of
// scalars, written once by CornerPass and read by the edge search.
struct Corners {
  double x[4], y[4], z[4];
  double rx[4], ry[4];  // residual (rx, ry, z)
  double squared[4];
  Xyz du, dv;

  Vector3 Point(int k) const { return Vector3(x[k], y[k], z[k]); }
  Xyz ResidualAt(int k) const { return {rx[k], ry[k], z[k]}; }
  int Nearest() const {
    const int n01 = squared[1] < squared[0] ? 1 : 0;
    const int n23 = squared[3] < squared[2] ? 3 : 2;
    return squared[n23] < squared[n01] ? n23 : n01;
  }
};

// The smallest squared distance from a corner to the other rectangle, and whether some
// corner passes the optimality test: with d = the corner's residual (pointing from the other
// rectangle to it), the other rectangle's closest point maximises d.x over it (a property of
// the clamp), so the pair is the rectangles' closest pair iff the corner minimises d.y over
// its own rectangle, i.e. d has a non-negative component along both edges leaving the corner
// (a zero-length edge or a zero residual imposes nothing). A certified corner's distance is
// the rectangles' distance; every corner's is an upper bound, so the minimum over the four
// then equals it too.
struct CornerBound {
  double squared;
  bool certified;
};

// Fills *c for the rectangle {o + s du + t dv} against R = [0, l0] x [0, l1] x {0}. All four
// corners are tested branch-free: singling out the nearest one would be an unpredictable
// branch on random pairs.
[[gnu::always_inline]] inline CornerBound CornerPass(const Xyz& o, const Xyz& du, const Xyz& dv,
                                                     const double l[2], Corners* c) {
  c->du = du;
  c->dv = dv;
  CornerBound result{std::numeric_limits<double>::infinity(), false};
  auto corner = [&](int k, const Xyz& point, double sign_u, double sign_v) {
    const Xyz r{Excess(point.x, l[0]), Excess(point.y, l[1]), point.z};
    const double squared = Dot(r, r);
    c->x[k] = point.x;
    c->y[k] = point.y;
    c->z[k] = point.z;
    c->rx[k] = r.x;
    c->ry[k] = r.y;
    c->squared[k] = squared;
    result.squared = std::min(result.squared, squared);
    result.certified |= std::min(sign_u * Dot(du, r), sign_v * Dot(dv, r)) >= 0.0;
  };
  const Xyz o_u = o + du;
  corner(0, o, 1.0, 1.0);
  corner(1, o_u, -1.0, 1.0);
  corner(2, o + dv, 1.0, -1.0);
  corner(3, o_u + dv, -1.0, -1.0);
  return result;
}

// A's origin and edge vectors in B's frame, from B in A's frame.
struct SwappedFrame {
  Xyz origin, edge_u, edge_v;
};
inline SwappedFrame Swap(const LocalPair& f) {
  const Xyz& u = f.u;
  const Xyz& v = f.v;
  const Xyz n{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
  return {Xyz{-Dot(u, f.p), -Dot(v, f.p), -Dot(n, f.p)}, f.la[0] * Xyz{u.x, v.x, n.x},
          f.la[1] * Xyz{u.y, v.y, n.y}};
}

// Edges as (start corner, end corner, along v, inward sign): an edge along du (dv) lies at
// t = 0 or t = lb1 (s = 0 or s = lb0); its rectangle lies on the side `inward sign` * dv (du).
struct Edge {
  int start;
  int end;
  bool along_v;
  double inward;
};
constexpr Edge kEdges[4] = {
    {0, 1, false, 1.0}, {2, 3, false, -1.0}, {0, 2, true, 1.0}, {1, 3, true, -1.0}};

// Minimum over s in [0, 1] of dist(c + s * w, R)^2 for R = [0, l0] x [0, l1] x {0}, given that
// it is interior: g(s) = w . residual(c + s * w), half the derivative, satisfies g(0) = g0 < 0
// < g1 = g(1). g is continuous, non-decreasing (the function is convex) and linear between
// the breakpoints where x or y crosses 0 or l: the bracket [lo, hi] is shrunk over those
// breakpoints, leaving g linear on it, and its root is interpolated. A segment crossing R's
// plane inside R gives exactly 0. Returns the squared distance; *point is the minimiser on
// the segment and *closest its closest point on R. Cost: at most 4 evaluations of g.
double SegmentToRectangle(const Vector3& c, const Vector3& w, const double l[2], double g0,
                          double g1, Vector3* point, Vector3* closest) {
  const double z0 = c.z();
  const double z1 = c.z() + w.z();
  if ((z0 < 0.0 && z1 > 0.0) || (z0 > 0.0 && z1 < 0.0)) {
    const double s = z0 / (z0 - z1);
    const double x = c.x() + s * w.x();
    const double y = c.y() + s * w.y();
    if (x >= 0.0 && x <= l[0] && y >= 0.0 && y <= l[1]) {
      *point = *closest = Vector3(x, y, 0.0);
      return 0.0;
    }
  }
  double lo = 0.0, hi = 1.0, g_lo = g0, g_hi = g1;
  for (int axis = 0; axis < 2; ++axis) {
    if (w[axis] == 0.0) continue;
    const double inverse = 1.0 / w[axis];
    const double breaks[2] = {-c[axis] * inverse, (l[axis] - c[axis]) * inverse};
    for (const double t : breaks) {
      if (!(t > lo && t < hi)) continue;
      const double g = w.dot(Residual(c + t * w, l));
      if (g < 0.0) {
        lo = t;
        g_lo = g;
      } else if (g > 0.0) {
        hi = t;
        g_hi = g;
      } else {
        lo = hi = t;
        g_lo = g_hi = 0.0;
      }
    }
  }
  const double s = g_lo == 0.0 ? lo : lo + (hi - lo) * (g_lo / (g_lo - g_hi));
  *point = c + s * w;
  *closest = ClosestOnRectangle(*point, l);
  return (*point - *closest).squaredNorm();
}

// Interior minima of the four edges of `own` against the other rectangle (lengths `l`), in
// that rectangle's frame. Updates *best (and *witness, if given, with in_b_frame =
// `b_frame`) when an edge comes closer; returns true when the candidate is certified optimal
// (or 0), i.e. the search is over.
bool EdgeInteriors(const Corners& own, const double l[2], bool b_frame, double* best,
                   LocalWitness* witness) {
  for (const Edge& e : kEdges) {
    const Xyz& w = e.along_v ? own.dv : own.du;
    const double g0 = Dot(w, own.ResidualAt(e.start));
    const double g1 = Dot(w, own.ResidualAt(e.end));
    if (!(g0 < 0.0 && g1 > 0.0)) continue;  // the edge's minimum is at a corner
    Vector3 point, closest;
    const double squared =
        SegmentToRectangle(own.Point(e.start), ToVector(w), l, g0, g1, &point, &closest);
    if (squared < *best) {
      *best = squared;
      if (witness != nullptr) *witness = {b_frame, closest, point};
    }
    // Optimal when the edge's own rectangle lies on the far side of the plane through the
    // point normal to d = point - closest (d is normal to the edge at an interior minimum).
    const Xyz& inward = e.along_v ? own.du : own.dv;
    if (squared == 0.0 || e.inward * Dot(inward, AsXyz(point - closest)) >= 0.0) return true;
  }
  return false;
}

// After both corner passes failed: the edges' interiors, B's edges against A then A's
// against B, starting from the best corner distance `best`. Kept out of line so that the
// corner passes inline into RssDistance with few registers to spill.
[[gnu::noinline]] double EdgeSearch(const LocalPair& f, const Corners& b_corners,
                                    const Corners& a_corners, double best, LocalWitness* witness) {
  if (EdgeInteriors(b_corners, f.la, false, &best, witness)) return best;
  EdgeInteriors(a_corners, f.lb, true, &best, witness);
  return best;
}

// Squared distance between the rectangles of `f`, with its witness if asked for; exact up to
// rounding. The optimum has a point on an edge of one rectangle, and each edge's distance to
// the other rectangle is a convex function of the edge parameter, minimal at a corner or in
// the edge's interior; so the minimum over the 8 corners and the edges' interior minima is
// the distance. The search stops at the first candidate passing the optimality test: B's
// corners, A's corners, then the edges' interiors (EdgeSearch).
[[gnu::always_inline]] inline double SquaredDistance(const LocalPair& f, LocalWitness* witness) {
  Corners b_corners, a_corners;
  const CornerBound b_bound = CornerPass(f.p, f.lb[0] * f.u, f.lb[1] * f.v, f.la, &b_corners);
  if (witness != nullptr) {
    const int k = b_corners.Nearest();
    *witness = {false, ClosestOnRectangle(b_corners.Point(k), f.la), b_corners.Point(k)};
  }
  if (b_bound.certified) return b_bound.squared;
  const SwappedFrame swapped = Swap(f);
  const CornerBound a_bound =
      CornerPass(swapped.origin, swapped.edge_u, swapped.edge_v, f.lb, &a_corners);
  if (witness != nullptr && a_bound.squared < b_bound.squared) {
    const int k = a_corners.Nearest();
    *witness = {true, ClosestOnRectangle(a_corners.Point(k), f.lb), a_corners.Point(k)};
  }
  const double best = std::min(a_bound.squared, b_bound.squared);
  if (a_bound.certified) return best;
  return EdgeSearch(f, b_corners, a_corners, best, witness);
}

}  // namespace

double RectangleDistance(const Rss& a, const Rss& b, Vector3* point_a, Vector3* point_b) {
  LocalPair f;
  f.u = TransposeTimes(a.axes, Column(b.axes, 0));
  f.v = TransposeTimes(a.axes, Column(b.axes, 1));
  f.p = TransposeTimes(a.axes, AsXyz(b.origin - a.origin));
  f.la[0] = a.length[0];
  f.la[1] = a.length[1];
  f.lb[0] = b.length[0];
  f.lb[1] = b.length[1];
  LocalWitness witness;
  const double squared = SquaredDistance(f, &witness);
  // Back to the common frame; a witness found in B's frame has its roles swapped.
  const Rss& own = witness.in_b_frame ? b : a;
  const Vector3 on_own = own.origin + own.axes * witness.on_own;
  const Vector3 on_other = own.origin + own.axes * witness.on_other;
  if (point_a != nullptr) *point_a = witness.in_b_frame ? on_other : on_own;
  if (point_b != nullptr) *point_b = witness.in_b_frame ? on_own : on_other;
  return std::sqrt(squared);
}

double RssDistance(const Rss& a, const Eigen::Matrix3d& rotation, const Vector3& translation,
                   const Rss& b) {
  const double radii = a.radius + b.radius;
  // b's origin relative to a's, in a's parent frame.
  const Xyz moved = Times(rotation, AsXyz(b.origin));
  const Xyz offset{moved.x + translation.x() - a.origin.x(),
                   moved.y + translation.y() - a.origin.y(),
                   moved.z + translation.z() - a.origin.z()};
  // Points (leaves of a sphere hierarchy): the distance to the other rectangle is a clamp.
  if (b.length[0] == 0.0 && b.length[1] == 0.0) {
    const Xyz x = TransposeTimes(a.axes, offset);
    const Xyz r{Excess(x.x, a.length[0]), Excess(x.y, a.length[1]), x.z};
    return std::sqrt(Dot(r, r)) - radii;
  }
  const Xyz u_parent = Times(rotation, Column(b.axes, 0));
  const Xyz v_parent = Times(rotation, Column(b.axes, 1));
  if (a.length[0] == 0.0 && a.length[1] == 0.0) {
    const Xyz n_parent{u_parent.y * v_parent.z - u_parent.z * v_parent.y,
                       u_parent.z * v_parent.x - u_parent.x * v_parent.z,
                       u_parent.x * v_parent.y - u_parent.y * v_parent.x};
    const Xyz x{-Dot(u_parent, offset), -Dot(v_parent, offset), -Dot(n_parent, offset)};
    const Xyz r{Excess(x.x, b.length[0]), Excess(x.y, b.length[1]), x.z};
    return std::sqrt(Dot(r, r)) - radii;
  }
  LocalPair f;
  f.u = TransposeTimes(a.axes, u_parent);
  f.v = TransposeTimes(a.axes, v_parent);
  f.p = TransposeTimes(a.axes, offset);
  f.la[0] = a.length[0];
  f.la[1] = a.length[1];
  f.lb[0] = b.length[0];
  f.lb[1] = b.length[1];
  return std::sqrt(SquaredDistance(f, nullptr)) - radii;
}

Rss FitRss(const std::vector<Sphere>& balls, const std::int32_t* indices, std::size_t count) {
  assert(count >= 1);
  Rss rss;
  if (count == 1) {
    rss.origin = balls[static_cast<std::size_t>(indices[0])].center;
    rss.radius = balls[static_cast<std::size_t>(indices[0])].radius;
    return rss;
  }
  auto ball = [&](std::size_t i) -> const Sphere& {
    return balls[static_cast<std::size_t>(indices[i])];
  };

  // Orientation: principal axes of the centres about their mean (two passes, so a large
  // common offset does not cancel the covariance away).
  Vector3 mean = Vector3::Zero();
  double magnitude = 0.0;  // largest |coordinate|, for the rounding pad
  for (std::size_t i = 0; i < count; ++i) {
    mean += ball(i).center;
    magnitude = std::max(magnitude, ball(i).center.cwiseAbs().maxCoeff());
  }
  mean /= static_cast<double>(count);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < count; ++i) {
    const Vector3 d = ball(i).center - mean;
    covariance.noalias() += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Vector3 e0 = solver.eigenvectors().col(2).normalized();  // largest eigenvalue
  const Vector3 normal = e0.cross(solver.eigenvectors().col(1)).normalized();
  rss.axes.col(0) = e0;
  rss.axes.col(1) = normal.cross(e0);
  rss.axes.col(2) = normal;

  // Centres in the RSS frame (about the mean); thickness: the slab between the lowest and
  // highest points of the balls along the normal, the rectangle's plane in its middle.
  std::vector<Vector3> local(count);
  double z_lo = std::numeric_limits<double>::infinity();
  double z_hi = -z_lo;
  for (std::size_t i = 0; i < count; ++i) {
    local[i].noalias() = rss.axes.transpose() * (ball(i).center - mean);
    z_lo = std::min(z_lo, local[i].z() - ball(i).radius);
    z_hi = std::max(z_hi, local[i].z() + ball(i).radius);
  }
  const double radius = 0.5 * (z_hi - z_lo);
  const double z_mid = 0.5 * (z_hi + z_lo);
  // Ball i fits when its centre is within reach[i] of the rectangle, in the plane z = z_mid.
  std::vector<double> reach(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double slack = radius - ball(i).radius;
    const double dz = local[i].z() - z_mid;
    reach[i] = std::sqrt(std::max(0.0, slack * slack - dz * dz));
  }

  // Rectangle, per axis: the range of positions within every ball's reach along that axis;
  // if those ranges are empty any value in between serves, so the range collapses to it.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo[2] = {kInf, kInf};
  double hi[2] = {-kInf, -kInf};
  for (std::size_t i = 0; i < count; ++i) {
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], local[i][k] + reach[i]);
      hi[k] = std::max(hi[k], local[i][k] - reach[i]);
    }
  }
  for (int k = 0; k < 2; ++k) {
    if (lo[k] > hi[k]) lo[k] = hi[k] = 0.5 * (lo[k] + hi[k]);
  }
  // Excess of a centre beyond the rectangle along axis k (0 within its range).
  auto excess = [&](std::size_t i, int k) {
    return std::max(0.0, std::max(lo[k] - local[i][k], local[i][k] - hi[k]));
  };
  // Corners: a ball beyond a corner by more than its reach moves the nearer of the corner's
  // two edges outward until the corner is within reach (the per-axis pass guarantees the
  // excess along each axis alone is within reach, so the square roots are real). The
  // rectangle only grows, so one pass leaves every ball within reach.
  for (std::size_t i = 0; i < count; ++i) {
    const double e[2] = {excess(i, 0), excess(i, 1)};
    const double h = reach[i];
    if (e[0] == 0.0 || e[1] == 0.0 || e[0] * e[0] + e[1] * e[1] <= h * h) continue;
    double grow[2];
    for (int k = 0; k < 2; ++k)
      grow[k] = e[k] - std::sqrt(std::max(0.0, h * h - e[1 - k] * e[1 - k]));
    // Grow the edge that adds less area.
    const int k = grow[0] * (hi[1] - lo[1]) <= grow[1] * (hi[0] - lo[0]) ? 0 : 1;
    if (local[i][k] < lo[k]) {
      lo[k] -= grow[k];
    } else {
      hi[k] += grow[k];
    }
  }
  // Tighten: move each edge inward as far as every ball stays within reach (a collapsed
  // range's midpoint, or an edge grown for a ball that a later growth also covers, can leave
  // room). Afterwards each edge of positive length has a ball at reach on it.
  for (int k = 0; k < 2; ++k) {
    double lo_max = hi[k];
    double hi_min = lo[k];
    for (std::size_t i = 0; i < count; ++i) {
      const double e = excess(i, 1 - k);
      const double along = std::sqrt(std::max(0.0, reach[i] * reach[i] - e * e));
      lo_max = std::min(lo_max, local[i][k] + along);
      hi_min = std::max(hi_min, local[i][k] - along);
    }
    // Both moves together must keep lo <= hi; each alone keeps every ball within reach, and
    // together too, since a ball can be beyond only one of the two edges.
    lo[k] = std::max(lo[k], lo_max);
    hi[k] = std::max(lo[k], std::min(hi[k], hi_min));
  }

  // The radius that actually contains every ball for this rectangle (`radius` but for
  // rounding), padded for the rounding of later distance computations.
  double fitted = 0.0;
  for (std::size_t i = 0; i < count; ++i) {
    const double dx = excess(i, 0);
    const double dy = excess(i, 1);
    const double dz = local[i].z() - z_mid;
    fitted = std::max(fitted, std::sqrt(dx * dx + dy * dy + dz * dz) + ball(i).radius);
  }
  rss.origin = mean + rss.axes * Vector3(lo[0], lo[1], z_mid);
  rss.length[0] = hi[0] - lo[0];
  rss.length[1] = hi[1] - lo[1];
  rss.radius = fitted + kRadiusPadUlps * kEpsilon * (fitted + magnitude);
  return rss;
}

}  // namespace inscribe
