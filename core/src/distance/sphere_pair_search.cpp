#include "distance/sphere_pair_search.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "base/float_rounding.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(INSCRIBE_AVX2_FILTER)
#include <immintrin.h>
#endif

namespace inscribe::internal {

// Set during static initialisation, hence the explicit __builtin_cpu_init.
bool use_avx2_filter = [] {
#if defined(INSCRIBE_AVX2_FILTER)
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") != 0;
#else
  return false;
#endif
}();

namespace {

using Quad = SphereHierarchy::Quad;

// Node pairs with at most this many sphere pairs below them are compared pair by pair: the
// filter first drops the rows out of reach of the other node's sphere (most of them), then
// rejects four or eight pairs in a few instructions, much less than a step of the tree (the
// value was chosen on the Table II poses: docs/benchmarks/distance.md).
constexpr std::int64_t kAllPairs = 1024;
static_assert(kAllPairs <= 64 * 64, "the shorter side of a compared pair fits a 64-bit mask");

// A step splits both nodes (up to 4 x 4 Quad entries) when neither node's query sphere is more
// than this many times the other's radius, else only the bigger one (1.5-3 were equally fast).
constexpr double kSplitBothRatio = 2.0;

// b's centres are moved into a's frame in blocks of this many (aligned in the ordered arrays).
constexpr std::size_t kMoveBlock = 8;

// Float rounding. Let M be a power of two bounding every |coordinate| and radius the search
// reads in a's frame (the hierarchies' query spheres and spheres, b's moved by the relative
// pose) and u = 2^-24. Every float read is within u M of its double (rounded to nearest; b's
// centres are moved in double, then rounded), so a float centre distance is within 7 u M of
// the double one, its float square within a relative 3.01 u, its float square root within
// 16 u M (|d| <= 2 sqrt(3) M); sums and differences of radii and thresholds (magnitudes below
// 6 M) add at most 22 u M. A margin of 128 u M thus makes
//  - a node pair's float bound (centre distance - radii - margin, one side's sphere against
//    the other's Quad entries or Quad entries against Quad entries: the same operations on
//    the same rounded values) at least 90 u M below the double one, itself below every sphere
//    pair under the two nodes, up to the rotation's departure from orthonormality s
//    (|R x| <= (1 + s) |x|), which can shrink a moved child's distance to the node centre by s
//    times a radius (at most 2 M); the margin adds 4 s M;
//  - the sphere-pair filter (reject when the float squared centre distance is at least the
//    square of threshold + margin + r_a + r_b, the threshold clamped to [-4 M, 4 M] since no
//    pair's value leaves [-2 M, 3.5 M]) pass every pair whose double value is below the
//    threshold: its float reach exceeds its float distance by 99 u M, more than the 4.02 u |d|
//    and 2^-114 M^2 that rounding and underflow of the squares can add. It thus passes every
//    pair whose double value is below threshold + 85 u M + 4 s M;
//  - the row test (that filter applied to one sphere and the query sphere around the other
//    node) reject a sphere only when its value against that query sphere is at least
//    threshold + 85 u M + 4 s M; every sphere inside the query sphere (to the containment
//    slack, 1e-10 of a radius, and the move's departure, s times a radius) is then at least
//    the threshold away in double, so none of the row's pairs could pass.
// The AVX2 filter runs the same float operations lane by lane (no fused multiply-add).
// Bounding spheres accepted by Deserialize may leave a sphere out by 1e-10 of their radius,
// far below the margin. The search runs only when 2^-40 <= M <= 2^60: nothing overflows and
// denormals' absolute error (2^-149) stays far below the margin.
constexpr int kFloatMarginExponent = 7 - 24;  // 128 u M
constexpr int kFloatMinExponent = -40, kFloatMaxExponent = 60;

// Per-thread scratch kept between queries: b's ordered centres (by blocks of kMoveBlock) and
// b's Quads moved into a's frame in float, filled lazily; an entry is valid when its stamp
// equals the query's epoch.
struct Scratch {
  std::vector<float> x, y, z;
  std::vector<std::uint32_t> block_stamp;
  struct MovedQuad {
    float x[4], y[4], z[4];
  };
  std::vector<MovedQuad> quads;
  std::vector<std::uint32_t> quad_stamp;
  std::uint32_t epoch = 0;
  struct Pair {
    HierarchyRef a, b;
    float bound;  // a lower bound on the pairs below (conservative in float)
  };
  std::vector<Pair> stack;

