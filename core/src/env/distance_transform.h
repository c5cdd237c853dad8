// Private: the exact Euclidean distance transform of a 3D grid of cells, in integer cell
// units (Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled Functions", 2012: the
// lower envelope of parabolas, one pass per axis). The envelope's breakpoints are compared as
// exact fractions of 64-bit integers, so the result is exact for up to 2^16 cells per axis.
#pragma once

#include <cstdint>
#include <vector>

namespace inscribe::internal {

struct CellDistanceTransform {
  // Per cell: the squared distance, in cells, to the nearest occupied cell (both at their
  // centres), and that cell's index; when no cell is occupied d2 is kNoSite and site 0.
  std::vector<std::int64_t> d2;
  std::vector<std::int64_t> site;
};

inline constexpr std::int64_t kNoSite = INT64_MAX / 4;

// `occupied` per cell, numbered (ix * n[1] + iy) * n[2] + iz; each n[axis] in 1..2^16.
// O(cells) time and memory.
CellDistanceTransform ComputeCellDistanceTransform(const std::vector<std::uint8_t>& occupied,
                                                   const int n[3]);

}  // namespace inscribe::internal
