// Exact volume of a union of balls (inscribe::UnionVolume) on random overlapping balls, and its
// parts: the dual complex alone (CGAL regular triangulation + fixed alpha shape) and the
// closed-form inclusion-exclusion sum over a given complex.
//
//   ./union_volume_bench [--benchmark_* flags]
//
// Input for n balls: centres uniform in a cube of side n^(1/3) (one centre per unit volume),
// radii uniform in [0.6, 1.2], fixed seed; the counters give the complex's size (about 2.7
// tetrahedra per ball). Before timing, the 1000-ball volume is checked against a brute-force
// Monte Carlo estimate (2 * 10^5 samples, within 5 standard errors): a fast wrong answer is
// worthless. Times are wall clock per call, in milliseconds.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/balls/union_of_balls.h"
#include "inscribe/geometry/sphere.h"

namespace inscribe {
namespace {

constexpr std::uint64_t kSeed = 0x5eed'ba11;

std::vector<Sphere> OverlappingBalls(int n) {
  std::mt19937_64 rng(kSeed + static_cast<std::uint64_t>(n));
  std::uniform_real_distribution<double> coord(0.0, std::cbrt(static_cast<double>(n)));
  std::uniform_real_distribution<double> radius(0.6, 1.2);
  std::vector<Sphere> balls(static_cast<std::size_t>(n));
  for (Sphere& b : balls) {
    b.center = Vector3(coord(rng), coord(rng), coord(rng));
    b.radius = radius(rng);
  }
  return balls;
}

// Fraction of uniform samples in the balls' bounding box that fall in the union; brute force.
struct Estimate {
  double volume;
  double standard_error;
};

Estimate MonteCarloVolume(const std::vector<Sphere>& balls, int samples) {
  Vector3 lo = balls[0].center;
  Vector3 hi = lo;
  for (const Sphere& b : balls) {
    lo = lo.cwiseMin(b.center - Vector3::Constant(b.radius));
    hi = hi.cwiseMax(b.center + Vector3::Constant(b.radius));
  }
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int hits = 0;
  for (int s = 0; s < samples; ++s) {
    const Vector3 p = lo + (hi - lo).cwiseProduct(Vector3(unit(rng), unit(rng), unit(rng)));
    hits += std::any_of(balls.begin(), balls.end(), [&p](const Sphere& b) {
      return (p - b.center).squaredNorm() <= b.radius * b.radius;
    });
  }
  const double box = (hi - lo).prod();
  const double f = static_cast<double>(hits) / samples;
  return {box * f, box * std::sqrt(f * (1 - f) / samples)};
}

void SetCounters(benchmark::State& state, const DualComplex& c) {
  state.counters["balls"] = static_cast<double>(state.range(0));
  state.counters["edges"] = static_cast<double>(c.edges.size());
  state.counters["triangles"] = static_cast<double>(c.triangles.size());
  state.counters["tetrahedra"] = static_cast<double>(c.tetrahedra.size());
}

void BM_UnionVolume(benchmark::State& state) {
  const std::vector<Sphere> balls = OverlappingBalls(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    absl::StatusOr<double> v = UnionVolume(balls);
    if (!v.ok()) state.SkipWithError(v.status().ToString().c_str());
    benchmark::DoNotOptimize(v);
  }
  SetCounters(state, *ComputeDualComplex(balls));
}

void BM_DualComplex(benchmark::State& state) {
  const std::vector<Sphere> balls = OverlappingBalls(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    absl::StatusOr<DualComplex> c = ComputeDualComplex(balls);
    if (!c.ok()) state.SkipWithError(c.status().ToString().c_str());
    benchmark::DoNotOptimize(c);
  }
  SetCounters(state, *ComputeDualComplex(balls));
}

// The closed-form sum alone, over a complex computed once.
void BM_UnionVolumeGivenComplex(benchmark::State& state) {
  const std::vector<Sphere> balls = OverlappingBalls(static_cast<int>(state.range(0)));
  const DualComplex complex = *ComputeDualComplex(balls);
  for (auto _ : state) {
    absl::StatusOr<double> v = UnionVolume(balls, complex);
    if (!v.ok()) state.SkipWithError(v.status().ToString().c_str());
    benchmark::DoNotOptimize(v);
  }
  SetCounters(state, complex);
}

BENCHMARK(BM_UnionVolume)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DualComplex)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_UnionVolumeGivenComplex)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const std::vector<inscribe::Sphere> balls = inscribe::OverlappingBalls(1000);
  const absl::StatusOr<double> exact = inscribe::UnionVolume(balls);
  if (!exact.ok()) {
    std::fprintf(stderr, "union_volume_bench: %s\n", exact.status().ToString().c_str());
    return 1;
  }
  const inscribe::Estimate mc = inscribe::MonteCarloVolume(balls, 200'000);
  const double deviations = (*exact - mc.volume) / mc.standard_error;
  if (std::abs(deviations) > 5) {
    std::fprintf(stderr,
                 "union_volume_bench: volume %.9g disagrees with Monte Carlo %.9g +- %.3g, not "
                 "timing it\n",
                 *exact, mc.volume, mc.standard_error);
    return 1;
  }
  char check[128];
  std::snprintf(check, sizeof(check), "1000 balls: %.6f, Monte Carlo %.6f +- %.6f (%.2f se)",
                *exact, mc.volume, mc.standard_error, deviations);
  benchmark::AddCustomContext("volume check", check);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
