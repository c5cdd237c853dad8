#include "cover/cover_constructions.h"

#include <CGAL/Min_sphere_of_points_d_traits_3.h>
#include <CGAL/Min_sphere_of_spheres_d.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>

#include "base/parallel.h"

namespace inscribe::internal {
namespace {

// Rounds of re-clustering after the farthest-first centres.
constexpr int kClusterRounds = 2;
// Halvings of the first rung tried where it lies past the medial axis (a thin part).
constexpr int kThinHalvings = 6;
// Steps of the search for the deepest centre on a normal (each shrinks the interval by 0.618).
constexpr int kGoldenSteps = 10;

// A piece of the boundary (or an interior point) owned by a sphere.
struct Owned {
  std::uint32_t sphere;
  Vector3 point;
};

}  // namespace

std::vector<Sphere> LadderCandidates(const Solid& solid, const std::vector<LadderBase>& base,
                                     double s0, double s_max, std::vector<Vector3>* interior) {
  const BoundaryOracle& oracle = solid.oracle;
  const double factor = std::sqrt(2.0);
  int ladder = 1;
  while (s0 * std::pow(factor, ladder) <= s_max) ++ladder;
  const int rungs = ladder + 1;  // the last slot: the deepest centre on the normal
  std::vector<Sphere> slots(base.size() * static_cast<std::size_t>(rungs),
                            Sphere{Vector3::Zero(), 0.0});
  ParallelFor(std::size_t{0}, base.size(), [&](std::size_t b) {
    const Vector3& p = base[b].point;
    Vector3 normal;
    if (base[b].vertex >= 0) {
      normal = oracle.vertex_normals()[static_cast<std::size_t>(base[b].vertex)];
    } else {
      normal = oracle.face_normals()[static_cast<std::size_t>(oracle.ClosestPoint(p).triangle)];
    }
    Sphere* slot = &slots[b * static_cast<std::size_t>(rungs)];
    // Depth of the centre at distance s along the inward normal; 0 outside.
    const auto depth = [&](double s) {
      const Vector3 c = p - s * normal;
      const BoundaryPoint closest = oracle.ClosestPoint(c);
      return oracle.Classify(c, closest) == Side::kInside ? closest.distance : 0.0;
    };
    // The solid may lie on the normal's other side (a triangle the mesh orients against its
    // neighbours; a vertex where such triangles meet); a part thinner than 2 s0 has its
    // medial axis before the first rung: start lower there.
    if (!(normal.norm() > 0.0)) return;
    normal.normalize();
    double first = s0;
    for (int halvings = 0; halvings <= kThinHalvings; ++halvings, first *= 0.5) {
      if (depth(first) > 0.0) break;
      if (depth(-first) > 0.0) {
        normal = -normal;
        break;
      }
    }
    double last = 0.0, last_s = 0.0, before_s = 0.0;
    int k = 0;
    for (; k < ladder; ++k) {
      const double s = first * std::pow(factor, k);
      const double d = depth(s);
      // Past the medial axis the centre nears another part of the boundary: stop.
      if (d <= last) break;
      slot[k] = Sphere{p - s * normal, d};
      last = d;
      before_s = last_s;
      last_s = s;
    }
    if (k == 0) return;
    // The deepest centre lies between the rung before the last and the first that failed:
    // a golden-section search of the depth along the normal.
    double lo = before_s, hi = k < ladder ? first * std::pow(factor, k) : last_s;
    const double phi = 0.5 * (std::sqrt(5.0) - 1.0);
    double m1 = hi - phi * (hi - lo), m2 = lo + phi * (hi - lo);
    double d1 = depth(m1), d2 = depth(m2);
    for (int step = 0; step < kGoldenSteps; ++step) {
      if (d1 < d2) {
        lo = m1;
        m1 = m2;
        d1 = d2;
        m2 = lo + phi * (hi - lo);
        d2 = depth(m2);
      } else {
        hi = m2;
        m2 = m1;
        d2 = d1;
        m1 = hi - phi * (hi - lo);
        d1 = depth(m1);
      }
    }
    const double s = 0.5 * (lo + hi), d = depth(s);
    if (d > last) slot[ladder] = Sphere{p - s * normal, d};
  });
  std::vector<Sphere> out;
  for (std::size_t b = 0; b < base.size(); ++b) {
    const Sphere* deepest = nullptr;
    for (int k = 0; k < rungs; ++k) {
      const Sphere& s = slots[b * static_cast<std::size_t>(rungs) + static_cast<std::size_t>(k)];
      if (s.radius > 0.0) {
        out.push_back(s);
        deepest = &s;
      }
    }
    if (deepest != nullptr) interior->push_back(deepest->center);
  }
  return out;
}

namespace {

// Calls visit(sphere, point) for the corners of every piece a sphere owns (OwnedPoints' rule)
// and for every interior point with its sphere, from the threads of a parallel loop over the
// triangles, then over the interior points, each visit with the index of its triangle or
// interior point (interior points after the triangles).
template <typename Visit>
void ForEachOwned(const Mesh& mesh, const std::vector<Sphere>& spheres,
                  const std::vector<Vector3>& interior, double edge, const Visit& visit) {
  const std::size_t n = spheres.size();
  const auto growth = [&spheres](std::size_t i, const Vector3& p) {
    return (p - spheres[i].center).norm() - spheres[i].radius;
  };
  std::vector<std::size_t> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = i;
  // Splits a triangle in 4 (at its edges' midpoints) until its edges are short, keeping the
  // spheres that can still be best for a part of it: the growth to any point of a triangle is
  // within its diameter of the growth to its centroid.
  const std::function<void(std::size_t, const Vector3&, const Vector3&, const Vector3&,
                           const std::vector<std::size_t>&)>
      hold = [&](std::size_t item, const Vector3& p, const Vector3& q, const Vector3& r,
                 const std::vector<std::size_t>& candidates) {
        const double diameter = std::max({(q - p).norm(), (r - p).norm(), (r - q).norm()});
        // The sphere that holds the whole piece with the least growth (a ball holds a
        // triangle when it holds its corners), and the least growth any sphere needs at the
        // centroid, which no finer split can go below at that point.
        std::size_t pick = candidates.front();
        double least = std::numeric_limits<double>::infinity();
        for (const std::size_t i : candidates) {
          const double g = std::max({growth(i, p), growth(i, q), growth(i, r)});
          if (g < least) {
            least = g;
            pick = i;
          }
        }
        const Vector3 centroid = (p + q + r) / 3.0;
        std::vector<double> at(candidates.size());
        double best = std::numeric_limits<double>::infinity();
        std::array<double, 3> corner_best;
        corner_best.fill(std::numeric_limits<double>::infinity());
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          best = std::min(best, at[k] = growth(candidates[k], centroid));
          corner_best[0] = std::min(corner_best[0], growth(candidates[k], p));
          corner_best[1] = std::min(corner_best[1], growth(candidates[k], q));
          corner_best[2] = std::min(corner_best[2], growth(candidates[k], r));
        }
        // No split holds the centroid or a corner with less growth than the least any sphere
        // needs there. Whole, when splitting could save at most `edge` of growth over that (or
        // the piece is small).
        const double floor = std::max({best, corner_best[0], corner_best[1], corner_best[2], 0.0});
        if (diameter <= edge || least <= floor + edge) {
          visit(item, pick, p);
          visit(item, pick, q);
          visit(item, pick, r);
          return;
        }
        std::vector<std::size_t> near;
        for (std::size_t k = 0; k < candidates.size(); ++k) {
          if (at[k] <= best + 2.0 * diameter) near.push_back(candidates[k]);
        }
        const Vector3 pq = 0.5 * (p + q), qr = 0.5 * (q + r), rp = 0.5 * (r + p);
        hold(item, p, pq, rp, near);
        hold(item, pq, q, qr, near);
        hold(item, rp, qr, r, near);
        hold(item, pq, qr, rp, near);
      };
  const auto triangles = static_cast<std::size_t>(mesh.triangles.rows());
  ParallelFor(std::size_t{0}, triangles, [&](std::size_t t) {
    const auto row = static_cast<Eigen::Index>(t);
    hold(t, mesh.vertices.row(mesh.triangles(row, 0)).transpose(),
         mesh.vertices.row(mesh.triangles(row, 1)).transpose(),
         mesh.vertices.row(mesh.triangles(row, 2)).transpose(), all);
  });
  ParallelFor(std::size_t{0}, interior.size(), [&](std::size_t p) {
    std::size_t pick = 0;
    double least = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const double g = growth(i, interior[p]);
      if (g < least) {
        least = g;
        pick = i;
      }
    }
    visit(triangles + p, pick, interior[p]);
  });
}

}  // namespace

