// Conservative dilation (Section VI-A): envelope points from the dual complex, closed-form
// triple and circle points, a flat bounding-box tree over the balls for the "inside another
// sphere" test, and the growth to the boundary points nearest to the envelope points.
#include "inscribe/medial/sphere_dilation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "base/parallel.h"
#include "inscribe/balls/union_of_balls.h"

namespace inscribe {
namespace {

using Clock = std::chrono::steady_clock;
using Vector3L = Eigen::Matrix<long double, 3, 1>;

// An envelope point must lie on each of its spheres to within this fraction of the radius.
constexpr double kOnSphereTolerance = 1e-9;
// Strictly inside another sphere: |x - c| < r (1 - kInsideMargin). The margin is far above the
// rounding of a well-conditioned point (~1e-15 r), so a point that lies exactly on a fourth
// sphere (co-spherical centres: symmetric input) stays on the envelope.
constexpr double kInsideMargin = 1e-12;
// h^2 (squared half-distance between the two points of a triple or a circle) within this
// fraction of r^2 below 0 is rounding of a tangent configuration: one point.
constexpr long double kTangentTolerance = 1e-12L;

// Flat binary tree over the balls' bounding boxes (median split of the centres on the widest
// axis, leaves of up to kLeafSize balls). An inner node's children are nodes[first] and
// nodes[first + 1]; a leaf lists order[first, first + count). Depth <= log2(n) + 1 since the
// splits are medians, so a fixed traversal stack suffices.
class BallTree {
 public:
  explicit BallTree(const std::vector<Sphere>& spheres) : spheres_(spheres) {
    if (spheres.empty()) return;
    order_.resize(spheres.size());
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = static_cast<std::int32_t>(i);
    nodes_.reserve(2 * spheres.size() / kLeafSize + 2);
    nodes_.emplace_back();
    Build(0, 0, static_cast<std::int32_t>(order_.size()));
  }

  // True when x is strictly inside (margin kInsideMargin) a ball whose index is not in
  // `exclude` (entries -1 are ignored). Cost O(log n + balls whose box holds x).
  bool InsideAnyOther(const Vector3& x, const std::array<std::int32_t, 3>& exclude) const {
    if (nodes_.empty()) return false;
    std::int32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
      if (!node.box.contains(x)) continue;
      if (node.count == 0) {
        stack[top++] = node.first;
        stack[top++] = node.first + 1;
        continue;
      }
      for (std::int32_t k = node.first; k < node.first + node.count; ++k) {
        const std::int32_t b = order_[static_cast<std::size_t>(k)];
        if (b == exclude[0] || b == exclude[1] || b == exclude[2]) continue;
        const Sphere& s = spheres_[static_cast<std::size_t>(b)];
        const double limit = s.radius * (1.0 - kInsideMargin);
        if ((x - s.center).squaredNorm() < limit * limit) return true;
      }
    }
    return false;
  }

 private:
  static constexpr std::int32_t kLeafSize = 4;

  struct Node {
    Eigen::AlignedBox3d box;
    std::int32_t first = 0;
    std::int32_t count = 0;  // 0 for an inner node
  };

  // Box of ball b, padded outward by a few ulps of its coordinates so that rounding of c +- r
  // never excludes a point inside the ball.
  Eigen::AlignedBox3d BallBox(std::int32_t b) const {
    const Sphere& s = spheres_[static_cast<std::size_t>(b)];
    const double pad = s.radius + 4.0 * std::numeric_limits<double>::epsilon() *
                                      (s.center.cwiseAbs().maxCoeff() + s.radius);
    return Eigen::AlignedBox3d(s.center.array() - pad, s.center.array() + pad);
  }

  void Build(std::size_t node_index, std::int32_t begin, std::int32_t end) {
    Eigen::AlignedBox3d box;
    Eigen::AlignedBox3d centres;
    for (std::int32_t k = begin; k < end; ++k) {
      const std::int32_t b = order_[static_cast<std::size_t>(k)];
      box.extend(BallBox(b));
      centres.extend(spheres_[static_cast<std::size_t>(b)].center);
    }
    nodes_[node_index].box = box;
    if (end - begin <= kLeafSize) {
      nodes_[node_index].first = begin;
      nodes_[node_index].count = end - begin;
      return;
    }
    int axis = 0;
    centres.sizes().maxCoeff(&axis);
    const std::int32_t middle = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                     [this, axis](std::int32_t a, std::int32_t b) {
                       const double ca = spheres_[static_cast<std::size_t>(a)].center[axis];
                       const double cb = spheres_[static_cast<std::size_t>(b)].center[axis];
                       return ca < cb || (ca == cb && a < b);
                     });
    const auto children = static_cast<std::int32_t>(nodes_.size());
    nodes_[node_index].first = children;
    nodes_[node_index].count = 0;
    nodes_.emplace_back();
    nodes_.emplace_back();
    Build(static_cast<std::size_t>(children), begin, middle);
    Build(static_cast<std::size_t>(children) + 1, middle, end);
  }

