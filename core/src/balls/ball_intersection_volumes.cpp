// Closed-form volumes of intersections of balls.
//
// Derivation (written for this project; the same ingredients as Edelsbrunner & Fu 1994,
// "Measuring space filling diagrams and voids", and Mach & Koehl's AlphaBall, 2011: caps,
// circular segments and the dihedral angles of the tetrahedra of centres and common points).
//
// Ball m: centre c_m, radius r_m, power pi_m(x) = |x - c_m|^2 - r_m^2. X = ∩ b_m is where the
// largest power is <= 0. Split X by which power is largest: X_m = b_m ∩ W_m with
// W_m = {x : pi_m(x) >= pi_n(x) for all n}, a convex cone (a farthest-power cell) bounded by the
// radical planes H_mn = {pi_m = pi_n}. X_m is bounded by the spherical face F_m = S_m ∩ W_m and
// by planar faces G_mn = X ∩ W_m ∩ W_n ⊂ H_mn. The divergence theorem with apex c_m gives
// vol(X_m) = 1/3 ∮ (x - c_m)·ν dA: on F_m the integrand is r_m; on G_mn the outward normal is
// -u_mn (W_m lies on c_n's side of H_mn; u_mn is the unit vector from c_m to c_n) and the
// integrand is -a_mn, the signed distance from c_m to H_mn. G_mn is shared by X_m and X_n and
// a_mn + a_nm = d_mn = |c_n - c_m|, hence
//
//   vol(X) = 1/3 [ sum_m r_m area(F_m) - sum_{m<n} d_mn area(G_mn) ].                  (V)
//
// area(F_m) by Gauss-Bonnet on S_m (curvature 1 / r_m^2). F_m is a disk bounded by arcs of
// the circles C_mn = S_m ∩ S_n. F_m lies in the cap S_m ∩ b_n whose angular radius phi has
// cos(phi) = a_mn / r_m, so an arc of C_mn turning by psi about u_mn has total geodesic
// curvature psi a_mn / r_m. Where arcs of C_mn and C_mk meet at P, F_m is locally the
// intersection of two caps and its exterior angle is the angle between the projections of
// u_mn and u_mk onto the tangent plane: the dihedral angle eps at edge (c_m, P) of the
// tetrahedron (c_m, c_n, c_k, P). So
//
//   area(F_m) = r_m^2 [ 2 pi - sum_arcs psi a_mn / r_m - sum_corners eps ].              (A)
//
// Three balls whose spheres share two points P± = y ± h n (y: the point of the radical line in
// the plane of centres; -h^2 = pi(y)), which holds for every triangle of a dual complex. The
// W_m are three wedges about the line P+P-. On C_mn, measured about u_mn from the direction of
// the third centre c_k, the arc inside b_k is [-gamma, gamma] with gamma = atan2(h, s), s the
// signed distance from the circle's centre q_mn to y towards c_k (s < 0 when y lies beyond
// q_mn from c_k, i.e. y outside the triangle of centres: the arc is then more than half the
// circle). G_mn is the segment of the disk of C_mn beyond the chord P+P- on c_k's side, of area
// rho^2 gamma - s h. P+ and P- are mirror images, so both corners of F_m have the same eps.
//
// Four balls whose power point z (equal power to all four) lies in all four balls, which holds
// for every tetrahedron of a dual complex. The W_m are trihedral cones with apex z, each F_m a
// spherical triangle. Its corner on the radical line of (m, n, k) is the common point of
// S_m, S_n, S_k inside the fourth ball b_l, which is y_mnk + h_mnk n with n pointing to c_l's
// side of the plane (c_m, c_n, c_k). About u_mn from the direction of c_k, the arc of C_mn
// inside b_k is [-gamma_k, gamma_k], the one inside b_l is [alpha - gamma_l, alpha + gamma_l]
// (alpha: dihedral angle of the tetrahedron of centres at edge c_m c_n), and the edge of X is
// their common part from alpha - gamma_l to gamma_k: psi_mn = gamma_k + gamma_l - alpha.
// G_mn is the triangle (z, P_mnk, P_mnl) plus the circular segment beyond its chord, of area
// rho^2 (psi - sin psi) / 2.
//
// In the inclusion-exclusion a tetrahedron's term is subtracted and its faces' terms added.
// Its corner angles on face m are the eps of its four triples, and gamma_k, gamma_l in psi_mn
// are the triples' half arcs: with W_mn = r_m^2 a_mn + r_n^2 a_nm, the tetrahedron holds
// -(1/3) r_m^3 eps and -(1/3) gamma (W_mn + d rho^2 / 2) for each, its triangle
// -(2/3) r_m^3 eps and -(1/3) gamma (2 W_mn + d rho^2). So a triangle with k tetrahedra of the
// complex on it weighs its angles by 1 - k/2 and the tetrahedra leave them out: 0 for a
// triangle inside the complex. The tetrahedron keeps 2 pi r_m^3 per sphere and, per pair,
// alpha (W_mn + d rho^2 / 2), the planar triangle and -d rho^2 sin(psi) / 2, sin(psi) from
// the three angles' cosines and sines.
//
// Everything is computed relative to the first ball's centre, so a large common offset costs
// no precision; Monte Carlo and quadrature tests (tests/core/union_of_balls_test.cpp) check
// every configuration.
#include "balls/ball_intersection_volumes.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace inscribe::internal {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Two spheres m < n, centres relative to a common origin.
struct PairGeometry {
  Vector3 u = Vector3::Zero();  // unit vector from c_m to c_n
  double d = 0.0;               // |c_n - c_m| > 0
  double a_m = 0.0;             // signed distance from c_m to the radical plane, along u
  double a_n = 0.0;             // from c_n, along -u; a_m + a_n = d
  double rho2 = 0.0;            // squared radius of the circle S_m ∩ S_n, 0 if they miss
  Vector3 q = Vector3::Zero();  // centre of that circle
};