  void Begin(std::size_t spheres, std::size_t nodes) {
    if (x.size() < spheres) {
      x.resize(spheres, 0.0f);
      y.resize(spheres, 0.0f);
      z.resize(spheres, 0.0f);
      block_stamp.resize(spheres / kMoveBlock + 1, 0);
    }
    if (quads.size() < nodes) {
      quads.resize(nodes, MovedQuad{});
      quad_stamp.resize(nodes, 0);
    }
    if (++epoch == 0) {  // wrapped: forget every stamp
      std::fill(block_stamp.begin(), block_stamp.end(), 0);
      std::fill(quad_stamp.begin(), quad_stamp.end(), 0);
      epoch = 1;
    }
    stack.clear();
  }
};

class FloatSearch {
 public:
  FloatSearch(const SphereHierarchy& a, const SphereHierarchy& b, const RelativeFrame& relative,
              const DistanceRequest& request, double scale, double margin, Scratch& scratch)
      : a_(a),
        b_(b),
        rel_(relative),
        request_(request),
        yes_no_(std::isfinite(request.closer_than)),
        threshold_(std::min(request.closer_than, request.max_distance)),
        scale_(scale),
        margin_(RoundUp(margin)),
        s_(scratch) {
    s_.Begin(b.ordered_spheres().size() + SphereHierarchy::kFloatPadding, b.num_nodes());
    UpdateFloatReach();
  }

  void Run(DistanceResult* out) {
    s_.stack.push_back({a_.root(), b_.root(), -std::numeric_limits<float>::infinity()});
    while (!s_.stack.empty()) {
      const Scratch::Pair p = s_.stack.back();
      s_.stack.pop_back();
      if (static_cast<double>(p.bound) >= threshold_) continue;
      const SphereHierarchy::Slot& sa = a_.slot(p.a);
      const SphereHierarchy::Slot& sb = b_.slot(p.b);
      if (std::int64_t{sa.count} * sb.count <= kAllPairs) {
        CompareAll(p.a, sa, p.b, sb, out);
        if (yes_no_ && best_ < request_.closer_than) break;
        continue;
      }
      const Sphere& qa = a_.query_sphere(p.a);
      const Sphere& qb = b_.query_sphere(p.b);
      if (sa.count > 1 && sb.count > 1 && qa.radius <= kSplitBothRatio * qb.radius &&
          qb.radius <= kSplitBothRatio * qa.radius) {
        ExpandBoth(p, out);
        continue;
      }
      const bool split_a = sa.count > 1 && (sb.count == 1 || qa.radius >= qb.radius);
      if (split_a) {
        const Vector3 cb = Move(qb.center);
        const Quad& q = a_.quad(p.a);
        Expand(q, q.x, q.y, q.z, cb, qb.radius, p, true, out);
      } else {
        const Quad& q = b_.quad(p.b);
        const Scratch::MovedQuad& m = MovedQuad(p.b, q);
        Expand(q, m.x, m.y, m.z, qa.center, qa.radius, p, false, out);
      }
    }
    if (best_a_ >= 0) {
      out->distance = best_;
      out->sphere_a = best_a_;
      out->sphere_b = best_b_;
    }
    out->closer = best_ < request_.closer_than;
  }

 private:
  Vector3 Move(const Vector3& p) const { return MoveToA(rel_, p); }

  void Improve(double d, std::int32_t sphere_a, std::int32_t sphere_b) {
    best_ = d;
    best_a_ = sphere_a;
    best_b_ = sphere_b;
    threshold_ = PruneThreshold(request_, d);
    UpdateFloatReach();
  }