  const std::vector<Sphere>& spheres_;
  std::vector<std::int32_t> order_;
  std::vector<Node> nodes_;
};

Vector3L Long(const Vector3& v) { return v.cast<long double>(); }

bool OnSpheres(const std::vector<Sphere>& spheres, const EnvelopePoint& p) {
  for (std::int32_t s : p.spheres) {
    if (s < 0) continue;
    const Sphere& ball = spheres[static_cast<std::size_t>(s)];
    if (!(std::abs((p.point - ball.center).norm() - ball.radius) <=
          kOnSphereTolerance * ball.radius)) {
      return false;
    }
  }
  return true;
}

// Up to two points of one triangle or singleton edge, before the inside test.
struct Candidates {
  EnvelopePoint points[2];
  int count = 0;
  bool degenerate = false;
};

// The points common to spheres i < j < k, in long double relative to c_i: the radical line
// {x : |x|^2 - r_i^2 = |x - p_j|^2 - r_j^2 = |x - p_k|^2 - r_k^2} (p = c - c_i) is
// x0 + t n with n = p_j x p_k and x0 in the plane of the centres, and it meets sphere i at
// t = +-sqrt(r_i^2 - |x0|^2) / |n|.
Candidates TriplePoints(const std::vector<Sphere>& spheres, const std::array<std::int32_t, 3>& t) {
  Candidates out;
  const Sphere& si = spheres[static_cast<std::size_t>(t[0])];
  const Sphere& sj = spheres[static_cast<std::size_t>(t[1])];
  const Sphere& sk = spheres[static_cast<std::size_t>(t[2])];
  const Vector3L pj = Long(sj.center) - Long(si.center);
  const Vector3L pk = Long(sk.center) - Long(si.center);
  const Vector3L n = pj.cross(pk);
  const long double nn = n.squaredNorm();
  const long double ri2 = static_cast<long double>(si.radius) * si.radius;
  if (!(nn > 0.0L)) {  // collinear centres: a circle or nothing, never isolated points
    out.degenerate = true;
    return out;
  }
  const long double bj =
      0.5L * (pj.squaredNorm() + ri2 - static_cast<long double>(sj.radius) * sj.radius);
  const long double bk =
      0.5L * (pk.squaredNorm() + ri2 - static_cast<long double>(sk.radius) * sk.radius);
  const Vector3L x0 = (bj * pk.cross(n) + bk * n.cross(pj)) / nn;
  long double h2 = ri2 - x0.squaredNorm();
  if (h2 < 0.0L) {
    if (h2 < -kTangentTolerance * ri2) {
      out.degenerate = true;
      return out;
    }
    h2 = 0.0L;
  }
  const long double step = std::sqrt(h2 / nn);
  const Vector3L base = Long(si.center) + x0;
  out.count = h2 > 0.0L ? 2 : 1;
  for (int s = 0; s < out.count; ++s) {
    out.points[s].point = (base + (s == 0 ? step : -step) * n).cast<double>();
    out.points[s].spheres = t;
    if (!OnSpheres(spheres, out.points[s])) {
      out.count = 0;
      out.degenerate = true;
      return out;
    }
  }
  return out;
}