std::vector<std::vector<Vector3>> OwnedPoints(const Mesh& mesh, const std::vector<Sphere>& spheres,
                                              const std::vector<Vector3>& interior, double edge) {
  // Per triangle or interior point, its pieces' corners (each item is visited by one thread).
  std::vector<std::vector<Owned>> pieces(static_cast<std::size_t>(mesh.triangles.rows()) +
                                         interior.size());
  ForEachOwned(mesh, spheres, interior, edge,
               [&](std::size_t item, std::size_t sphere, const Vector3& p) {
                 pieces[item].push_back({static_cast<std::uint32_t>(sphere), p});
               });
  std::vector<std::vector<Vector3>> owned(spheres.size());
  for (const std::vector<Owned>& list : pieces) {
    for (const Owned& o : list) owned[o.sphere].push_back(o.point);
  }
  return owned;
}

std::vector<Sphere> HoldBoundary(const Mesh& mesh, const std::vector<Sphere>& spheres,
                                 const std::vector<Vector3>& interior, double edge, double margin) {
  // Per sphere, the farthest point it owns, kept as the bits of a non-negative double (whose
  // order is the integers'), so threads can raise it with an atomic max.
  std::vector<std::atomic<std::uint64_t>> reach(spheres.size());
  for (std::atomic<std::uint64_t>& r : reach) r.store(0);
  std::vector<std::atomic<bool>> owns(spheres.size());
  for (std::atomic<bool>& o : owns) o.store(false);
  ForEachOwned(
      mesh, spheres, interior, edge, [&](std::size_t, std::size_t sphere, const Vector3& p) {
        const double d = (p - spheres[sphere].center).norm();
        std::uint64_t bits = 0;
        std::memcpy(&bits, &d, sizeof bits);
        std::uint64_t seen = reach[sphere].load(std::memory_order_relaxed);
        while (seen < bits &&
               !reach[sphere].compare_exchange_weak(seen, bits, std::memory_order_relaxed)) {
        }
        if (!owns[sphere].load(std::memory_order_relaxed)) owns[sphere].store(true);
      });
  std::vector<Sphere> out = spheres;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!owns[i].load()) continue;
    double d = 0.0;
    const std::uint64_t bits = reach[i].load();
    std::memcpy(&d, &bits, sizeof d);
    out[i].radius = std::max(out[i].radius, (d + margin) * (1.0 + kReachMargin));
  }
  return out;
}

