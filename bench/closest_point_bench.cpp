// Closest-point queries: inscribe's BoundaryOracle with each backend (kFlatBvh, its own flat
// BVH; kEmbree, Embree 3 with a double-precision callback), against CGAL 5.5's AABB_tree
// (Simple_cartesian<double>, the fastest CGAL kernel for this, with its KD-tree start hint), on
// data/bunny00.off (75,408 triangles) and data/fandisk.off (12,946). All answer the same
// queries, and setup checks that they agree (the two backends bit for bit, CGAL to 1e-9
// relative) before anything is timed: a benchmark of wrong answers is worthless.
//
//   INSCRIBE_DATA_DIR=/path/to/meshes ./closest_point_bench [--benchmark_* flags]
//
// Query benchmarks time one pass over a query set per iteration, one query at a time on one
// thread, and report items_per_second = queries per second (wall clock). Build and refit
// benchmarks report ms per call. Names end in /<mesh>.
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
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using CgalTriangles = std::vector<Kernel::Triangle_3>;
using CgalPrimitive = CGAL::AABB_triangle_primitive<Kernel, CgalTriangles::const_iterator>;
using CgalTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CgalPrimitive>>;

// A large scanned mesh and a mid-sized CAD mesh with sharp edges.
constexpr const char* kMeshNames[] = {"bunny00.off", "fandisk.off"};
constexpr Eigen::Index kNumQueries = 100000;
// Random walks for the coherent query set: steps of this fraction of the bbox diagonal, a new
// random start every kWalkLength steps.
constexpr double kWalkStep = 0.005;
constexpr Eigen::Index kWalkLength = 100;
// Points compared between the structures before timing, and the largest relative difference
// in distance accepted against CGAL. Both compute in double precision with different formulas;
// cancellation makes the difference grow like 1e-16 * |coordinates| / distance, so queries near
// the surface differ most (7e-12 at worst over all 100k queries on bunny00), still far below.
constexpr Eigen::Index kNumChecked = 1000;
constexpr double kMaxRelativeDifference = 1e-9;
constexpr std::uint64_t kSeed = 0x5eed'b077;

constexpr double kNoBound = std::numeric_limits<double>::infinity();

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
// every run and every structure see the same points.
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

// #n by 3 points on random walks in the bounding box (steps of kWalkStep diagonals, a fresh
// start every kWalkLength): consecutive queries close together, as a caller probing around a
// point issues them (the medial-sphere generator samples voxel by voxel).
Vertices MakeWalk(const BoundingBox& box, Eigen::Index n) {
  std::mt19937_64 rng(kSeed + 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  Vertices walk(n, 3);
  Vector3 x = Vector3::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (i % kWalkLength == 0) {
      x = box.min + box.extent().cwiseProduct(Vector3(unit(rng), unit(rng), unit(rng)));
    } else {
      const Vector3 step = Vector3(normal(rng), normal(rng), normal(rng)).normalized();
      x = (x + kWalkStep * box.diagonal() * step).cwiseMax(box.min).cwiseMin(box.max);
    }
    walk.row(i) = x.transpose();
  }
  return walk;
}

// Rows of `queries` with index = first (mod 2): one of the two kinds MakeQueries alternates.
Vertices EveryOther(const Vertices& queries, Eigen::Index first) {
  Vertices out((queries.rows() - first + 1) / 2, 3);
  for (Eigen::Index i = first, j = 0; i < queries.rows(); i += 2, ++j) out.row(j) = queries.row(i);
  return out;
}

struct QuerySet {
  std::string name;  // "mixed" (all), "box1x" (in the bbox), "box2x" (in the doubled box), "walk"
  Vertices points;   // #Q by 3
};

struct Fixture {
  std::string name;  // mesh file name without extension
  std::string path;
  Mesh mesh;
  std::vector<QuerySet> sets;
  // For the walk: the bound a caller stepping along it knows, |walk_i - B(walk_{i-1})| (the
  // distance to the previous answer's boundary point); infinity at each walk's start.
  std::vector<double> walk_bounds;
  BoundaryOracle flat;
  BoundaryOracle embree;
  std::unique_ptr<CgalIndex> cgal;

