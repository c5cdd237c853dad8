#include "scene/scene_sweep.h"

#include <algorithm>
#include <cmath>

#include "distance/sphere_pair_search.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(INSCRIBE_AVX2_FILTER)
#include <immintrin.h>
#endif

namespace inscribe::internal {
namespace {

// The sphere test's margin is 2^kSweepMarginExponent M (64 u M), for M within
// [2^kSweepMinExponent, 2^kSweepMaxExponent].
constexpr int kSweepMarginExponent = 6 - 24;
constexpr int kSweepMinExponent = -40, kSweepMaxExponent = 60;

std::size_t ScanRow(const SweepView& view, std::size_t k, std::uint32_t* out) {
  const int s = view.axis, u = (s + 1) % 3, v = (s + 2) % 3;
  std::size_t kept = 0;
#if defined(__SSE2__)
  const __m128 ks_high = _mm_set1_ps(view.high[s][k]), ks_low = _mm_set1_ps(view.low[s][k]);
  const __m128 ku_high = _mm_set1_ps(view.high[u][k]), ku_low = _mm_set1_ps(view.low[u][k]);
  const __m128 kv_high = _mm_set1_ps(view.high[v][k]), kv_low = _mm_set1_ps(view.low[v][k]);
  const __m128 kx = _mm_set1_ps(view.center[0][k]), ky = _mm_set1_ps(view.center[1][k]),
               kz = _mm_set1_ps(view.center[2][k]), k_rho = _mm_set1_ps(view.rho[k]);
  const __m128 zero = _mm_setzero_ps();
  for (std::size_t m = k + 1;; m += 4) {
    const __m128 started = _mm_cmplt_ps(_mm_loadu_ps(view.low[s] + m), ks_high);
    __m128 keep = _mm_and_ps(started, _mm_cmplt_ps(ks_low, _mm_loadu_ps(view.high[s] + m)));
    keep = _mm_and_ps(keep, _mm_cmplt_ps(_mm_loadu_ps(view.low[u] + m), ku_high));
    keep = _mm_and_ps(keep, _mm_cmplt_ps(ku_low, _mm_loadu_ps(view.high[u] + m)));
    keep = _mm_and_ps(keep, _mm_cmplt_ps(_mm_loadu_ps(view.low[v] + m), kv_high));
    keep = _mm_and_ps(keep, _mm_cmplt_ps(kv_low, _mm_loadu_ps(view.high[v] + m)));
    const __m128 dx = _mm_sub_ps(_mm_loadu_ps(view.center[0] + m), kx);
    const __m128 dy = _mm_sub_ps(_mm_loadu_ps(view.center[1] + m), ky);
    const __m128 dz = _mm_sub_ps(_mm_loadu_ps(view.center[2] + m), kz);
    const __m128 squared =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 reach = _mm_add_ps(_mm_loadu_ps(view.rho + m), k_rho);
    keep = _mm_and_ps(keep, _mm_and_ps(_mm_cmpgt_ps(reach, zero),
                                       _mm_cmplt_ps(squared, _mm_mul_ps(reach, reach))));
    for (int bits = _mm_movemask_ps(keep); bits != 0; bits &= bits - 1) {
      out[kept++] = static_cast<std::uint32_t>(
          m + static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(bits))));
    }
    if (_mm_movemask_ps(started) != 0xf) break;
  }
#else
  for (std::size_t m = k + 1; view.low[s][m] < view.high[s][k]; ++m) {
    const float dx = view.center[0][m] - view.center[0][k];
    const float dy = view.center[1][m] - view.center[1][k];
    const float dz = view.center[2][m] - view.center[2][k];
    const float reach = view.rho[m] + view.rho[k];
    out[kept] = static_cast<std::uint32_t>(m);
    kept += static_cast<std::size_t>(
        (view.low[s][k] < view.high[s][m]) & (view.low[u][m] < view.high[u][k]) &
        (view.low[u][k] < view.high[u][m]) & (view.low[v][m] < view.high[v][k]) &
        (view.low[v][k] < view.high[v][m]) & (reach > 0.0f) &
        (dx * dx + dy * dy + dz * dz < reach * reach));
  }
#endif
  return kept;
}