std::uint64_t SplitMix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Two opposite points of the circle where spheres i < j meet, at an angle in [0, 2 pi) hashed
// from (seed, i, j) in a frame fixed by the axis alone (Eigen's unitOrthogonal).
Candidates CirclePoints(const std::vector<Sphere>& spheres, std::int32_t i, std::int32_t j,
                        std::uint64_t seed) {
  Candidates out;
  const Sphere& si = spheres[static_cast<std::size_t>(i)];
  const Sphere& sj = spheres[static_cast<std::size_t>(j)];
  const Vector3L axis = Long(sj.center) - Long(si.center);
  const long double d = axis.norm();
  if (!(d > 0.0L)) {
    out.degenerate = true;
    return out;
  }
  const long double ri = si.radius;
  const long double rj = sj.radius;
  // Distance from c_i to the circle's plane along the axis, and the circle's squared radius.
  const long double a = (d * d + ri * ri - rj * rj) / (2.0L * d);
  long double rho2 = (ri - a) * (ri + a);
  if (rho2 < 0.0L) {
    if (rho2 < -kTangentTolerance * ri * ri) {
      out.degenerate = true;
      return out;
    }
    rho2 = 0.0L;
  }
  const Vector3L e = axis / d;
  const Vector3L u = e.unitOrthogonal();
  const Vector3L w = e.cross(u);
  const std::uint64_t hash = SplitMix64(
      seed ^ SplitMix64((static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) |
                        static_cast<std::uint32_t>(j)));
  const long double angle = 2.0L * 3.14159265358979323846264338327950288L *
                            static_cast<long double>(hash >> 11) * 0x1.0p-53L;
  const Vector3L radial = std::sqrt(rho2) * (std::cos(angle) * u + std::sin(angle) * w);
  const Vector3L centre = Long(si.center) + a * e;
  out.count = rho2 > 0.0L ? 2 : 1;
  for (int s = 0; s < out.count; ++s) {
    out.points[s].point =
        (s == 0 ? Vector3L(centre + radial) : Vector3L(centre - radial)).cast<double>();
    out.points[s].spheres = {i, j, -1};
    if (!OnSpheres(spheres, out.points[s])) {
      out.count = 0;
      out.degenerate = true;
      return out;
    }
  }
  return out;
}

// Computes `make(item)` for every item in parallel, drops points strictly inside another
// sphere, and appends the survivors to `points` in item order (deterministic).
template <typename Item, typename Make>
std::int64_t CollectPoints(const std::vector<Item>& items, const BallTree& tree, const Make& make,
                           std::vector<EnvelopePoint>* points) {
  std::vector<Candidates> candidates(items.size());
  internal::ParallelForRange(
      std::size_t{0}, items.size(), 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t t = begin; t != end; ++t) {
          Candidates c = make(items[t]);
          int kept = 0;
          for (int s = 0; s < c.count; ++s) {
            if (!tree.InsideAnyOther(c.points[s].point, c.points[s].spheres)) {
              c.points[kept++] = c.points[s];
            }
          }
          c.count = kept;
          candidates[t] = c;
        }
      });
  std::int64_t degenerate = 0;
  for (const Candidates& c : candidates) {
    degenerate += c.degenerate;
    for (int s = 0; s < c.count; ++s) points->push_back(c.points[s]);
  }
  return degenerate;
}

// Edges of `complex` that are a side of none of its triangles. Both lists are sorted.
std::vector<std::array<std::int32_t, 2>> SingletonEdges(const DualComplex& complex) {
  std::vector<char> in_triangle(complex.edges.size(), 0);
  const auto mark = [&](std::int32_t a, std::int32_t b) {
    const std::array<std::int32_t, 2> edge = {a, b};
    const auto it = std::lower_bound(complex.edges.begin(), complex.edges.end(), edge);
    if (it != complex.edges.end() && *it == edge) in_triangle[it - complex.edges.begin()] = 1;
  };
  for (const auto& t : complex.triangles) {
    mark(t[0], t[1]);
    mark(t[0], t[2]);
    mark(t[1], t[2]);
  }
  std::vector<std::array<std::int32_t, 2>> singletons;
  for (std::size_t e = 0; e < complex.edges.size(); ++e) {
    if (!in_triangle[e]) singletons.push_back(complex.edges[e]);
  }
  return singletons;
}

}  // namespace

absl::StatusOr<EnvelopePoints> ComputeEnvelopePoints(const std::vector<Sphere>& spheres,
                                                     const DilationOptions& options) {
  if (absl::Status s = CheckSpheres(spheres); !s.ok()) return s;
  EnvelopePoints out;
  if (spheres.empty()) return out;
  absl::StatusOr<DualComplex> complex = ComputeDualComplex(spheres);
  if (!complex.ok()) return complex.status();
  const BallTree tree(spheres);

  out.complex_triangles = static_cast<std::int64_t>(complex->triangles.size());
  out.degenerate = CollectPoints(
      complex->triangles, tree,
      [&spheres](const std::array<std::int32_t, 3>& t) { return TriplePoints(spheres, t); },
      &out.v_points);

  const std::vector<std::array<std::int32_t, 2>> singletons = SingletonEdges(*complex);
  out.singleton_edges = static_cast<std::int64_t>(singletons.size());
  if (options.singleton_edges) {
    const std::uint64_t seed = options.seed;
    out.degenerate += CollectPoints(
        singletons, tree,
        [&spheres, seed](const std::array<std::int32_t, 2>& e) {
          return CirclePoints(spheres, e[0], e[1], seed);
        },
        &out.circle_points);
  }
  return out;
}