PairGeometry MakePair(const Vector3& cm, double rm, const Vector3& cn, double rn) {
  PairGeometry p;
  const Vector3 v = cn - cm;
  p.d = v.norm();
  p.u = v / p.d;
  const double dr2 = (rm - rn) * (rm + rn);
  p.a_m = (p.d * p.d + dr2) / (2 * p.d);
  p.a_n = (p.d * p.d - dr2) / (2 * p.d);
  // rho^2 = r_m^2 - a_m^2, written as a product (Heron-like) so no difference of near-equal
  // squares is formed; negative exactly when the spheres do not meet.
  const double product = (rm + rn + p.d) * (rm + rn - p.d) * (p.d + rm - rn) * (p.d - rm + rn);
  p.rho2 = std::max(0.0, product) / (4 * p.d * p.d);
  p.q = cm + p.a_m * p.u;
  return p;
}

// Pair quantities seen from one of its two balls.
struct Oriented {
  Vector3 u;  // unit vector from this ball's centre to the other's
  double a;   // signed distance from this ball's centre to the radical plane
};

template <int N>
struct Pairs {
  PairGeometry p[N][N];  // filled for m < n

  const PairGeometry& Get(int m, int n) const { return m < n ? p[m][n] : p[n][m]; }
  Oriented From(int m, int n) const {
    return m < n ? Oriented{p[m][n].u, p[m][n].a_m} : Oriented{-p[n][m].u, p[n][m].a_n};
  }
};

// The two common points y ± h normal of three spheres (i, j, k).
struct TripleGeometry {
  Vector3 y = Vector3::Zero();       // the radical line's point in the plane of centres
  Vector3 normal = Vector3::Zero();  // unit normal of the plane of centres
  double h = 0.0;                    // >= 0; 0 when the spheres touch or (by rounding) miss
};

TripleGeometry MakeTriple(const Vector3& ci, double ri, const Vector3& cj, double rj,
                          const Vector3& ck, double rk) {
  // y - c_i = x solves x·e1 = b1, x·e2 = b2 within the plane of e1, e2 (the radical planes).
  const Vector3 e1 = cj - ci;
  const Vector3 e2 = ck - ci;
  const Vector3 n = e1.cross(e2);
  const double n2 = n.squaredNorm();
  const double b1 = (e1.squaredNorm() + (ri - rj) * (ri + rj)) / 2;
  const double b2 = (e2.squaredNorm() + (ri - rk) * (ri + rk)) / 2;
  const Vector3 x = (b1 * e2.cross(n) + b2 * n.cross(e1)) / n2;
  TripleGeometry t;
  t.y = ci + x;
  t.normal = n / std::sqrt(n2);
  const double xn = x.norm();
  t.h = std::sqrt(std::max(0.0, (ri - xn) * (ri + xn)));
  return t;
}

// Half the angle (gamma) of the arc of C_mn inside b_k, and s (see the derivation).
struct HalfArc {
  double gamma;
  double s;
};

// gamma is left 0 without `with_gamma` (its atan2 not needed).
HalfArc HalfArcInside(const PairGeometry& p, const Vector3& cm, const Vector3& ck,
                      const TripleGeometry& t, bool with_gamma = true) {
  Vector3 towards_k = ck - cm;
  towards_k -= towards_k.dot(p.u) * p.u;
  towards_k.normalize();
  const double s = (t.y - p.q).dot(towards_k);
  return {with_gamma ? std::atan2(t.h, s) : 0.0, s};
}

