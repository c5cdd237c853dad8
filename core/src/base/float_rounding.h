// Rounding doubles to floats outward: float bounds (boxes, gaps) that still contain the
// double values they stand for. Private to core.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace inscribe::internal {

// The float next to f toward -infinity / +infinity (f not NaN). Inline bit arithmetic:
// std::nextafter is a library call, and callers round every bound of a box or a search.
inline float NextFloatDown(float f) {
  if (f == 0.0f) return -std::numeric_limits<float>::denorm_min();
  std::uint32_t bits;
  std::memcpy(&bits, &f, sizeof(bits));
  bits = f > 0.0f ? bits - 1 : bits + 1;
  std::memcpy(&f, &bits, sizeof(bits));
  return f;
}
inline float NextFloatUp(float f) { return -NextFloatDown(-f); }

// x rounded to a float toward -infinity / +infinity: float boxes that contain double points.
inline float RoundDown(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) > x ? NextFloatDown(f) : f;
}
inline float RoundUp(double x) {
  const auto f = static_cast<float>(x);
  return static_cast<double>(f) < x ? NextFloatUp(f) : f;
}

// Without branches, for filters that round many bounds per call: a float at most / at least x
// (x not NaN), up to about 2^-21 |x| + 1e-30 further than RoundDown / RoundUp. x is moved by
// more than half a float ulp before the conversion rounds it to nearest, and a finite x
// beyond float's range becomes the largest float rather than an infinity on the wrong side.
inline float LooseRoundDown(double x) {
  const double below = x - (std::abs(x) * 0x1p-22 + 1e-30);
  return std::min(static_cast<float>(below), std::numeric_limits<float>::max());
}
inline float LooseRoundUp(double x) {
  const double above = x + (std::abs(x) * 0x1p-22 + 1e-30);
  return std::max(static_cast<float>(above), -std::numeric_limits<float>::max());
}

}  // namespace inscribe::internal