  // The sphere-pair filter's threshold + margin, the threshold clamped to [-4 M, 4 M].
  void UpdateFloatReach() {
    const double clamped = std::clamp(threshold_, -4.0 * scale_, 4.0 * scale_);
    float_reach_ = static_cast<float>(clamped) + margin_;
  }

  // b's Quad of node `node` moved into a's frame (cached for the query).
  const Scratch::MovedQuad& MovedQuad(HierarchyRef node, const Quad& q) {
    const auto at = static_cast<std::size_t>(node);
    Scratch::MovedQuad& m = s_.quads[at];
    if (s_.quad_stamp[at] != s_.epoch) {
      s_.quad_stamp[at] = s_.epoch;
      for (int k = 0; k < 4; ++k) {
        if (k < q.size) {
          const Vector3 c = Move(b_.query_sphere(q.child[k]).center);
          m.x[k] = static_cast<float>(c.x());
          m.y[k] = static_cast<float>(c.y());
          m.z[k] = static_cast<float>(c.z());
        } else {
          m.x[k] = m.y[k] = m.z[k] = 0.0f;
        }
      }
    }
    return m;
  }

  // Bounds of the Quad's entries (centres x, y, z in a's frame, radii q.radius) against the
  // other side's sphere (centre `other` in a's frame, radius other_radius), four at once;
  // pushes the entries bounded below the threshold, the nearest on top (searched first).
  void Expand(const Quad& q, const float* x, const float* y, const float* z, const Vector3& other,
              double other_radius, const Scratch::Pair& parent, bool split_a, DistanceResult* out) {
    out->volume_tests += q.size;
    alignas(16) float bound[4];
    const float ox = static_cast<float>(other.x()), oy = static_cast<float>(other.y()),
                oz = static_cast<float>(other.z());
    const float shift = static_cast<float>(other_radius) + margin_;
#if defined(__SSE2__)
    const __m128 dx = _mm_sub_ps(_mm_loadu_ps(x), _mm_set1_ps(ox));
    const __m128 dy = _mm_sub_ps(_mm_loadu_ps(y), _mm_set1_ps(oy));
    const __m128 dz = _mm_sub_ps(_mm_loadu_ps(z), _mm_set1_ps(oz));
    const __m128 squared =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 gap = _mm_sub_ps(_mm_sqrt_ps(squared), _mm_loadu_ps(q.radius));
    _mm_store_ps(bound, _mm_sub_ps(gap, _mm_set1_ps(shift)));
#else
    for (int k = 0; k < 4; ++k) {
      const float dx = x[k] - ox, dy = y[k] - oy, dz = z[k] - oz;
      bound[k] = (std::sqrt(dx * dx + dy * dy + dz * dz) - q.radius[k]) - shift;
    }
#endif
    Scratch::Pair kept[4];
    int n = 0;
    for (int k = 0; k < q.size; ++k) {
      if (!(static_cast<double>(bound[k]) < threshold_)) continue;
      Scratch::Pair pair = split_a ? Scratch::Pair{q.child[k], parent.b, bound[k]}
                                   : Scratch::Pair{parent.a, q.child[k], bound[k]};
      // Insertion by decreasing bound: the nearest ends last.
      int at = n++;
      while (at > 0 && kept[at - 1].bound < pair.bound) {
        kept[at] = kept[at - 1];
        --at;
      }
      kept[at] = pair;
    }
    for (int k = 0; k < n; ++k) s_.stack.push_back(kept[k]);
  }

  // Swaps the nearest of the pairs pushed from stack position `first` on to the top, so that it
  // is searched first; the others stay in the order found. For ExpandBoth's up to 16 pairs,
  // sorting them all cost 12% more time on the Table II poses (Expand's up to four are sorted:
  // slightly faster there).
  void NearestOnTop(std::size_t first) {
    std::vector<Scratch::Pair>& stack = s_.stack;
    if (stack.size() <= first + 1) return;
    std::size_t nearest = first;
    for (std::size_t k = first + 1; k < stack.size(); ++k) {
      if (stack[k].bound < stack[nearest].bound) nearest = k;
    }
    std::swap(stack[nearest], stack.back());
  }

