#include "support/union_volume_reference.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "base/parallel.h"

namespace inscribe::testing {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A disk in a slice plane: centre (x, y), radius r.
struct Disk {
  double x, y, r;
};

double DiskUnionArea(const std::vector<Disk>& disks) {
  double area = 0.0;
  std::vector<std::pair<double, double>> covered;
  std::vector<std::pair<double, double>> split;
  for (std::size_t i = 0; i < disks.size(); ++i) {
    const Disk& a = disks[i];
    covered.clear();
    bool hidden = false;
    for (std::size_t j = 0; j < disks.size() && !hidden; ++j) {
      if (j == i) continue;
      const Disk& b = disks[j];
      const double dx = b.x - a.x;
      const double dy = b.y - a.y;
      const double d = std::hypot(dx, dy);
      if (d + a.r <= b.r) {
        hidden = !(d == 0 && a.r == b.r && j > i);  // of equal disks the first one counts
        continue;
      }
      if (d >= a.r + b.r || d + b.r <= a.r) continue;
      const double c = (d * d + a.r * a.r - b.r * b.r) / (2 * d * a.r);
      const double half = std::acos(std::clamp(c, -1.0, 1.0));
      const double mid = std::atan2(dy, dx);
      covered.emplace_back(mid - half, mid + half);
    }
    if (hidden) continue;
    split.clear();
    for (auto [lo, hi] : covered) {
      const double shift = 2 * kPi * std::floor(lo / (2 * kPi));
      lo -= shift;
      hi -= shift;
      if (hi > 2 * kPi) {
        split.emplace_back(lo, 2 * kPi);
        split.emplace_back(0.0, hi - 2 * kPi);
      } else {
        split.emplace_back(lo, hi);
      }
    }
    std::sort(split.begin(), split.end());
    // Green: area = 1/2 ∮ x dy - y dx over the uncovered arcs, counter-clockwise.
    const auto arc = [&a](double t0, double t1) {
      return 0.5 * (a.r * a.r * (t1 - t0) + a.r * (a.x * (std::sin(t1) - std::sin(t0)) -
                                                   a.y * (std::cos(t1) - std::cos(t0))));
    };
    double t = 0.0;
    for (const auto& [lo, hi] : split) {
      if (lo > t) area += arc(t, lo);
      t = std::max(t, hi);
    }
    if (t < 2 * kPi) area += arc(t, 2 * kPi);
  }
  return area;
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
void GaussLegendre(int n, std::vector<double>* x, std::vector<double>* w) {
  x->resize(static_cast<std::size_t>(n));
  w->resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
      double p0 = 1.0;
      double p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-16) break;
    }
    (*x)[static_cast<std::size_t>(i)] = z;
    (*w)[static_cast<std::size_t>(i)] = 2 / ((1 - z * z) * dp * dp);
  }
}

}  // namespace

double SliceQuadratureVolume(std::vector<Sphere> balls, int order) {
  Vector3 centroid = Vector3::Zero();
  for (const Sphere& b : balls) centroid += b.center;
  centroid /= static_cast<double>(balls.size());
  for (Sphere& b : balls) b.center -= centroid;

  double zlo = balls[0].center.z() - balls[0].radius;
  double zhi = balls[0].center.z() + balls[0].radius;
  std::vector<double> events;
  for (const Sphere& b : balls) {
    zlo = std::min(zlo, b.center.z() - b.radius);
    zhi = std::max(zhi, b.center.z() + b.radius);
    events.push_back(b.center.z() - b.radius);
    events.push_back(b.center.z() + b.radius);
  }
  const std::size_t n = balls.size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vector3 v = balls[j].center - balls[i].center;
      const double d = v.norm();
      const double ri = balls[i].radius;
      const double rj = balls[j].radius;
      if (d >= ri + rj || d <= std::abs(ri - rj)) continue;
      const double a = (d * d + ri * ri - rj * rj) / (2 * d);
      const double rho = std::sqrt(std::max(0.0, ri * ri - a * a));
      const Vector3 u = v / d;
      const double qz = balls[i].center.z() + a * u.z();
      const double reach = rho * std::sqrt(std::max(0.0, 1 - u.z() * u.z()));
      events.push_back(qz - reach);
      events.push_back(qz + reach);
      for (std::size_t k = j + 1; k < n; ++k) {
        const Vector3 e2 = balls[k].center - balls[i].center;
        const double rk = balls[k].radius;
        Eigen::Matrix3d m;
        m.row(0) = v.transpose();
        m.row(1) = e2.transpose();
        m.row(2) = v.cross(e2).transpose();
        if (m.row(2).norm() < 1e-12 * d * e2.norm()) continue;
        const Vector3 rhs(d * a, (e2.squaredNorm() + ri * ri - rk * rk) / 2, 0.0);
        const Vector3 x = m.partialPivLu().solve(rhs);
        const double h2 = ri * ri - x.squaredNorm();
        if (h2 < 0) continue;
        const double dz = std::sqrt(h2) * m.row(2).normalized()(2);
        events.push_back(balls[i].center.z() + x.z() - dz);
        events.push_back(balls[i].center.z() + x.z() + dz);
      }
    }
  }
  std::sort(events.begin(), events.end());
  std::vector<double> cuts;
  for (double e : events) {
    if (e < zlo || e > zhi) continue;
    if (cuts.empty() || e - cuts.back() > 1e-13 * (zhi - zlo)) cuts.push_back(e);
  }
  cuts.back() = zhi;

  std::vector<double> gx;
  std::vector<double> gw;
  GaussLegendre(order, &gx, &gw);
  std::vector<Disk> disks;
  const auto area_at = [&](double z) {
    disks.clear();
    for (const Sphere& b : balls) {
      const double dz = z - b.center.z();
      const double r2 = b.radius * b.radius - dz * dz;
      if (r2 > 0) disks.push_back({b.center.x(), b.center.y(), std::sqrt(r2)});
    }
    return DiskUnionArea(disks);
  };
  // On [a, b], z = a + (b - a)(1 - cos t) / 2 for t in [0, pi]: nodes cluster at both ends,
  // where the area has (z - e)^(3/2) terms (two slice circles starting to overlap).
  double volume = 0.0;
  const double max_length = (zhi - zlo) / 32;
  for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
    const int pieces = static_cast<int>(std::ceil((cuts[c + 1] - cuts[c]) / max_length));
    for (int p = 0; p < pieces; ++p) {
      const double a = cuts[c] + (cuts[c + 1] - cuts[c]) * p / pieces;
      const double b = cuts[c] + (cuts[c + 1] - cuts[c]) * (p + 1) / pieces;
      for (std::size_t g = 0; g < gx.size(); ++g) {
        const double t = kPi / 2 * (gx[g] + 1);
        const double z = a + (b - a) * (1 - std::cos(t)) / 2;
        volume += gw[g] * kPi / 2 * (b - a) / 2 * std::sin(t) * area_at(z);
      }
    }
  }
  return volume;
}