  const QuerySet& set(const std::string& set_name) const {
    for (const QuerySet& s : sets) {
      if (s.name == set_name) return s;
    }
    std::abort();
  }
};

std::string MeshPath(const std::string& name) {
  const char* dir = std::getenv("INSCRIBE_DATA_DIR");
  const std::string base =
      dir != nullptr && *dir != '\0' ? std::string(dir) : std::string(INSCRIBE_SOURCE_DIR "/data");
  return (std::filesystem::path(base) / name).string();
}

BoundaryOracleOptions WithBackend(BoundaryOracleBackend backend) {
  BoundaryOracleOptions options;
  options.backend = backend;
  return options;
}

absl::StatusOr<std::unique_ptr<Fixture>> LoadFixture(const std::string& file_name) {
  const std::string path = MeshPath(file_name);
  if (!std::filesystem::exists(path)) {
    return absl::NotFoundError(absl::StrCat(
        "mesh not found: ", path, "\n  Set INSCRIBE_DATA_DIR to the directory holding ", file_name,
        ", or fetch the test meshes into data/ (scripts/fetch-meshes)."));
  }
  absl::StatusOr<Mesh> read = ReadMesh(path);
  if (!read.ok()) return read.status();
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(read));
  if (!prepared.ok()) return prepared.status();
  Mesh mesh = std::move(prepared->mesh);
  absl::StatusOr<BoundaryOracle> flat =
      BoundaryOracle::Build(mesh, WithBackend(BoundaryOracleBackend::kFlatBvh));
  if (!flat.ok()) return flat.status();
  absl::StatusOr<BoundaryOracle> embree =
      BoundaryOracle::Build(mesh, WithBackend(BoundaryOracleBackend::kEmbree));
  if (!embree.ok()) return embree.status();
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  Vertices queries = MakeQueries(box, kNumQueries);
  std::vector<QuerySet> sets = {{"mixed", queries},
                                {"box1x", EveryOther(queries, 0)},
                                {"box2x", EveryOther(queries, 1)},
                                {"walk", MakeWalk(box, kNumQueries)}};
  const Vertices& walk = sets.back().points;
  std::vector<double> walk_bounds(static_cast<std::size_t>(walk.rows()), kNoBound);
  const std::vector<BoundaryPoint> walk_answers = flat->ClosestPoints(walk);
  for (Eigen::Index i = 1; i < walk.rows(); ++i) {
    if (i % kWalkLength == 0) continue;
    walk_bounds[static_cast<std::size_t>(i)] =
        (walk.row(i).transpose() - walk_answers[static_cast<std::size_t>(i - 1)].point).norm();
  }
  std::unique_ptr<CgalIndex> cgal = BuildCgalIndex(mesh);
  const std::string name = file_name.substr(0, file_name.find('.'));
  return std::make_unique<Fixture>(Fixture{name, path, std::move(mesh), std::move(sets),
                                           std::move(walk_bounds), *std::move(flat),
                                           *std::move(embree), std::move(cgal)});
}

bool Identical(const BoundaryPoint& a, const BoundaryPoint& b) {
  return a.triangle == b.triangle && a.point == b.point && a.barycentric == b.barycentric &&
         a.distance == b.distance;
}