  // Both nodes' Quads against each other: up to 16 bounds, four at a time (a's entries in the
  // lanes, one of b's entries per pass); pushes the pairs bounded below the threshold, the
  // nearest on top.
  void ExpandBoth(const Scratch::Pair& parent, DistanceResult* out) {
    const Quad& qa = a_.quad(parent.a);
    const Quad& qb = b_.quad(parent.b);
    const Scratch::MovedQuad& mb = MovedQuad(parent.b, qb);
    out->volume_tests += qa.size * qb.size;
    alignas(16) float bound[4][4];
#if defined(__SSE2__)
    const __m128 ax = _mm_loadu_ps(qa.x), ay = _mm_loadu_ps(qa.y), az = _mm_loadu_ps(qa.z),
                 ar = _mm_loadu_ps(qa.radius);
    for (int j = 0; j < qb.size; ++j) {
      const __m128 dx = _mm_sub_ps(ax, _mm_set1_ps(mb.x[j]));
      const __m128 dy = _mm_sub_ps(ay, _mm_set1_ps(mb.y[j]));
      const __m128 dz = _mm_sub_ps(az, _mm_set1_ps(mb.z[j]));
      const __m128 squared =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      const __m128 gap = _mm_sub_ps(_mm_sqrt_ps(squared), ar);
      _mm_store_ps(bound[j], _mm_sub_ps(gap, _mm_set1_ps(qb.radius[j] + margin_)));
    }
#else
    for (int j = 0; j < qb.size; ++j) {
      for (int k = 0; k < 4; ++k) {
        const float dx = qa.x[k] - mb.x[j], dy = qa.y[k] - mb.y[j], dz = qa.z[k] - mb.z[j];
        bound[j][k] =
            (std::sqrt(dx * dx + dy * dy + dz * dz) - qa.radius[k]) - (qb.radius[j] + margin_);
      }
    }
#endif
    const std::size_t first = s_.stack.size();
    for (int j = 0; j < qb.size; ++j) {
      for (int k = 0; k < qa.size; ++k) {
        if (!(static_cast<double>(bound[j][k]) < threshold_)) continue;
        s_.stack.push_back({qa.child[k], qb.child[j], bound[j][k]});
      }
    }
    NearestOnTop(first);
  }

  // The double value of one sphere pair (positions in the ordered arrays), computed as the
  // brute force does; a new best pair when below the threshold.
  void ComparePair(std::int32_t i, std::int32_t j) {
    const Sphere& s = a_.ordered_spheres()[static_cast<std::size_t>(i)];
    const Sphere& t = b_.ordered_spheres()[static_cast<std::size_t>(j)];
    const double d = SphereGap(s.center, s.radius, Move(t.center), t.radius);
    if (d < threshold_) {
      Improve(d, a_.leaf_order()[static_cast<std::size_t>(i)],
              b_.leaf_order()[static_cast<std::size_t>(j)]);
    }
  }

