// Cost of the RSS bounding volume's operations (inscribe/rss.h): RssDistance, the inner loop
// of the sphere-hierarchy distance query, against FCL's RSS distance (PQP's RectDist, what
// FCL's exact mesh distance calls per node pair); RectangleDistance with witness points; and
// FitRss per ball.
//
//   ./rss_bench [--benchmark_* flags]
//
// Input: 4096 pairs per benchmark, each RSS fitted (FitRss) to 40 random balls of radius
// 0.05-0.3 on a gently curved sheet (like a medial sheet) or in a blob, both within about
// [-1, 1]^3, the second placed by a uniformly random rotation and a translation of random
// direction whose length is uniform in the argument's range (in tenths): [0, 2] makes most
// pairs overlap, [2, 6] neighbours, [10, 50] far apart. "point" pairs an RSS with a single
// ball (a point rectangle), as the hierarchy query does at its leaves. Fixed seed. Times are
// wall clock per call, in nanoseconds, cycling through the pairs.
//
// Before timing, every pair's RssDistance is checked against FCL's (which clamps at 0) to
// 1e-9: a fast wrong answer is worthless, so a disagreement exits with status 1.
#include <benchmark/benchmark.h>
#include <fcl/math/bv/RSS.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <vector>

#include "inscribe/distance/rss.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {
namespace {

constexpr std::uint64_t kSeed = 0x5eed'0b55;
constexpr int kPairs = 4096;

Eigen::Matrix3d RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
      .normalized()
      .toRotationMatrix();
}

std::vector<Sphere> RandomBalls(std::mt19937_64& rng, int n, bool sheet) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Matrix3d frame = RandomRotation(rng);
  const double bend = 0.3 * unit(rng);
  std::vector<Sphere> balls(static_cast<std::size_t>(n));
  for (Sphere& b : balls) {
    const double x = 2 * unit(rng) - 1, y = 0.6 * (2 * unit(rng) - 1);
    const double z = sheet ? bend * x * x : 0.5 * (2 * unit(rng) - 1);
    b.center = frame * Vector3(x, y, z);
    b.radius = sheet ? 0.05 + 0.2 * (0.5 + 0.5 * std::sin(2 * x + y)) : 0.05 + 0.25 * unit(rng);
  }
  return balls;
}

Rss FitAll(const std::vector<Sphere>& balls) {
  std::vector<std::int32_t> indices(balls.size());
  std::iota(indices.begin(), indices.end(), 0);
  return FitRss(balls, indices.data(), indices.size());
}

struct PosedPair {
  Rss a, b;
  Eigen::Matrix3d rotation;
  Vector3 translation;
};

// Pairs with translations of length uniform in [lo, hi]; b a single ball when `point`.
std::vector<PosedPair> MakePairs(double lo, double hi, bool point) {
  std::mt19937_64 rng(kSeed + static_cast<std::uint64_t>(lo * 1000 + hi));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<PosedPair> pairs(kPairs);
  for (int i = 0; i < kPairs; ++i) {
    PosedPair& p = pairs[static_cast<std::size_t>(i)];
    p.a = FitAll(RandomBalls(rng, 40, i % 2 == 0));
    p.b = FitAll(RandomBalls(rng, point ? 1 : 40, i % 3 == 0));
    p.rotation = RandomRotation(rng);
    p.translation = RandomRotation(rng).col(0) * (lo + (hi - lo) * unit(rng));
  }
  return pairs;
}

fcl::RSS<double> ToFcl(const Rss& r) {
  fcl::RSS<double> f;
  f.axis = r.axes;
  f.To = r.origin;
  f.l[0] = r.length[0];
  f.l[1] = r.length[1];
  f.r = r.radius;
  return f;
}

const std::vector<PosedPair>& Pairs(int which) {
  static const std::vector<PosedPair> sets[4] = {
      MakePairs(0.0, 2.0, false), MakePairs(2.0, 6.0, false), MakePairs(10.0, 50.0, false),
      MakePairs(0.0, 6.0, true)};
  return sets[which];
}
const char* const kSetNames[4] = {"overlapping", "neighbours", "far", "point"};

