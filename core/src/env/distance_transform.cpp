#include "env/distance_transform.h"

#include <algorithm>
#include <cassert>

namespace inscribe::internal {
namespace {

// One line: d[q] = min over p of (q - p)^2 + f[p] (f[p] == kNoSite: no parabola), arg[q] the
// minimising p. v, zn, zd: scratch of n and n + 1 entries. Breakpoints are fractions zn / zd
// (zd > 0); zd == 0 stands for -infinity (zn < 0) or +infinity (zn > 0).
void Envelope(const std::int64_t* f, int n, std::int64_t* d, std::int64_t* arg, int* v,
              std::int64_t* zn, std::int64_t* zd) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kNoSite) continue;
    const std::int64_t fq = f[q] + static_cast<std::int64_t>(q) * q;
    std::int64_t sn = 0, sd = 0;
    while (k >= 0) {
      const int p = v[k];
      sn = fq - (f[p] + static_cast<std::int64_t>(p) * p);  // s = sn / sd
      sd = 2 * static_cast<std::int64_t>(q - p);
      // s <= z[k]?  z[k] == -infinity never is.
      const bool below = zd[k] != 0 && sn * zd[k] <= zn[k] * sd;
      if (!below) break;
      --k;
    }
    ++k;
    v[k] = q;
    if (k == 0) {
      zn[0] = -1;
      zd[0] = 0;
    } else {
      zn[k] = sn;
      zd[k] = sd;
    }
    zn[k + 1] = 1;
    zd[k + 1] = 0;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) {
      d[q] = kNoSite;
      arg[q] = -1;
    }
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    // Advance while z[j + 1] < q.
    while (zd[j + 1] != 0 && zn[j + 1] < static_cast<std::int64_t>(q) * zd[j + 1]) ++j;
    const std::int64_t dq = q - v[j];
    d[q] = dq * dq + f[v[j]];
    arg[q] = v[j];
  }
}

}  // namespace

CellDistanceTransform ComputeCellDistanceTransform(const std::vector<std::uint8_t>& occupied,
                                                   const int n[3]) {
  const std::int64_t cells = static_cast<std::int64_t>(n[0]) * n[1] * n[2];
  assert(static_cast<std::int64_t>(occupied.size()) == cells);
  CellDistanceTransform out;
  out.d2.assign(cells, kNoSite);
  out.site.assign(cells, 0);
  for (std::int64_t k = 0; k < cells; ++k) {
    if (occupied[k]) {
      out.d2[k] = 0;
      out.site[k] = k;
    }
  }
  const int longest = std::max(n[0], std::max(n[1], n[2]));
  std::vector<std::int64_t> f(longest), d(longest), arg(longest), zn(longest + 1), zd(longest + 1),
      sites(longest);
  std::vector<int> v(longest);
  const std::int64_t stride[3] = {static_cast<std::int64_t>(n[1]) * n[2], n[2], 1};
  for (int axis = 2; axis >= 0; --axis) {
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int i1 = 0; i1 < n[a1]; ++i1) {
      for (int i2 = 0; i2 < n[a2]; ++i2) {
        const std::int64_t base = i1 * stride[a1] + i2 * stride[a2];
        const int len = n[axis];
        for (int q = 0; q < len; ++q) {
          f[q] = out.d2[base + q * stride[axis]];
          sites[q] = out.site[base + q * stride[axis]];
        }
        Envelope(f.data(), len, d.data(), arg.data(), v.data(), zn.data(), zd.data());
        for (int q = 0; q < len; ++q) {
          out.d2[base + q * stride[axis]] = d[q];
          out.site[base + q * stride[axis]] = arg[q] < 0 ? 0 : sites[arg[q]];
        }
      }
    }
  }
  return out;
}

}  // namespace inscribe::internal