  // Every sphere below a against every sphere below b through the float filter, four or eight
  // at a time; the pairs it passes go to ComparePair.
  void CompareAll(HierarchyRef ra, const SphereHierarchy::Slot& sa, HierarchyRef rb,
                  const SphereHierarchy::Slot& sb, DistanceResult* out) {
    const std::int32_t na = sa.count, nb = sb.count;
    const std::size_t b_spheres = b_.ordered_spheres().size();
    for (std::size_t block = static_cast<std::size_t>(sb.first) / kMoveBlock;
         block * kMoveBlock < static_cast<std::size_t>(sb.first + nb); ++block) {
      if (s_.block_stamp[block] == s_.epoch) continue;
      s_.block_stamp[block] = s_.epoch;
      const std::size_t end = std::min(block * kMoveBlock + kMoveBlock, b_spheres);
      for (std::size_t at = block * kMoveBlock; at < end; ++at) {
        const Vector3 c = Move(b_.ordered_spheres()[at].center);
        s_.x[at] = static_cast<float>(c.x());
        s_.y[at] = static_cast<float>(c.y());
        s_.z[at] = static_cast<float>(c.z());
      }
    }
    const auto fa = static_cast<std::size_t>(sa.first), fb = static_cast<std::size_t>(sb.first);
    const Side side_a{a_.float_x() + fa,      a_.float_y() + fa, a_.float_z() + fa,
                      a_.float_radius() + fa, sa.first,          na};
    const Side side_b{s_.x.data() + fb,       s_.y.data() + fb, s_.z.data() + fb,
                      b_.float_radius() + fb, sb.first,         nb};
    // The longer range fills the SIMD lanes. Each row is first tested against the query sphere
    // around the lanes' node, which bounds every pair of the row from below (the row test of
    // the margins' comment).
    const bool rows_are_a = nb >= na;
    const Sphere& q = rows_are_a ? b_.query_sphere(rb) : a_.query_sphere(ra);
    const FloatSphere around = RoundedSphere(rows_are_a ? Move(q.center) : q.center, q.radius);
    const Side& rows = rows_are_a ? side_a : side_b;
    const Side& lanes = rows_are_a ? side_b : side_a;
    const std::uint64_t rows_in_reach = RowsInReach(rows, around);
    // A row test counts as a volume test (a sphere against a node's sphere).
    out->volume_tests += rows.count;
    out->sphere_tests += std::int64_t{__builtin_popcountll(rows_in_reach)} * lanes.count;
    if (rows_in_reach == 0) return;
#if defined(INSCRIBE_AVX2_FILTER)
    if (use_avx2_filter) {
      FilterAvx2(rows, rows_in_reach, lanes, rows_are_a);
      return;
    }
#endif
    Filter(rows, rows_in_reach, lanes, rows_are_a);
  }

  // A range of spheres in float (centres in a's frame) and its first position in the ordered
  // arrays; readable for kFloatPadding entries past its end.
  struct Side {
    const float *x, *y, *z, *radius;
    std::int32_t first, count;
  };

  // A sphere in float: centre in a's frame and radius, each rounded to nearest.
  struct FloatSphere {
    float x, y, z, radius;
  };
  static FloatSphere RoundedSphere(const Vector3& center, double radius) {
    return {static_cast<float>(center.x()), static_cast<float>(center.y()),
            static_cast<float>(center.z()), static_cast<float>(radius)};
  }

  // The rows the filter passes against `around` (the same test as one pair's), bit i for row
  // i; at most 64 rows (the shorter side of at most kAllPairs pairs).
  std::uint64_t RowsInReach(const Side& rows, const FloatSphere& around) const {
    std::uint64_t in_reach = 0;
#if defined(__SSE2__)
    const __m128 cx = _mm_set1_ps(around.x), cy = _mm_set1_ps(around.y), cz = _mm_set1_ps(around.z),
                 reach_all = _mm_set1_ps(float_reach_), radius = _mm_set1_ps(around.radius),
                 zero = _mm_setzero_ps();
    for (std::int32_t i = 0; i < rows.count; i += 4) {
      const __m128 dx = _mm_sub_ps(_mm_loadu_ps(rows.x + i), cx);
      const __m128 dy = _mm_sub_ps(_mm_loadu_ps(rows.y + i), cy);
      const __m128 dz = _mm_sub_ps(_mm_loadu_ps(rows.z + i), cz);
      const __m128 squared =
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
      const __m128 reach = _mm_add_ps(_mm_add_ps(reach_all, _mm_loadu_ps(rows.radius + i)), radius);
      const __m128 pass =
          _mm_and_ps(_mm_cmpgt_ps(reach, zero), _mm_cmplt_ps(squared, _mm_mul_ps(reach, reach)));
      in_reach |= std::uint64_t{static_cast<unsigned>(_mm_movemask_ps(pass))} << i;
    }
#else
    for (std::int32_t i = 0; i < rows.count; ++i) {
      const float dx = rows.x[i] - around.x, dy = rows.y[i] - around.y, dz = rows.z[i] - around.z;
      const float reach = (float_reach_ + rows.radius[i]) + around.radius;
      if (reach > 0.0f && dx * dx + dy * dy + dz * dz < reach * reach) {
        in_reach |= std::uint64_t{1} << i;
      }
    }
#endif
    return rows.count == 64 ? in_reach : in_reach & ((std::uint64_t{1} << rows.count) - 1);
  }