#if defined(INSCRIBE_AVX2_FILTER)
// ScanRow eight boxes at a time: the same float operations per lane.
__attribute__((target("avx2"))) std::size_t ScanRowAvx2(const SweepView& view, std::size_t k,
                                                        std::uint32_t* out) {
  const int s = view.axis, u = (s + 1) % 3, v = (s + 2) % 3;
  std::size_t kept = 0;
  const __m256 ks_high = _mm256_set1_ps(view.high[s][k]), ks_low = _mm256_set1_ps(view.low[s][k]);
  const __m256 ku_high = _mm256_set1_ps(view.high[u][k]), ku_low = _mm256_set1_ps(view.low[u][k]);
  const __m256 kv_high = _mm256_set1_ps(view.high[v][k]), kv_low = _mm256_set1_ps(view.low[v][k]);
  const __m256 kx = _mm256_set1_ps(view.center[0][k]), ky = _mm256_set1_ps(view.center[1][k]),
               kz = _mm256_set1_ps(view.center[2][k]), k_rho = _mm256_set1_ps(view.rho[k]);
  const __m256 zero = _mm256_setzero_ps();
  for (std::size_t m = k + 1;; m += 8) {
    const __m256 started = _mm256_cmp_ps(_mm256_loadu_ps(view.low[s] + m), ks_high, _CMP_LT_OQ);
    __m256 keep = _mm256_and_ps(
        started, _mm256_cmp_ps(ks_low, _mm256_loadu_ps(view.high[s] + m), _CMP_LT_OQ));
    keep =
        _mm256_and_ps(keep, _mm256_cmp_ps(_mm256_loadu_ps(view.low[u] + m), ku_high, _CMP_LT_OQ));
    keep =
        _mm256_and_ps(keep, _mm256_cmp_ps(ku_low, _mm256_loadu_ps(view.high[u] + m), _CMP_LT_OQ));
    keep =
        _mm256_and_ps(keep, _mm256_cmp_ps(_mm256_loadu_ps(view.low[v] + m), kv_high, _CMP_LT_OQ));
    keep =
        _mm256_and_ps(keep, _mm256_cmp_ps(kv_low, _mm256_loadu_ps(view.high[v] + m), _CMP_LT_OQ));
    const __m256 dx = _mm256_sub_ps(_mm256_loadu_ps(view.center[0] + m), kx);
    const __m256 dy = _mm256_sub_ps(_mm256_loadu_ps(view.center[1] + m), ky);
    const __m256 dz = _mm256_sub_ps(_mm256_loadu_ps(view.center[2] + m), kz);
    const __m256 squared = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const __m256 reach = _mm256_add_ps(_mm256_loadu_ps(view.rho + m), k_rho);
    keep = _mm256_and_ps(
        keep, _mm256_and_ps(_mm256_cmp_ps(reach, zero, _CMP_GT_OQ),
                            _mm256_cmp_ps(squared, _mm256_mul_ps(reach, reach), _CMP_LT_OQ)));
    for (int bits = _mm256_movemask_ps(keep); bits != 0; bits &= bits - 1) {
      out[kept++] = static_cast<std::uint32_t>(
          m + static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(bits))));
    }
    if (_mm256_movemask_ps(started) != 0xff) break;
  }
  return kept;
}
#endif

}  // namespace

double SweepHalfMargin(double largest_coordinate, double largest_radius, double reach) {
  const double bound = std::max(largest_coordinate, 2.0 * largest_radius + std::abs(reach));
  if (!(bound > 0.0) || !std::isfinite(bound)) return -1.0;
  const int exponent = std::ilogb(bound) + 1;  // M = 2^exponent > bound
  if (exponent < kSweepMinExponent || exponent > kSweepMaxExponent) return -1.0;
  return std::ldexp(1.0, exponent + kSweepMarginExponent - 1);
}

std::size_t ScanSweepRow(const SweepView& view, std::size_t k, std::uint32_t* out) {
#if defined(INSCRIBE_AVX2_FILTER)
  if (use_avx2_filter) return ScanRowAvx2(view, k, out);
#endif
  return ScanRow(view, k, out);
}

bool OrientedBoxesApart(const Vector3& center_a, const Eigen::Matrix3d& axes_a,
                        const Vector3& half_a, const Vector3& center_b,
                        const Eigen::Matrix3d& axes_b, const Vector3& half_b, double reach) {
  // b's axes and centre in a's frame, a row (one of a's axes) at a time: most separated
  // pairs stop at a's first face axes.
  const Vector3 d = center_b - center_a;
  double r[3][3], abs_r[3][3], t[3];
  for (int i = 0; i < 3; ++i) {
    const auto axis = axes_a.col(i);
    t[i] = axis.dot(d);
    for (int j = 0; j < 3; ++j) {
      r[i][j] = axis.dot(axes_b.col(j));
      abs_r[i][j] = std::abs(r[i][j]);
    }
    const double extent_b =
        abs_r[i][0] * half_b[0] + abs_r[i][1] * half_b[1] + abs_r[i][2] * half_b[2];
    if (std::abs(t[i]) - half_a[i] - extent_b >= reach) return true;
  }
  for (int j = 0; j < 3; ++j) {
    const double t_b = r[0][j] * t[0] + r[1][j] * t[1] + r[2][j] * t[2];
    const double extent_a =
        abs_r[0][j] * half_a[0] + abs_r[1][j] * half_a[1] + abs_r[2][j] * half_a[2];
    if (std::abs(t_b) - half_b[j] - extent_a >= reach) return true;
  }
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // The axis a_i x b_j in a's frame has length sqrt(1 - r_ij^2); the gap along it is
      // (distance - radii) / length, compared here as distance - radii >= reach * length.
      const double length_squared = 1.0 - r[i][j] * r[i][j];
      if (!(length_squared >= 1e-6)) continue;
      const double apart = std::abs(t[i2] * r[i1][j] - t[i1] * r[i2][j]) -
                           (half_a[i1] * abs_r[i2][j] + half_a[i2] * abs_r[i1][j] +
                            half_b[j1] * abs_r[i][j2] + half_b[j2] * abs_r[i][j1]);
      if (reach > 0.0 ? apart > 0.0 && apart >= reach * std::sqrt(length_squared)
                      : apart >= 0.0 || apart >= reach * std::sqrt(length_squared)) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace inscribe::internal