Sphere EnclosingBall(const std::vector<Vector3>& points) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Traits = CGAL::Min_sphere_of_points_d_traits_3<Kernel, double>;
  using MinSphere = CGAL::Min_sphere_of_spheres_d<Traits>;
  std::vector<Kernel::Point_3> input;
  input.reserve(points.size());
  for (const Vector3& p : points) input.emplace_back(p.x(), p.y(), p.z());
  MinSphere min_sphere(input.begin(), input.end());
  Sphere out;
  auto coordinate = min_sphere.center_cartesian_begin();
  for (int k = 0; k < 3; ++k, ++coordinate) out.center[k] = CGAL::to_double(*coordinate);
  // The radius that really holds every point from that centre (CGAL's is exact only up to its
  // number type), padded for the rounding of that distance.
  double radius = 0.0;
  for (const Vector3& p : points) radius = std::max(radius, (p - out.center).norm());
  out.radius = radius * (1.0 + kReachMargin) + std::numeric_limits<double>::denorm_min();
  return out;
}

std::vector<Sphere> KCenterBalls(const std::vector<Vector3>& points, std::size_t k) {
  const std::size_t n = points.size();
  if (n == 0) return {};
  k = std::max<std::size_t>(1, std::min(k, n));
  Vector3 mean = Vector3::Zero();
  for (const Vector3& p : points) mean += p;
  mean /= static_cast<double>(n);
  // Farthest-first traversal: each point's distance to its nearest centre so far.
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  std::vector<std::uint32_t> cluster(n, 0);
  std::size_t next = 0;
  for (std::size_t i = 1; i < n; ++i) {
    if ((points[i] - mean).squaredNorm() > (points[next] - mean).squaredNorm()) next = i;
  }
  std::vector<Vector3> centres;
  while (centres.size() < k) {
    const Vector3 c = points[next];
    const auto index = static_cast<std::uint32_t>(centres.size());
    centres.push_back(c);
    ParallelFor(std::size_t{0}, n, [&](std::size_t i) {
      const double d = (points[i] - c).squaredNorm();
      if (d < nearest[i]) {
        nearest[i] = d;
        cluster[i] = index;
      }
    });
    next = static_cast<std::size_t>(std::max_element(nearest.begin(), nearest.end()) -
                                    nearest.begin());
    if (!(nearest[next] > 0.0)) break;  // every point is a centre
  }
  std::vector<Sphere> balls;
  for (int round = 0;; ++round) {
    std::vector<std::vector<Vector3>> members(centres.size());
    for (std::size_t i = 0; i < n; ++i) members[cluster[i]].push_back(points[i]);
    balls.clear();
    for (const std::vector<Vector3>& m : members) {
      if (!m.empty()) balls.push_back(EnclosingBall(m));
    }
    if (round == kClusterRounds) break;
    centres.resize(balls.size());
    ParallelFor(std::size_t{0}, n, [&](std::size_t i) {
      double least = std::numeric_limits<double>::infinity();
      for (std::size_t b = 0; b < balls.size(); ++b) {
        const double g = (points[i] - balls[b].center).norm() - balls[b].radius;
        if (g < least) {
          least = g;
          cluster[i] = static_cast<std::uint32_t>(b);
        }
      }
    });
  }
  return balls;
}