  // The pair of row i and lane j passed the filter.
  void PassPair(const Side& rows, std::int32_t i, const Side& lanes, std::int32_t j,
                bool rows_are_a) {
    if (rows_are_a) {
      ComparePair(rows.first + i, lanes.first + j);
    } else {
      ComparePair(lanes.first + j, rows.first + i);
    }
  }

  // Each row sphere in rows_in_reach (bit i for row i) against the lane spheres, four lanes at
  // a time; rows_are_a tells which side is a's.
  void Filter(const Side& rows, std::uint64_t rows_in_reach, const Side& lanes, bool rows_are_a) {
    const std::int32_t nl = lanes.count;
    for (std::uint64_t in_reach = rows_in_reach; in_reach != 0; in_reach &= in_reach - 1) {
      const auto i = static_cast<std::int32_t>(__builtin_ctzll(in_reach));
      const float reach_i = float_reach_ + rows.radius[i];
      const auto pass_pair = [&](std::int32_t j) { PassPair(rows, i, lanes, j, rows_are_a); };
#if defined(__SSE2__)
      const __m128 x = _mm_set1_ps(rows.x[i]), y = _mm_set1_ps(rows.y[i]),
                   z = _mm_set1_ps(rows.z[i]);
      const __m128 reach_row = _mm_set1_ps(reach_i), zero = _mm_setzero_ps();
      for (std::int32_t j = 0; j < nl; j += 4) {
        const __m128 dx = _mm_sub_ps(x, _mm_loadu_ps(lanes.x + j));
        const __m128 dy = _mm_sub_ps(y, _mm_loadu_ps(lanes.y + j));
        const __m128 dz = _mm_sub_ps(z, _mm_loadu_ps(lanes.z + j));
        const __m128 squared =
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        const __m128 reach = _mm_add_ps(reach_row, _mm_loadu_ps(lanes.radius + j));
        const __m128 pass =
            _mm_and_ps(_mm_cmpgt_ps(reach, zero), _mm_cmplt_ps(squared, _mm_mul_ps(reach, reach)));
        auto mask = static_cast<unsigned>(_mm_movemask_ps(pass));
        if (nl - j < 4) mask &= (1u << (nl - j)) - 1u;
        while (mask != 0) {
          const int k = __builtin_ctz(mask);
          mask &= mask - 1;
          pass_pair(j + k);
        }
      }
#else
      for (std::int32_t j = 0; j < nl; ++j) {
        const float dx = rows.x[i] - lanes.x[j], dy = rows.y[i] - lanes.y[j],
                    dz = rows.z[i] - lanes.z[j];
        const float squared = dx * dx + dy * dy + dz * dz;
        const float reach = reach_i + lanes.radius[j];
        if (reach > 0.0f && squared < reach * reach) pass_pair(j);
      }
#endif
    }
  }

#if defined(INSCRIBE_AVX2_FILTER)
  // Filter with eight lanes at a time.
  __attribute__((target("avx2"))) void FilterAvx2(const Side& rows, std::uint64_t rows_in_reach,
                                                  const Side& lanes, bool rows_are_a) {
    const std::int32_t nl = lanes.count;
    for (std::uint64_t in_reach = rows_in_reach; in_reach != 0; in_reach &= in_reach - 1) {
      const auto i = static_cast<std::int32_t>(__builtin_ctzll(in_reach));
      const __m256 x = _mm256_set1_ps(rows.x[i]), y = _mm256_set1_ps(rows.y[i]),
                   z = _mm256_set1_ps(rows.z[i]);
      const __m256 reach_row = _mm256_set1_ps(float_reach_ + rows.radius[i]);
      const __m256 zero = _mm256_setzero_ps();
      for (std::int32_t j = 0; j < nl; j += 8) {
        const __m256 dx = _mm256_sub_ps(x, _mm256_loadu_ps(lanes.x + j));
        const __m256 dy = _mm256_sub_ps(y, _mm256_loadu_ps(lanes.y + j));
        const __m256 dz = _mm256_sub_ps(z, _mm256_loadu_ps(lanes.z + j));
        const __m256 squared = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
        const __m256 reach = _mm256_add_ps(reach_row, _mm256_loadu_ps(lanes.radius + j));
        const __m256 pass =
            _mm256_and_ps(_mm256_cmp_ps(reach, zero, _CMP_GT_OQ),
                          _mm256_cmp_ps(squared, _mm256_mul_ps(reach, reach), _CMP_LT_OQ));
        auto mask = static_cast<unsigned>(_mm256_movemask_ps(pass));
        if (nl - j < 8) mask &= (1u << (nl - j)) - 1u;
        while (mask != 0) {
          const int k = __builtin_ctz(mask);
          mask &= mask - 1;
          PassPair(rows, i, lanes, j + k, rows_are_a);
        }
      }
    }
  }
#endif