// "" when, for the first kNumChecked queries of every set, the backends agree bit for bit (also
// with the walk's bounds) and with CGAL to kMaxRelativeDifference; else a description of the
// first disagreement. `max_relative` gets the largest relative difference from CGAL.
std::string CheckAgreement(const Fixture& f, double* max_relative) {
  *max_relative = 0.0;
  char buffer[512];
  for (const QuerySet& set : f.sets) {
    for (Eigen::Index i = 0; i < std::min(kNumChecked, set.points.rows()); ++i) {
      const Vector3 q = set.points.row(i).transpose();
      const BoundaryPoint flat = f.flat.ClosestPoint(q);
      const BoundaryPoint embree = f.embree.ClosestPoint(q);
      if (!Identical(flat, embree)) {
        std::snprintf(buffer, sizeof(buffer),
                      "%s query %ld: flat BVH distance %.17g (triangle %d), Embree %.17g "
                      "(triangle %d)",
                      set.name.c_str(), static_cast<long>(i), flat.distance, flat.triangle,
                      embree.distance, embree.triangle);
        return buffer;
      }
      if (set.name == "walk") {
        const double bound = f.walk_bounds[static_cast<std::size_t>(i)];
        if (!Identical(f.flat.ClosestPoint(q, bound), flat) ||
            !Identical(f.embree.ClosestPoint(q, bound), flat)) {
          std::snprintf(buffer, sizeof(buffer), "walk query %ld: bounded query differs",
                        static_cast<long>(i));
          return buffer;
        }
      }
      const double theirs = CgalDistance(f.cgal->tree, q);
      const double difference = std::abs(flat.distance - theirs);
      const double scale = std::max(flat.distance, theirs);
      if (!(difference <= kMaxRelativeDifference * scale)) {
        std::snprintf(buffer, sizeof(buffer),
                      "%s query %ld (%.17g, %.17g, %.17g): BoundaryOracle distance %.17g "
                      "(triangle %d), CGAL AABB_tree distance %.17g; relative difference %.3g > "
                      "%.3g",
                      set.name.c_str(), static_cast<long>(i), q.x(), q.y(), q.z(), flat.distance,
                      flat.triangle, theirs, difference / scale, kMaxRelativeDifference);
        return buffer;
      }
      if (scale > 0.0) *max_relative = std::max(*max_relative, difference / scale);
    }
  }
  return "";
}

