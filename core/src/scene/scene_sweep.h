// The scene's sweep (Scene::PrepareSweep, Scene::SweepPairs): the float filters over the
// objects' boxes and bounding spheres in sweep order, and the exact oriented-box test of the
// pairs they keep. Private to core.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "inscribe/geometry/sphere.h"

namespace inscribe::internal {

// Boxes the sweep compares at a time: four with SSE, eight with AVX2; the arrays are padded
// for the wider.
constexpr std::size_t kSweepLanes = 8;

// Half the margin of the sweep's float sphere test, or -1 when the test cannot run (every
// centre is then 0 and every rho the largest float: it keeps every pair).
//
// The test. Let M be a power of two at least every |coordinate| of the
// objects' world centres and r_a + r_b + |reach| for every pair (reach: the threshold plus the
// largest slack, as the boxes' grown ends), u = 2^-24. The centres are rounded to nearest and
// each object's sphere reach rho = r + reach / 2 + margin / 2 rounded up, margin = 64 u M.
// A pair passes when rho_a + rho_b > 0 and its float squared centre distance is below the
// square of that sum. Rounding: each float coordinate difference is within 4 u M of the
// double one, so the float distance (before its own rounding) within 7 u M; the float sum
// rho_a + rho_b is at least R + 62.9 u M for R = r_a + r_b + reach in (0, M]; the squares and
// their sum add relative errors of at most 4.02 u. Every pair whose double centre distance is
// below R (bounding spheres closer than the threshold plus the slack) is thus kept with 55 u M
// to spare; for R <= 0 there is none (a centre distance is at least 0). The test is used when 2^-40
// <= M <= 2^60 (no overflow, denormal errors far below the margin) and the reach is finite.
double SweepHalfMargin(double largest_coordinate, double largest_radius, double reach);

// The sweep's arrays in sweep order, padded by kSweepLanes empty boxes (Scene::PrepareSweep).
struct SweepView {
  const float* low[3];     // box low ends, rounded down
  const float* high[3];    // box high ends grown by the reach, rounded up
  const float* center[3];  // sphere centres, rounded to nearest
  const float* rho;        // sphere reaches, rounded up
  int axis;                // the sweep axis: lows sorted along it
};

// Appends to `out` the positions after k whose grown boxes overlap k's on every axis and whose
// float sphere test passes (SweepHalfMargin); returns how many. Sorted by low end
// (rounding down keeps the order: it is monotone), once a later box starts past k's grown high
// end, all later ones do. The other side of the sweep axis is tested too: it matters for a
// negative threshold. Eight lanes at a time with AVX2 (use_avx2_filter), else four with SSE2 or
// one.
std::size_t ScanSweepRow(const SweepView& view, std::size_t k, std::uint32_t* out);

// True when two oriented boxes (centres c, axes the columns of unit rotations R, half sides h)
// are at least `reach` apart along one of their separating axes: the boxes' 6 face normals and
// the 9 cross products of their edges, each gap a lower bound on the boxes' distance. The
// face axes are tried first and the test stops at the first axis that separates. An edge
// pair's axis is used only when far from degenerate (|n| >= 1e-3; near-parallel edges are
// covered by the face axes): the gaps then err by a few ulps of the coordinates over |n|, far
// below the broad phase's slack.
bool OrientedBoxesApart(const Vector3& center_a, const Eigen::Matrix3d& axes_a,
                        const Vector3& half_a, const Vector3& center_b,
                        const Eigen::Matrix3d& axes_b, const Vector3& half_b, double reach);

}  // namespace inscribe::internal