  const SphereHierarchy& a_;
  const SphereHierarchy& b_;
  const RelativeFrame& rel_;
  const DistanceRequest& request_;
  const bool yes_no_;  // a closer_than query: stop at the first pair below it
  double best_ = std::numeric_limits<double>::infinity();
  double threshold_;  // pairs bounded at or above this are pruned
  std::int32_t best_a_ = -1, best_b_ = -1;
  const double scale_;  // M
  const float margin_;
  float float_reach_ = 0.0f;  // the sphere-pair filter's clamped threshold + margin
  Scratch& s_;
};

}  // namespace

bool FloatFilteredSearch(const SphereHierarchy& a, const SphereHierarchy& b,
                         const RelativeFrame& relative, const DistanceRequest& request,
                         DistanceResult* out) {
  // M bounds a's magnitudes, and b's moved ones through the rotation's rows as computed (with a
  // relative slack for the double rounding of the move).
  const Eigen::Matrix3d& r = relative.rotation;
  double row_norm = 0.0;
  for (int k = 0; k < 3; ++k) row_norm = std::max(row_norm, r.row(k).norm());
  const double moved =
      (row_norm * b.max_center_norm() + relative.translation.cwiseAbs().maxCoeff()) * (1.0 + 1e-9);
  const double bound = std::max({a.max_abs_coordinate(), a.max_radius(), moved, b.max_radius()});
  // The rotation's departure from orthonormality: |R x| <= sqrt(1 + e) |x| <= (1 + e) |x|, e
  // the largest absolute row sum of R^T R - I.
  double departure = 0.0;
  for (int i = 0; i < 3; ++i) {
    double row_sum = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double gram = r(0, i) * r(0, j) + r(1, i) * r(1, j) + r(2, i) * r(2, j);
      row_sum += std::abs(gram - (i == j ? 1.0 : 0.0));
    }
    if (!(row_sum <= departure)) departure = row_sum;  // a NaN is kept, and refused below
  }
  if (!std::isfinite(bound) || !(bound > 0.0) || !std::isfinite(departure) || departure > 1e-3) {
    return false;
  }
  const int exponent = std::ilogb(bound) + 1;  // M = 2^exponent > bound
  if (exponent < kFloatMinExponent || exponent > kFloatMaxExponent) return false;
  const double scale = std::ldexp(1.0, exponent);
  const double margin = std::ldexp(1.0, exponent + kFloatMarginExponent) + 4.0 * departure * scale;
  thread_local Scratch scratch;
  FloatSearch(a, b, relative, request, scale, margin, scratch).Run(out);
  return true;
}

}  // namespace inscribe::internal