void BuildOracle(benchmark::State& state, const Fixture& f, BoundaryOracleBackend backend) {
  for (auto _ : state) {
    absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(f.mesh, WithBackend(backend));
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

// One query at a time on this thread, as a caller without its own batching would. With
// `bounds`, query i passes bounds[i] (ClosestPoint(query, upper_bound)).
void OracleClosestPoint(benchmark::State& state, const BoundaryOracle& oracle,
                        const Vertices& queries, const std::vector<double>* bounds) {
  for (auto _ : state) {
    double sum = 0.0;  // keeps every query observable
    if (bounds == nullptr) {
      for (Eigen::Index i = 0; i < queries.rows(); ++i) {
        sum += oracle.ClosestPoint(queries.row(i).transpose()).distance;
      }
    } else {
      for (Eigen::Index i = 0; i < queries.rows(); ++i) {
        sum +=
            oracle.ClosestPoint(queries.row(i).transpose(), (*bounds)[static_cast<std::size_t>(i)])
                .distance;
      }
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
void OracleClosestPointsBatch(benchmark::State& state, const BoundaryOracle& oracle,
                              const Vertices& queries) {
  for (auto _ : state) {
    std::vector<BoundaryPoint> points = oracle.ClosestPoints(queries);
    benchmark::DoNotOptimize(points.data());
  }
  state.SetItemsProcessed(state.iterations() * queries.rows());
}

// Refit to new positions of the same triangles (alternating between the mesh and a sheared
// copy, so every call changes every box): compare with BM_Build*.
void OracleRefit(benchmark::State& state, const Fixture& f, BoundaryOracleBackend backend) {
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(f.mesh, WithBackend(backend));
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

// Wall-clock time everywhere: Embree builds and the batches use several threads, and CPU time
// of the main thread alone would flatter them. `f` must outlive the run.
void RegisterAll(const Fixture& f) {
  const auto ms = [](benchmark::internal::Benchmark* b) {
    b->Unit(benchmark::kMillisecond)->UseRealTime();
  };
  const std::string mesh = "/" + f.name;
  const BoundaryOracleBackend kFlat = BoundaryOracleBackend::kFlatBvh;
  const BoundaryOracleBackend kEmbree = BoundaryOracleBackend::kEmbree;
  ms(benchmark::RegisterBenchmark(("BM_BuildFlatBvh" + mesh).c_str(), BuildOracle, std::cref(f),
                                  kFlat));
  ms(benchmark::RegisterBenchmark(("BM_BuildEmbree" + mesh).c_str(), BuildOracle, std::cref(f),
                                  kEmbree));
  ms(benchmark::RegisterBenchmark(("BM_BuildCgalAabbTree" + mesh).c_str(), BuildCgalAabbTree,
                                  std::cref(f)));
  ms(benchmark::RegisterBenchmark(("BM_RefitFlatBvh" + mesh).c_str(), OracleRefit, std::cref(f),
                                  kFlat));
  ms(benchmark::RegisterBenchmark(("BM_RefitEmbree" + mesh).c_str(), OracleRefit, std::cref(f),
                                  kEmbree));
  for (const QuerySet& set : f.sets) {
    const std::string suffix = "/" + set.name + mesh;
    ms(benchmark::RegisterBenchmark(("BM_FlatBvhClosestPoint" + suffix).c_str(), OracleClosestPoint,
                                    std::cref(f.flat), std::cref(set.points), nullptr));
    ms(benchmark::RegisterBenchmark(("BM_EmbreeClosestPoint" + suffix).c_str(), OracleClosestPoint,
                                    std::cref(f.embree), std::cref(set.points), nullptr));
    ms(benchmark::RegisterBenchmark(("BM_CgalClosestPoint" + suffix).c_str(), CgalClosestPoint,
                                    std::cref(f), std::cref(set.points)));
  }
  const QuerySet& walk = f.set("walk");
  ms(benchmark::RegisterBenchmark(("BM_FlatBvhClosestPointBounded/walk" + mesh).c_str(),
                                  OracleClosestPoint, std::cref(f.flat), std::cref(walk.points),
                                  &f.walk_bounds));
  ms(benchmark::RegisterBenchmark(("BM_EmbreeClosestPointBounded/walk" + mesh).c_str(),
                                  OracleClosestPoint, std::cref(f.embree), std::cref(walk.points),
                                  &f.walk_bounds));
  const QuerySet& mixed = f.set("mixed");
  ms(benchmark::RegisterBenchmark(("BM_FlatBvhClosestPointsBatch/mixed" + mesh).c_str(),
                                  OracleClosestPointsBatch, std::cref(f.flat),
                                  std::cref(mixed.points)));
  ms(benchmark::RegisterBenchmark(("BM_EmbreeClosestPointsBatch/mixed" + mesh).c_str(),
                                  OracleClosestPointsBatch, std::cref(f.embree),
                                  std::cref(mixed.points)));
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  std::vector<std::unique_ptr<inscribe::Fixture>> fixtures;
  for (const char* name : inscribe::kMeshNames) {
    absl::StatusOr<std::unique_ptr<inscribe::Fixture>> fixture = inscribe::LoadFixture(name);
    if (!fixture.ok()) {
      std::fprintf(stderr, "closest_point_bench: %s\n", fixture.status().ToString().c_str());
      return 1;
    }
    double max_relative = 0.0;
    if (const std::string error = inscribe::CheckAgreement(**fixture, &max_relative);
        !error.empty()) {
      std::fprintf(stderr, "closest_point_bench: %s: structures disagree, not timing them: %s\n",
                   name, error.c_str());
      return 1;
    }
    const inscribe::Fixture& f = **fixture;
    char context[512];
    std::snprintf(context, sizeof(context),
                  "%s, %ld triangles, %ld queries per set; first %ld of each checked, max relative "
                  "difference from CGAL %.3g",
                  f.path.c_str(), static_cast<long>(f.mesh.num_triangles()),
                  static_cast<long>(inscribe::kNumQueries),
                  static_cast<long>(inscribe::kNumChecked), max_relative);
    benchmark::AddCustomContext("mesh " + f.name, context);
    fixtures.push_back(*std::move(fixture));
  }
  for (const auto& f : fixtures) inscribe::RegisterAll(*f);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
