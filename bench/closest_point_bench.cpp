// Closest-point queries on data/bunny00.off: inscribe's BoundaryOracle (Embree BVH for culling,
// double-precision triangle tests) against CGAL 5.5's AABB_tree (Simple_cartesian<double>, the
// fastest CGAL kernel for this, with its KD-tree start hint). Both answer the same queries, and
// setup checks that they agree before anything is timed: a benchmark of wrong answers is
// worthless.
//
//   INSCRIBE_DATA_DIR=/path/to/meshes ./closest_point_bench [--benchmark_* flags]
//
// Query benchmarks time one pass over all kNumQueries points per iteration and report
// items_per_second = queries per second (wall clock). Build benchmarks report ms per build.
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "inscribe/boundary_oracle.h"
#include "inscribe/mesh.h"
#include "inscribe/mesh_io.h"
#include "inscribe/mesh_validation.h"

namespace inscribe {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using CgalTriangles = std::vector<Kernel::Triangle_3>;
using CgalPrimitive = CGAL::AABB_triangle_primitive<Kernel, CgalTriangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CgalPrimitive>>;

constexpr char kMeshName[] = "bunny00.off";
constexpr Eigen::Index kNumQueries = 100000;
// Points compared between the two structures before timing, and the largest relative
// difference in distance accepted. Both compute in double precision with different formulas;
// cancellation makes the difference grow like 1e-16 * |coordinates| / distance, so queries near
// the surface differ most (7e-12 at worst over all 100k queries on bunny00), still far below.
constexpr Eigen::Index kNumChecked = 1000;
constexpr double kMaxRelativeDifference = 1e-9;
constexpr std::uint64_t kSeed = 0x5eed'b077;

// CGAL's primitives hold iterators into `triangles`: build in place, never copy or move.
struct CgalIndex {
  CgalTriangles triangles;
  CgalTree tree;
};

// Everything a build costs before the first query: converting the mesh to CGAL triangles (the
// oracle copies the mesh too), the AABB hierarchy and the KD-tree of the distance-query hint.
// CGAL builds lazily on the first query otherwise, so both are forced here.
std::unique_ptr<CgalIndex> BuildCgalIndex(const Mesh& mesh) {
  auto index = std::make_unique<CgalIndex>();
  index->triangles.reserve(static_cast<std::size_t>(mesh.num_triangles()));
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    Kernel::Point_3 corners[3];
    for (int k = 0; k < 3; ++k) {
      const auto row = mesh.vertices.row(mesh.triangles(t, k));
      corners[k] = Kernel::Point_3(row(0), row(1), row(2));
    }
    index->triangles.emplace_back(corners[0], corners[1], corners[2]);
  }
  index->tree.insert(index->triangles.cbegin(), index->triangles.cend());
  index->tree.build();
  index->tree.accelerate_distance_queries();
  return index;
}

double CgalDistance(const CgalTree& tree, const Vector3& q) {
  const Kernel::Point_3 p(q.x(), q.y(), q.z());
  const Kernel::Point_3 closest = tree.closest_point_and_primitive(p).first;
  return std::sqrt(CGAL::squared_distance(p, closest));
}