void BM_RssDistance(benchmark::State& state) {
  const std::vector<PosedPair>& pairs = Pairs(static_cast<int>(state.range(0)));
  std::size_t i = 0;
  for (auto _ : state) {
    const PosedPair& p = pairs[i];
    benchmark::DoNotOptimize(RssDistance(p.a, p.rotation, p.translation, p.b));
    i = (i + 1) % pairs.size();
  }
  state.SetLabel(kSetNames[state.range(0)]);
}
BENCHMARK(BM_RssDistance)->DenseRange(0, 3);

void BM_FclRssDistance(benchmark::State& state) {
  const std::vector<PosedPair>& pairs = Pairs(static_cast<int>(state.range(0)));
  std::vector<fcl::RSS<double>> a, b;
  for (const PosedPair& p : pairs) {
    a.push_back(ToFcl(p.a));
    b.push_back(ToFcl(p.b));
  }
  std::size_t i = 0;
  for (auto _ : state) {
    const PosedPair& p = pairs[i];
    benchmark::DoNotOptimize(fcl::distance(p.rotation, p.translation, a[i], b[i]));
    i = (i + 1) % pairs.size();
  }
  state.SetLabel(kSetNames[state.range(0)]);
}
BENCHMARK(BM_FclRssDistance)->DenseRange(0, 3);

// In a common frame, with witness points.
void BM_RectangleDistance(benchmark::State& state) {
  std::vector<std::pair<Rss, Rss>> pairs;
  for (PosedPair p : Pairs(static_cast<int>(state.range(0)))) {
    p.b.axes = p.rotation * p.b.axes;
    p.b.origin = p.rotation * p.b.origin + p.translation;
    pairs.emplace_back(p.a, p.b);
  }
  std::size_t i = 0;
  Vector3 pa, pb;
  for (auto _ : state) {
    benchmark::DoNotOptimize(RectangleDistance(pairs[i].first, pairs[i].second, &pa, &pb));
    i = (i + 1) % pairs.size();
  }
  state.SetLabel(kSetNames[state.range(0)]);
}
BENCHMARK(BM_RectangleDistance)->DenseRange(0, 2);

void BM_FitRss(benchmark::State& state) {
  std::mt19937_64 rng(kSeed);
  const std::vector<Sphere> balls = RandomBalls(rng, static_cast<int>(state.range(0)), true);
  std::vector<std::int32_t> indices(balls.size());
  std::iota(indices.begin(), indices.end(), 0);
  for (auto _ : state) {
    benchmark::DoNotOptimize(FitRss(balls, indices.data(), indices.size()));
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_FitRss)->Arg(2)->Arg(16)->Arg(256)->Arg(4096);

// RssDistance against FCL on every benchmark pair; returns the number of disagreements.
int CheckAgainstFcl() {
  int bad = 0;
  for (int set = 0; set < 4; ++set) {
    for (const PosedPair& p : Pairs(set)) {
      const double ours = std::max(0.0, RssDistance(p.a, p.rotation, p.translation, p.b));
      const double fcl = fcl::distance(p.rotation, p.translation, ToFcl(p.a), ToFcl(p.b));
      if (!(std::abs(ours - fcl) <= 1e-9 * (1 + fcl))) {
        if (++bad <= 5)
          std::fprintf(stderr, "%s: inscribe %.17g, FCL %.17g\n", kSetNames[set], ours, fcl);
      }
    }
  }
  return bad;
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const int bad = inscribe::CheckAgainstFcl();
  if (bad > 0) {
    std::fprintf(stderr, "rss_bench: RssDistance disagrees with FCL on %d pairs\n", bad);
    return 1;
  }
  std::fprintf(stderr, "rss_bench: RssDistance agrees with FCL on %d pairs\n",
               4 * inscribe::kPairs);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