// The budgets up to kMonotoneCoverBudget at which every construction runs: 1..8, then about
// every factor of sqrt(2) (11, 16, 23, 32, 45, 64).
bool ConstructionBudget(std::int64_t n) {
  if (n <= 8 || n == kMonotoneCoverBudget) return true;
  const double steps = 2.0 * std::log2(static_cast<double>(n) / 8.0);
  const std::int64_t below =
      static_cast<std::int64_t>(std::round(8.0 * std::exp2(std::floor(steps) / 2.0)));
  const std::int64_t above =
      static_cast<std::int64_t>(std::round(8.0 * std::exp2(std::ceil(steps) / 2.0)));
  return n == below || n == above;
}

namespace {

// The sum of a cover's positive protrusions: the second key of the comparison.
double SummedProtrusion(const GeneratedCover& cover) {
  double sum = 0.0;
  for (const double p : cover.certificate.protrusions) sum += std::max(p, 0.0);
  return sum;
}

}  // namespace

// The better of two certified covers: the lesser delta, then the lesser summed protrusion,
// then fewer spheres.
bool BetterCover(const GeneratedCover& a, const GeneratedCover& b) {
  const double da = a.certificate.delta, db = b.certificate.delta;
  if (da != db) return da < db;
  const double sa = SummedProtrusion(a), sb = SummedProtrusion(b);
  if (sa != sb) return sa < sb;
  return a.set.size() < b.set.size();
}

// Depth of a point: its distance to the boundary, negative outside.
double Depth(const Solid& solid, const Vector3& p) {
  const BoundaryPoint closest = solid.oracle.ClosestPoint(p);
  return solid.oracle.Classify(p, closest) == Side::kInside ? closest.distance : -closest.distance;
}

}  // namespace inscribe::internal