// #n by 3 points, alternating between uniform in the mesh's bounding box (near the surface,
// where BVH culling is hardest) and uniform in the box of twice its extent about the same
// centre (farther away: tests how quickly the first good candidate is found). Fixed seed, so
// every run and both structures see the same points.
Vertices MakeQueries(const BoundingBox& box, Eigen::Index n) {
  std::mt19937_64 rng(kSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Vector3 centre = 0.5 * (box.min + box.max);
  Vertices queries(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double scale = i % 2 == 0 ? 1.0 : 2.0;
    const double ux = unit(rng), uy = unit(rng), uz = unit(rng);
    const Vector3 u(ux - 0.5, uy - 0.5, uz - 0.5);
    queries.row(i) = (centre + scale * u.cwiseProduct(box.extent())).transpose();
  }
  return queries;
}

// Rows of `queries` with index = first (mod 2): one of the two kinds MakeQueries alternates.
Vertices EveryOther(const Vertices& queries, Eigen::Index first) {
  Vertices out((queries.rows() - first + 1) / 2, 3);
  for (Eigen::Index i = first, j = 0; i < queries.rows(); i += 2, ++j) out.row(j) = queries.row(i);
  return out;
}

struct QuerySet {
  std::string name;  // "mixed" (all), "box1x" (in the bbox), "box2x" (in the doubled box)
  Vertices points;   // #Q by 3
};

struct Fixture {
  std::string path;
  Mesh mesh;
  Vertices queries;  // #kNumQueries by 3
  BoundaryOracle oracle;
  std::unique_ptr<CgalIndex> cgal;
};

std::string MeshPath() {
  const char* dir = std::getenv("INSCRIBE_DATA_DIR");
  const std::string base =
      dir != nullptr && *dir != '\0' ? std::string(dir) : std::string(INSCRIBE_SOURCE_DIR "/data");
  return (std::filesystem::path(base) / kMeshName).string();
}

absl::StatusOr<Fixture> LoadFixture() {
  const std::string path = MeshPath();
  if (!std::filesystem::exists(path)) {
    return absl::NotFoundError(absl::StrCat(
        "mesh not found: ", path, "\n  Set INSCRIBE_DATA_DIR to the directory holding ", kMeshName,
        ", or fetch the test meshes into data/ (scripts/fetch-meshes)."));
  }
  absl::StatusOr<Mesh> read = ReadMesh(path);
  if (!read.ok()) return read.status();
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(read));
  if (!prepared.ok()) return prepared.status();
  Mesh mesh = std::move(prepared->mesh);
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(mesh);
  if (!oracle.ok()) return oracle.status();
  Vertices queries = MakeQueries(ComputeBoundingBox(mesh.vertices), kNumQueries);
  std::unique_ptr<CgalIndex> cgal = BuildCgalIndex(mesh);
  return Fixture{path, std::move(mesh), std::move(queries), *std::move(oracle), std::move(cgal)};
}

// "" when both structures give the same distance for the first kNumChecked queries, else a
// description of the first disagreement. `max_relative` gets the largest relative difference.
std::string CheckAgreement(const Fixture& f, double* max_relative) {
  *max_relative = 0.0;
  for (Eigen::Index i = 0; i < std::min(kNumChecked, f.queries.rows()); ++i) {
    const Vector3 q = f.queries.row(i).transpose();
    const BoundaryPoint ours = f.oracle.ClosestPoint(q);
    const double theirs = CgalDistance(f.cgal->tree, q);
    const double difference = std::abs(ours.distance - theirs);
    const double scale = std::max(ours.distance, theirs);
    if (!(difference <= kMaxRelativeDifference * scale)) {
      char buffer[256];
      std::snprintf(buffer, sizeof(buffer),
                    "query %ld (%.17g, %.17g, %.17g): BoundaryOracle distance %.17g (triangle "
                    "%d), CGAL AABB_tree distance %.17g; relative difference %.3g > %.3g",
                    static_cast<long>(i), q.x(), q.y(), q.z(), ours.distance, ours.triangle, theirs,
                    difference / scale, kMaxRelativeDifference);
      return buffer;
    }
    if (scale > 0.0) *max_relative = std::max(*max_relative, difference / scale);
  }
  return "";
}

void BuildOracle(benchmark::State& state, const Fixture& f) {
  for (auto _ : state) {
    absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(f.mesh);
    if (!oracle.ok()) {
      state.SkipWithError(std::string(oracle.status().message()).c_str());
      break;
    }
    benchmark::DoNotOptimize(oracle);
  }
  state.counters["triangles"] = static_cast<double>(f.mesh.num_triangles());
}

void BuildCgalAabbTree(benchmark::State& state, const Fixture& f) {
  for (auto _ : state) {
    std::unique_ptr<CgalIndex> index = BuildCgalIndex(f.mesh);
    benchmark::DoNotOptimize(index);
  }
  state.counters["triangles"] = static_cast<double>(f.mesh.num_triangles());
}