absl::Status CheckDilationOptions(const DilationOptions& options) {
  if (!(options.growth >= 0.0 && options.growth <= 1.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("dilation growth must lie in [0, 1], got ", options.growth));
  }
  return absl::OkStatus();
}

absl::StatusOr<DilationResult> DilateSpheres(const BoundaryOracle& oracle, const SphereSet& spheres,
                                             const DilationOptions& options) {
  if (absl::Status s = CheckDilationOptions(options); !s.ok()) return s;
  const Clock::time_point start = Clock::now();
  const std::vector<Sphere>& balls = spheres.spheres;
  absl::StatusOr<EnvelopePoints> envelope = ComputeEnvelopePoints(balls, options);
  if (!envelope.ok()) return envelope.status();

  DilationResult result;
  result.set.spheres = balls;
  result.v_points = static_cast<std::int64_t>(envelope->v_points.size());
  result.edge_points = static_cast<std::int64_t>(envelope->circle_points.size());
  result.degenerate = envelope->degenerate;

  // Nearest boundary point of each centre: |x - m_s| bounds the search from an envelope point
  // x on sphere s, which then only visits the boundary near x.
  std::vector<Vector3> centre_closest(balls.size());
  internal::ParallelForRange(std::size_t{0}, balls.size(), 64,
                             [&](std::size_t begin, std::size_t end) {
                               for (std::size_t s = begin; s != end; ++s) {
                                 centre_closest[s] = oracle.ClosestPoint(balls[s].center).point;
                               }
                             });

  // Per envelope point and sphere slot: the radius that reaches the point's nearest boundary
  // point from that sphere's (original) centre.
  std::vector<const EnvelopePoint*> points;
  points.reserve(envelope->v_points.size() + envelope->circle_points.size());
  for (const EnvelopePoint& p : envelope->v_points) points.push_back(&p);
  for (const EnvelopePoint& p : envelope->circle_points) points.push_back(&p);
  std::vector<std::array<double, 3>> reach(points.size());
  internal::ParallelForRange(
      std::size_t{0}, points.size(), 64, [&](std::size_t begin, std::size_t end) {
        for (std::size_t q = begin; q != end; ++q) {
          const EnvelopePoint& p = *points[q];
          double bound = std::numeric_limits<double>::infinity();
          for (std::int32_t s : p.spheres) {
            if (s >= 0) {
              bound =
                  std::min(bound, (p.point - centre_closest[static_cast<std::size_t>(s)]).norm());
            }
          }
          const Vector3 m =
              oracle.ClosestPoint(p.point, BoundaryOracle::PaddedDistanceBound(bound)).point;
          for (int k = 0; k < 3; ++k) {
            const std::int32_t s = p.spheres[static_cast<std::size_t>(k)];
            reach[q][static_cast<std::size_t>(k)] =
                s >= 0 ? (balls[static_cast<std::size_t>(s)].center - m).norm() : 0.0;
          }
        }
      });

  std::vector<Sphere>& grown = result.set.spheres;
  for (std::size_t q = 0; q < points.size(); ++q) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t s = points[q]->spheres[static_cast<std::size_t>(k)];
      if (s < 0) continue;
      double& r = grown[static_cast<std::size_t>(s)].radius;
      r = std::max(r, reach[q][static_cast<std::size_t>(k)]);
    }
  }
  for (std::size_t s = 0; s < balls.size(); ++s) {
    if (options.growth != 1.0 && grown[s].radius > balls[s].radius) {
      grown[s].radius = balls[s].radius + options.growth * (grown[s].radius - balls[s].radius);
    }
    const double growth = grown[s].radius - balls[s].radius;
    if (growth > 0.0) {
      ++result.grown;
      result.max_growth = std::max(result.max_growth, growth);
    }
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace inscribe