// Exterior angle eps of F_m at a common point of S_m, S_n, S_k: the angle between the
// projections of u_mn, u_mk on the plane normal to w = (P - c_m) / r_m. Using
// u·w = a / r_m and det(u_mn, u_mk, w) = ±sin(theta) h / r_m (theta: angle at c_m), scaled by
// r_m^2.
double CornerAngle(const Oriented& mn, const Oriented& mk, double rm, double h) {
  const double cos_theta = mn.u.dot(mk.u);
  const double sin_theta = mn.u.cross(mk.u).norm();
  return std::atan2(rm * h * sin_theta, rm * rm * cos_theta - mn.a * mk.a);
}

double Cube(double x) { return x * x * x; }

// (cos, sin) of atan2(y, x), y >= 0, without the atan2; (1, 0) for (0, 0) like atan2. Scaled
// first: x and y may be squared lengths up to 1e300.
struct UnitDirection {
  double c = 1.0;
  double s = 0.0;
  UnitDirection(double x, double y) {
    const double scale = std::max(std::abs(x), y);
    if (!(scale > 0)) return;
    x /= scale;
    y /= scale;
    const double norm = std::sqrt(x * x + y * y);
    c = x / norm;
    s = y / norm;
  }
};

// Dihedral angle alpha at edge (c_m, c_n) between the half-planes towards c_k and c_l, as
// (|pk| |pl| cos alpha, |pk| |pl| sin alpha), the arguments of atan2.
std::pair<double, double> DihedralDirection(const Vector3& u, const Vector3& cm, const Vector3& ck,
                                            const Vector3& cl) {
  Vector3 pk = ck - cm;
  Vector3 pl = cl - cm;
  pk -= pk.dot(u) * u;
  pl -= pl.dot(u) * u;
  return {pk.dot(pl), pk.cross(pl).norm()};
}

}  // namespace

double BallVolume(const Sphere& b) { return 4.0 / 3.0 * kPi * Cube(b.radius); }

double TwoBallIntersectionVolume(const Sphere& a, const Sphere& b) {
  const double d = (b.center - a.center).norm();
  const double ra = a.radius;
  const double rb = b.radius;
  if (d >= ra + rb) return 0.0;
  if (d <= std::abs(ra - rb)) return BallVolume(ra < rb ? a : b);
  // Lens = cap of a beyond the radical plane + cap of b. Cap heights in product form:
  // h_a = r_a - a_a = (r_a + r_b - d)(d - r_a + r_b) / (2d), both factors > 0 here.
  const double ha = (ra + rb - d) * (d - ra + rb) / (2 * d);
  const double hb = (ra + rb - d) * (d + ra - rb) / (2 * d);
  return kPi / 3.0 * (ha * ha * (3 * ra - ha) + hb * hb * (3 * rb - hb));
}

double ThreeBallIntersectionVolume(const Sphere& a, const Sphere& b, const Sphere& c,
                                   double angle_weight) {
  const Vector3 o = a.center;
  const Vector3 centre[3] = {Vector3::Zero(), b.center - o, c.center - o};
  const double r[3] = {a.radius, b.radius, c.radius};
  Pairs<3> pairs;
  for (int m = 0; m < 3; ++m) {
    for (int n = m + 1; n < 3; ++n) {
      pairs.p[m][n] = MakePair(centre[m], r[m], centre[n], r[n]);
    }
  }
  const TripleGeometry t = MakeTriple(centre[0], r[0], centre[1], r[1], centre[2], r[2]);

  // (V) with (A): each face has two arcs of angle 2 gamma and two corners of angle eps.
  const bool angles = angle_weight != 0.0;
  double faces = 0.0;
  for (int m = 0; m < 3; ++m) {
    const int n = (m + 1) % 3;
    const int k = (m + 2) % 3;
    const double eps =
        angles ? angle_weight * CornerAngle(pairs.From(m, n), pairs.From(m, k), r[m], t.h) : 0.0;
    faces += Cube(r[m]) * (2 * kPi - 2 * eps);
  }
  double planar = 0.0;
  for (int m = 0; m < 3; ++m) {
    for (int n = m + 1; n < 3; ++n) {
      const int k = 3 - m - n;
      const PairGeometry& p = pairs.p[m][n];
      const HalfArc arc = HalfArcInside(p, centre[m], centre[k], t, angles);
      const double gamma = angle_weight * arc.gamma;
      planar += 2 * gamma * (r[m] * r[m] * p.a_m + r[n] * r[n] * p.a_n);
      planar += p.d * (p.rho2 * gamma - arc.s * t.h);
    }
  }
  const double volume = (faces - planar) / 3.0;
  return angle_weight == 1.0 ? std::max(0.0, volume) : volume;
}