// One query at a time on this thread, as a caller without its own batching would.
void OracleClosestPoint(benchmark::State& state, const BoundaryOracle& oracle,
                        const Vertices& queries) {
  for (auto _ : state) {
    double sum = 0.0;  // keeps every query observable
    for (Eigen::Index i = 0; i < queries.rows(); ++i) {
      sum += oracle.ClosestPoint(queries.row(i).transpose()).distance;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * queries.rows());
}

void CgalClosestPoint(benchmark::State& state, const Fixture& f, const Vertices& queries) {
  for (auto _ : state) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < queries.rows(); ++i) {
      sum += CgalDistance(f.cgal->tree, queries.row(i).transpose());
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * queries.rows());
}

// The batch entry point: TBB over all cores, so only wall-clock time is meaningful.
void OracleClosestPointsBatch(benchmark::State& state, const Fixture& f) {
  for (auto _ : state) {
    std::vector<BoundaryPoint> points = f.oracle.ClosestPoints(f.queries);
    benchmark::DoNotOptimize(points.data());
  }
  state.SetItemsProcessed(state.iterations() * f.queries.rows());
}

// Refit to new positions of the same triangles (alternating between the mesh and a sheared
// copy, so every call changes every box): compare with BM_BuildOracle.
void OracleRefit(benchmark::State& state, const Fixture& f) {
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(f.mesh);
  Vertices sheared = f.mesh.vertices;
  sheared.col(0) += 0.05 * sheared.col(1);
  bool flip = false;
  for (auto _ : state) {
    flip = !flip;
    const absl::Status status = oracle->Refit(flip ? sheared : f.mesh.vertices);
    if (!status.ok()) {
      state.SkipWithError(std::string(status.message()).c_str());
      break;
    }
  }
}

// Wall-clock time everywhere: Embree builds and the batch use several threads, and CPU time of
// the main thread alone would flatter them. `sets` must outlive the run.
void RegisterAll(const Fixture& f, const std::vector<QuerySet>& sets) {
  benchmark::RegisterBenchmark("BM_BuildOracle", BuildOracle, std::cref(f))
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("BM_BuildCgalAabbTree", BuildCgalAabbTree, std::cref(f))
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  for (const QuerySet& set : sets) {
    benchmark::RegisterBenchmark(("BM_OracleClosestPoint/" + set.name).c_str(), OracleClosestPoint,
                                 std::cref(f.oracle), std::cref(set.points))
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(("BM_CgalClosestPoint/" + set.name).c_str(), CgalClosestPoint,
                                 std::cref(f), std::cref(set.points))
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
  }
  benchmark::RegisterBenchmark("BM_OracleClosestPointsBatch", OracleClosestPointsBatch,
                               std::cref(f))
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("BM_OracleRefit", OracleRefit, std::cref(f))
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  absl::StatusOr<inscribe::Fixture> fixture = inscribe::LoadFixture();
  if (!fixture.ok()) {
    std::fprintf(stderr, "closest_point_bench: %s\n", fixture.status().ToString().c_str());
    return 1;
  }
  double max_relative = 0.0;
  if (const std::string error = inscribe::CheckAgreement(*fixture, &max_relative); !error.empty()) {
    std::fprintf(stderr, "closest_point_bench: structures disagree, not timing them: %s\n",
                 error.c_str());
    return 1;
  }
  benchmark::AddCustomContext("mesh", fixture->path);
  benchmark::AddCustomContext("triangles", std::to_string(fixture->mesh.num_triangles()));
  benchmark::AddCustomContext("queries", std::to_string(fixture->queries.rows()));
  char agreement[96];
  std::snprintf(agreement, sizeof(agreement), "first %ld queries, max relative difference %.3g",
                static_cast<long>(std::min(inscribe::kNumChecked, fixture->queries.rows())),
                max_relative);
  benchmark::AddCustomContext("distance check", agreement);
  const std::vector<inscribe::QuerySet> sets = {
      {"mixed", fixture->queries},
      {"box1x", inscribe::EveryOther(fixture->queries, 0)},
      {"box2x", inscribe::EveryOther(fixture->queries, 1)},
  };
  inscribe::RegisterAll(*fixture, sets);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
