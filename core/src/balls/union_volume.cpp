// The volume of a union of balls by the short inclusion-exclusion over its dual complex
// (union_of_balls.h), every term in closed form (ball_intersection_volumes.h).
#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "balls/ball_intersection_volumes.h"
#include "balls/union_ball_checks.h"
#include "base/parallel.h"
#include "inscribe/balls/union_of_balls.h"

namespace inscribe {
namespace internal {
namespace {

constexpr double kMaxMagnitude = 1e150;

}  // namespace

absl::Status CheckUnionBalls(const std::vector<Sphere>& balls) {
  if (balls.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return absl::InvalidArgumentError(
        absl::StrCat("too many balls: ", balls.size(), " (at most 2^31 - 1)"));
  }
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Sphere& b = balls[i];
    if (absl::Status valid = CheckSphere(b, i); !valid.ok()) return valid;
    // Weights r^2 and squared distances must not overflow.
    if (b.radius > kMaxMagnitude || b.center.cwiseAbs().maxCoeff() > kMaxMagnitude) {
      return absl::InvalidArgumentError(absl::StrCat("ball ", i, ": centre or radius above ",
                                                     kMaxMagnitude, " (squares would overflow)"));
    }
  }
  return absl::OkStatus();
}

}  // namespace internal

namespace {

// Indices per parallel chunk of the sums.
constexpr std::size_t kGrain = 1024;

// Every index in [0, num_balls), each tuple strictly increasing (the formulas need distinct
// balls).
template <std::size_t N>
absl::Status CheckIndices(const std::vector<std::array<std::int32_t, N>>& simplices,
                          std::size_t num_balls, const char* what) {
  for (std::size_t s = 0; s < simplices.size(); ++s) {
    for (std::size_t k = 0; k < N; ++k) {
      const std::int32_t i = simplices[s][k];
      if (i < 0 || static_cast<std::size_t>(i) >= num_balls) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, " ", s, ": ball index ", i, " out of range [0, ", num_balls, ")"));
      }
      if (k > 0 && simplices[s][k - 1] >= i) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, " ", s, ": ball indices not strictly increasing"));
      }
    }
  }
  return absl::OkStatus();
}

// Sum of term(s, simplices[s]) over `simplices` in long double, in list order. The terms are
// evaluated in parallel into their own slots, so the sum's bits do not depend on the thread count.
template <typename Simplex, typename Term>
long double OrderedSum(const std::vector<Simplex>& simplices, const Term& term) {
  std::vector<double> terms(simplices.size());
  internal::ParallelFor(std::size_t{0}, simplices.size(), kGrain,
                        [&](std::size_t s) { terms[s] = term(s, simplices[s]); });
  long double sum = 0;
  for (double t : terms) sum += t;
  return sum;
}

}  // namespace

absl::StatusOr<double> UnionVolume(const std::vector<Sphere>& balls, const DualComplex& complex) {
  if (absl::Status s = internal::CheckUnionBalls(balls); !s.ok()) return s;
  std::vector<std::array<std::int32_t, 1>> vertices(complex.vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v) vertices[v][0] = complex.vertices[v];
  if (absl::Status s = CheckIndices(vertices, balls.size(), "vertex"); !s.ok()) return s;
  if (absl::Status s = CheckIndices(complex.edges, balls.size(), "edge"); !s.ok()) return s;
  if (absl::Status s = CheckIndices(complex.triangles, balls.size(), "triangle"); !s.ok()) {
    return s;
  }
  if (absl::Status s = CheckIndices(complex.tetrahedra, balls.size(), "tetrahedron"); !s.ok()) {
    return s;
  }

  const auto ball = [&balls](std::int32_t i) -> const Sphere& {
    return balls[static_cast<std::size_t>(i)];
  };
  // The tetrahedra on each triangle (0, 1 or 2): a tetrahedron's term leaves out its faces'
  // angle terms, which its triangles weigh by 1 - cofaces / 2 instead, so that a triangle
  // inside the complex (two tetrahedra) needs no angle at all.
  // A face is looked up among the few triangles with the same lowest ball: `first_triangle[b]`
  // is where they start in the (sorted) list.
  std::vector<std::size_t> first_triangle(balls.size() + 1, 0);
  for (const auto& t : complex.triangles) ++first_triangle[static_cast<std::size_t>(t[0]) + 1];
  std::partial_sum(first_triangle.begin(), first_triangle.end(), first_triangle.begin());
  std::vector<std::atomic<std::uint8_t>> cofaces(complex.triangles.size());
  internal::ParallelFor(std::size_t{0}, complex.tetrahedra.size(), kGrain, [&](std::size_t s) {
    const std::array<std::int32_t, 4>& t = complex.tetrahedra[s];
    for (std::size_t skip = 0; skip < 4; ++skip) {
      std::array<std::int32_t, 3> face;
      for (std::size_t k = 0, j = 0; k < 4; ++k) {
        if (k != skip) face[j++] = t[k];
      }
      const std::size_t lowest = static_cast<std::size_t>(face[0]);
      const auto end =
          complex.triangles.begin() + static_cast<std::ptrdiff_t>(first_triangle[lowest + 1]);
      const auto it = std::lower_bound(
          complex.triangles.begin() + static_cast<std::ptrdiff_t>(first_triangle[lowest]), end,
          face);
      if (it != end && *it == face) {
        cofaces[static_cast<std::size_t>(it - complex.triangles.begin())].fetch_add(
            1, std::memory_order_relaxed);
      }
    }
  });
  // One long double accumulator per dimension, formed in list order; the alternating sum of
  // the four totals is formed once at the end.
  long double sum[4] = {0, 0, 0, 0};
  for (std::int32_t i : complex.vertices) sum[0] += internal::BallVolume(ball(i));
  sum[1] = OrderedSum(complex.edges, [&](std::size_t, const std::array<std::int32_t, 2>& e) {
    return internal::TwoBallIntersectionVolume(ball(e[0]), ball(e[1]));
  });
  sum[2] = OrderedSum(complex.triangles, [&](std::size_t s, const std::array<std::int32_t, 3>& t) {
    const double angle_weight = 1.0 - 0.5 * cofaces[s].load(std::memory_order_relaxed);
    return internal::ThreeBallIntersectionVolume(ball(t[0]), ball(t[1]), ball(t[2]), angle_weight);
  });
  sum[3] = OrderedSum(complex.tetrahedra, [&](std::size_t, const std::array<std::int32_t, 4>& t) {
    return internal::FourBallVolumeWithoutFaceAngles(ball(t[0]), ball(t[1]), ball(t[2]),
                                                     ball(t[3]));
  });
  return static_cast<double>(sum[0] - sum[1] + sum[2] - sum[3]);
}

absl::StatusOr<double> UnionVolume(const std::vector<Sphere>& balls) {
  absl::StatusOr<DualComplex> complex = ComputeDualComplex(balls);
  if (!complex.ok()) return complex.status();
  return UnionVolume(balls, *complex);
}

}  // namespace inscribe