double FourBallVolumeWithoutFaceAngles(const Sphere& a, const Sphere& b, const Sphere& c,
                                       const Sphere& d) {
  const Vector3 o = a.center;
  const Vector3 centre[4] = {Vector3::Zero(), b.center - o, c.center - o, d.center - o};
  const double r[4] = {a.radius, b.radius, c.radius, d.radius};
  Pairs<4> pairs;
  for (int m = 0; m < 4; ++m) {
    for (int n = m + 1; n < 4; ++n) {
      pairs.p[m][n] = MakePair(centre[m], r[m], centre[n], r[n]);
    }
  }
  // triple[l]: the three balls other than l; its corner point is the common point inside b_l.
  TripleGeometry triple[4];
  Vector3 corner[4];
  for (int l = 0; l < 4; ++l) {
    int v[3];
    for (int m = 0, k = 0; m < 4; ++m) {
      if (m != l) v[k++] = m;
    }
    TripleGeometry& t = triple[l];
    t = MakeTriple(centre[v[0]], r[v[0]], centre[v[1]], r[v[1]], centre[v[2]], r[v[2]]);
    if ((centre[l] - t.y).dot(t.normal) < 0) t.normal = -t.normal;
    corner[l] = t.y + t.h * t.normal;
  }
  // Power point z (c_0 = 0): z·c_m = (|c_m|^2 + r_0^2 - r_m^2) / 2 for m = 1, 2, 3.
  double rhs[4];
  for (int m = 1; m < 4; ++m) {
    rhs[m] = (centre[m].squaredNorm() + (r[0] - r[m]) * (r[0] + r[m])) / 2;
  }
  const Vector3 z = (rhs[1] * centre[2].cross(centre[3]) + rhs[2] * centre[3].cross(centre[1]) +
                     rhs[3] * centre[1].cross(centre[2])) /
                    centre[1].dot(centre[2].cross(centre[3]));

  // (V) with (A), less the face angles: face m is a spherical triangle whose three corner
  // angles are those of the triples containing m, and whose arc on C_mn turns by
  // psi = gamma_k + gamma_l - alpha, the gammas being those of the triples (m, n, k) and
  // (m, n, l). Left: 2 pi per sphere, and per pair -alpha in the arc and segment terms, the
  // triangle, and the segment's -sin(psi).
  double faces = 0.0;
  for (int m = 0; m < 4; ++m) faces += Cube(r[m]) * 2 * kPi;
  double planar = 0.0;
  for (int m = 0; m < 4; ++m) {
    for (int n = m + 1; n < 4; ++n) {
      int k = -1;
      int l = -1;
      for (int x = 0; x < 4; ++x) {
        if (x == m || x == n) continue;
        (k < 0 ? k : l) = x;
      }
      const PairGeometry& p = pairs.p[m][n];
      // triple[l] holds (m, n, k), triple[k] holds (m, n, l).
      const UnitDirection gamma_k(HalfArcInside(p, centre[m], centre[k], triple[l], false).s,
                                  triple[l].h);
      const UnitDirection gamma_l(HalfArcInside(p, centre[m], centre[l], triple[k], false).s,
                                  triple[k].h);
      const auto [alpha_x, alpha_y] = DihedralDirection(p.u, centre[m], centre[k], centre[l]);
      const UnitDirection alpha_turn(alpha_x, alpha_y);
      const double alpha = std::atan2(alpha_y, alpha_x);
      // sin(gamma_k + gamma_l - alpha) from the three directions.
      const double c2 = gamma_k.c * gamma_l.c - gamma_k.s * gamma_l.s;
      const double s2 = gamma_k.c * gamma_l.s + gamma_k.s * gamma_l.c;
      const double sin_psi = s2 * alpha_turn.c - c2 * alpha_turn.s;
      const double triangle = 0.5 * (corner[l] - z).cross(corner[k] - z).norm();
      planar -= alpha * (r[m] * r[m] * p.a_m + r[n] * r[n] * p.a_n + 0.5 * p.d * p.rho2);
      planar += p.d * (triangle - 0.5 * p.rho2 * sin_psi);
    }
  }
  return (faces - planar) / 3.0;
}

}  // namespace inscribe::internal
