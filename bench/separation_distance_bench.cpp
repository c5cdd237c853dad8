// Cost of one separation-distance query (inscribe/separation_distance.h) on real sphere sets:
// the RSS hierarchy, the sphere hierarchy and the brute force over all sphere pairs, on the same
// poses, so that the hierarchy's gain is a ratio from one run. bench/paper_table2 compares the
// same queries with FCL's exact mesh distance; this program isolates the query for profiling
// (perf record ./separation_distance_bench --benchmark_filter=rss).
//
//   ./separation_distance_bench [--benchmark_* flags]     (INSCRIBE_DATA_DIR: the demo meshes)
//
// Input, per model (eight, knot1): the mesh scaled to a largest bounding-box side of 10, S_D
// from GenerateWithSphereBudget (at most 1000 spheres, boundary voxels split in 8), grown by
// DilateSpheres (growth 0.5), and 512 random 'near' pose pairs as in Table II (both copies
// rotated, centre distance 0.4-0.9 bounding-box diagonals). Fixed seed. Times are wall clock per
// query, cycling through the poses; counters give the mean volume and sphere-pair tests.
//
// Before timing, every pose's answer from both hierarchies is checked against the brute force
// to 1e-9: a fast wrong answer is worthless, so a disagreement exits with status 1.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/rigid_pose.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/sphere_dilation.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe {
namespace {

constexpr std::uint64_t kSeed = 0x5eed'd157;
constexpr int kPoses = 512;
const char* const kModels[] = {"eight", "knot1"};

struct PosePair {
  RigidPose a, b;
};

struct Fixture {
  std::vector<Sphere> spheres;
  SphereHierarchy rss, sphere;
  std::vector<PosePair> poses;
};

Eigen::Quaterniond RandomRotation(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
}

[[noreturn]] void Fail(const std::string& what) {
  std::fprintf(stderr, "separation_distance_bench: %s\n", what.c_str());
  std::exit(1);
}

template <typename T>
T Must(absl::StatusOr<T> value, const std::string& what) {
  if (!value.ok()) Fail(what + ": " + value.status().ToString());
  return *std::move(value);
}

Fixture Prepare(const std::string& name) {
  std::string dir = INSCRIBE_SOURCE_DIR "/data";
  if (const char* env = std::getenv("INSCRIBE_DATA_DIR")) dir = env;
  Mesh mesh = Must(ReadMesh(dir + "/" + name + ".off"), name);
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const double scale = 10.0 / box.extent().maxCoeff();
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i) {
    const Vector3 p = mesh.vertices.row(i).transpose();
    mesh.vertices.row(i) = ((p - 0.5 * (box.min + box.max)) * scale).transpose();
  }
  ValidatedMesh prepared = Must(PrepareMesh(std::move(mesh), ValidateOptions{}), name);
  const BoundaryOracle oracle = Must(BoundaryOracle::Build(prepared.mesh), name);
  SphereBudgetOptions budget;
  budget.max_spheres = 1000;
  budget.base.subdivide_boundary = true;
  SphereBudgetResult generated = Must(GenerateWithSphereBudget(oracle, budget), name);
  DilationOptions dilation;
  dilation.growth = 0.5;
  std::vector<Sphere> spheres =
      Must(DilateSpheres(oracle, generated.best.set, dilation), name).set.spheres;
  Fixture f{spheres,
            Must(SphereHierarchy::Build(spheres, HierarchyVolume::kRss), name),
            Must(SphereHierarchy::Build(spheres, HierarchyVolume::kSphere), name),
            {}};

  const double diagonal = ComputeBoundingBox(prepared.mesh.vertices).diagonal();
  std::mt19937_64 rng(kSeed);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> fraction(0.4, 0.9);
  for (int i = 0; i < kPoses; ++i) {
    PosePair p;
    p.a.rotation = RandomRotation(rng);
    p.b.rotation = RandomRotation(rng);
    const Vector3 direction(normal(rng), normal(rng), normal(rng));
    p.b.translation = direction.normalized() * (fraction(rng) * diagonal);
    f.poses.push_back(p);
  }
  for (std::size_t i = 0; i < f.poses.size(); ++i) {
    const PosePair& p = f.poses[i];
    const double brute =
        Must(BruteForceSeparationDistance(f.spheres, p.a, f.spheres, p.b), name).distance;
    for (const SphereHierarchy* h : {&f.rss, &f.sphere}) {
      const double d = Must(SeparationDistance(*h, p.a, *h, p.b), name).distance;
      if (std::abs(d - brute) > 1e-9) {
        Fail(name + " pose " + std::to_string(i) + ": hierarchy " + std::to_string(d) +
             ", brute force " + std::to_string(brute));
      }
    }
  }
  return f;
}

const Fixture& Model(int index) {
  static std::vector<Fixture> fixtures = [] {
    std::vector<Fixture> all;
    for (const char* name : kModels) all.push_back(Prepare(name));
    return all;
  }();
  return fixtures[static_cast<std::size_t>(index)];
}

enum Method { kRssHierarchy, kSphereHierarchy, kBruteForce };

void BM_Query(benchmark::State& state) {
  const Fixture& f = Model(static_cast<int>(state.range(0)));
  const auto method = static_cast<Method>(state.range(1));
  state.SetLabel(std::string(kModels[state.range(0)]) + ", " + std::to_string(f.spheres.size()) +
                 " spheres");
  std::size_t i = 0;
  double volume_tests = 0.0, sphere_tests = 0.0;
  for (auto _ : state) {
    const PosePair& p = f.poses[i];
    absl::StatusOr<DistanceResult> r =
        method == kBruteForce     ? BruteForceSeparationDistance(f.spheres, p.a, f.spheres, p.b)
        : method == kRssHierarchy ? SeparationDistance(f.rss, p.a, f.rss, p.b)
                                  : SeparationDistance(f.sphere, p.a, f.sphere, p.b);
    benchmark::DoNotOptimize(r);
    volume_tests += static_cast<double>(r->volume_tests);
    sphere_tests += static_cast<double>(r->sphere_tests);
    if (++i == f.poses.size()) i = 0;
  }
  state.counters["volume_tests"] =
      benchmark::Counter(volume_tests, benchmark::Counter::kAvgIterations);
  state.counters["sphere_tests"] =
      benchmark::Counter(sphere_tests, benchmark::Counter::kAvgIterations);
}

BENCHMARK(BM_Query)
    ->ArgNames({"model", "method"})
    ->ArgsProduct({{0, 1}, {kRssHierarchy, kSphereHierarchy, kBruteForce}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace inscribe

BENCHMARK_MAIN();