BallGrid::BallGrid(const std::vector<Sphere>& balls) : balls_(balls) {
  lo_ = hi_ = balls[0].center;
  double rmax = 0.0;
  for (const Sphere& b : balls) {
    lo_ = lo_.cwiseMin(b.center - Vector3::Constant(b.radius));
    hi_ = hi_.cwiseMax(b.center + Vector3::Constant(b.radius));
    rmax = std::max(rmax, b.radius);
  }
  for (int k = 0; k < 3; ++k) {
    dims_[k] = std::clamp(static_cast<int>((hi_[k] - lo_[k]) / rmax), 1, 64);
  }
  cells_.resize(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]));
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Sphere& b = balls[i];
    int from[3];
    int to[3];
    for (int k = 0; k < 3; ++k) {
      from[k] = Cell(b.center[k] - b.radius, k);
      to[k] = Cell(b.center[k] + b.radius, k);
    }
    for (int x = from[0]; x <= to[0]; ++x) {
      for (int y = from[1]; y <= to[1]; ++y) {
        for (int z = from[2]; z <= to[2]; ++z) cells_[Index(x, y, z)].push_back(i);
      }
    }
  }
}

bool BallGrid::Contains(const Vector3& p) const {
  for (std::size_t i : cells_[Index(Cell(p.x(), 0), Cell(p.y(), 1), Cell(p.z(), 2))]) {
    const Sphere& b = balls_[i];
    if ((p - b.center).squaredNorm() <= b.radius * b.radius) return true;
  }
  return false;
}

int BallGrid::Cell(double v, int k) const {
  return std::clamp(static_cast<int>((v - lo_[k]) / (hi_[k] - lo_[k]) * dims_[k]), 0, dims_[k] - 1);
}

std::size_t BallGrid::Index(int x, int y, int z) const {
  return static_cast<std::size_t>((x * dims_[1] + y) * dims_[2] + z);
}

MonteCarloEstimate MonteCarloVolume(const std::vector<Sphere>& balls, std::int64_t samples,
                                    std::uint64_t seed) {
  const BallGrid grid(balls);
  constexpr std::int64_t kBlock = 1 << 16;
  const std::int64_t blocks = (samples + kBlock - 1) / kBlock;
  const Vector3 lo = grid.lo();
  const Vector3 size = grid.hi() - grid.lo();
  const std::int64_t hits = internal::ParallelReduce(
      std::int64_t{0}, blocks, 1, std::int64_t{0},
      [&](std::int64_t first, std::int64_t last, std::int64_t count) {
        for (std::int64_t block = first; block != last; ++block) {
          std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(block));
          const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
          const std::int64_t end = std::min(samples, (block + 1) * kBlock);
          for (std::int64_t s = block * kBlock; s < end; ++s) {
            const double x = uniform();
            const double y = uniform();
            const double z = uniform();
            if (grid.Contains(lo + size.cwiseProduct(Vector3(x, y, z)))) ++count;
          }
        }
        return count;
      },
      [](std::int64_t a, std::int64_t b) { return a + b; });
  const double box = size.prod();
  const double p = static_cast<double>(hits) / static_cast<double>(samples);
  return {box * p, box * std::sqrt(p * (1 - p) / static_cast<double>(samples))};
}

}  // namespace inscribe::testing
