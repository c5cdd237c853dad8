// Certified covers at planner budgets: delta against the sphere count N on each link of the
// demo arm (tests/support/mesh_arm.h, links fitted to 0.1-0.25 m) and on eight, cow and
// elephant, for the cover GenerateCover makes by default and with CoverConstructions::monotone,
// beside each construction alone in the same run: the ladder choice as it was before the
// constructions were added (no tightening, no monotone recursion), one minimum enclosing ball, and
// k-center clusters with an enclosing ball each (untightened). Every set printed is certified
// (CertifyCover passed inside the generator; the program certifies the best set again from scratch
// and exits 1 if that fails). Also: whether delta ever rises with N, how many budgets came back
// short (with the reason), and the seconds of one cold GenerateCover at the counts in --cold (a
// fresh PreparedCover, so the recursion over smaller budgets is paid).
//
//   cover_curve_bench [--counts 1-64] [--cold 9,16,32,64] [--models eight,cow,elephant]
//                     [--no-arm] [--data DIR] [--quick]
//
// Exit status: 0 every check passed; 1 a set failed the fresh certificate or delta rose with N
// (a bug: monotone by construction); 2 a model could not be read.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/cover/sphere_cover.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "support/mesh_arm.h"

namespace {

using namespace inscribe;
using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// "1-64" or "1,2,9": the counts.
std::vector<std::int64_t> ParseCounts(const std::string& text) {
  std::vector<std::int64_t> out;
  for (const absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    const std::vector<std::string> range = absl::StrSplit(part, '-');
    std::int64_t lo = 0, hi = 0;
    if (!absl::SimpleAtoi(range[0], &lo)) continue;
    hi = lo;
    if (range.size() == 2 && !absl::SimpleAtoi(range[1], &hi)) continue;
    for (std::int64_t n = lo; n <= hi; ++n) out.push_back(n);
  }
  return out;
}

struct Method {
  const char* name;
  CoverConstructions constructions;
};

std::vector<Method> Methods() {
  CoverConstructions ladder, ball, clusters, monotone;
  monotone.monotone = true;
  ladder.enclosing_ball = ladder.k_center = ladder.tighten = ladder.monotone = false;
  ball.ladder = ball.k_center = ball.tighten = ball.monotone = false;
  clusters.ladder = clusters.enclosing_ball = clusters.tighten = clusters.monotone = false;
  return {{"default", CoverConstructions{}},
          {"monotone", monotone},
          {"ladder (before)", ladder},
          {"enclosing ball", ball},
          {"k-center", clusters}};
}

struct Named {
  std::string name;
  Solid solid;
  double unit = 1.0;  // printed deltas are in mm (arm links, metres) or % of the largest side
  const char* unit_name = "";
};

// One model's curve: per method, delta at each count; returns false when a check fails.
bool RunModel(const Named& model, const std::vector<std::int64_t>& counts,
              const std::vector<std::int64_t>& cold) {
  const std::int64_t most = *std::max_element(counts.begin(), counts.end());
  const std::vector<Method> methods = Methods();
  std::vector<std::vector<double>> deltas(methods.size());
  std::vector<std::vector<std::size_t>> sizes(methods.size());
  std::vector<double> seconds(methods.size(), 0.0);
  bool ok = true;
  std::int64_t short_budgets = 0;
  std::string reason;
  for (std::size_t m = 0; m < methods.size(); ++m) {
    CoverParameters parameters;
    parameters.max_spheres = most;
    parameters.constructions = methods[m].constructions;
    const auto start = Clock::now();
    absl::StatusOr<PreparedCover> prepared = PreparedCover::Prepare(model.solid, parameters);
    if (!prepared.ok()) {
      absl::FPrintF(stderr, "%s: %s\n", model.name, prepared.status().message());
      return false;
    }
    for (const std::int64_t n : counts) {
      absl::StatusOr<GeneratedCover> cover = prepared->Generate(n);
      if (!cover.ok()) {
        absl::FPrintF(stderr, "%s, %s, N=%d: %s\n", model.name, methods[m].name, n,
                      cover.status().message());
        deltas[m].push_back(-1.0);
        sizes[m].push_back(0);
        if (m <= 1) ok = false;
        continue;
      }
      deltas[m].push_back(cover->certificate.delta);
      sizes[m].push_back(cover->set.size());
      if (m <= 1) {
        absl::StatusOr<CoverCertificate> again = CertifyCover(model.solid, cover->set.spheres);
        if (!again.ok() || !again->certified) {
          absl::FPrintF(stderr, "%s, N=%d: the cover fails a fresh certificate\n", model.name, n);
          ok = false;
        }
        if (m == 1 && !cover->unused_reason.empty()) {
          ++short_budgets;
          reason = cover->unused_reason;
        }
      }
    }
    seconds[m] = SecondsSince(start);
  }
  absl::PrintF(
      "\n### %s (delta in %s)\n\n| N | default | spheres | monotone | spheres | "
      "ladder (before) | enclosing ball | k-center | default / before | monotone / "
      "before |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
      model.name, model.unit_name);
  bool monotone = true;
  for (std::size_t k = 0; k < counts.size(); ++k) {
    if (k > 0 && deltas[1][k] > deltas[1][k - 1] && counts[k] > counts[k - 1] &&
        counts[k] <= kMonotoneCoverBudget) {
      monotone = false;
    }
    const auto show = [&](std::size_t m) {
      return deltas[m][k] < 0.0 ? std::string("failed")
                                : absl::StrFormat("%.2f", deltas[m][k] * model.unit);
    };
    absl::PrintF("| %d | %s | %d | %s | %d | %s | %s | %s | %.2f | %.2f |\n", counts[k], show(0),
                 sizes[0][k], show(1), sizes[1][k], show(2), show(3), show(4),
                 deltas[0][k] / std::max(deltas[2][k], 1e-300),
                 deltas[1][k] / std::max(deltas[2][k], 1e-300));
  }
  absl::PrintF(
      "\nseconds for the whole curve: default %.2f, monotone %.2f, ladder %.2f, "
      "enclosing ball %.2f, k-center %.2f; monotone: delta %s with N, %d budgets short "
      "of N%s%s\n",
      seconds[0], seconds[1], seconds[2], seconds[3], seconds[4],
      monotone ? "never rises" : "RISES", short_budgets, reason.empty() ? "" : ", e.g. ", reason);
  if (!monotone) ok = false;
  for (const std::int64_t n : cold) {
    CoverParameters parameters;
    parameters.max_spheres = n;
    const auto start = Clock::now();
    absl::StatusOr<GeneratedCover> cover = GenerateCover(model.solid, parameters);
    const double s = SecondsSince(start);
    parameters.constructions.monotone = true;
    const auto monotone_start = Clock::now();
    absl::StatusOr<GeneratedCover> monotone_cover = GenerateCover(model.solid, parameters);
    const double monotone_s = SecondsSince(monotone_start);
    if (!cover.ok() || !monotone_cover.ok()) {
      ok = false;
      continue;
    }
    absl::PrintF(
        "cold GenerateCover, N=%d: default %.2f s (delta %.2f), monotone %.2f s "
        "(delta %.2f)\n",
        n, s, cover->certificate.delta * model.unit, monotone_s,
        monotone_cover->certificate.delta * model.unit);
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Certified covers: delta against the sphere count"};
  std::string counts_text = "1-64", cold_text = "9,16,32,64", models_text = "eight,cow,elephant";
  std::string data_dir = INSCRIBE_SOURCE_DIR "/data";
  if (const char* env = std::getenv("INSCRIBE_DATA_DIR")) data_dir = env;
  bool no_arm = false, quick = false;
  app.add_option("--counts", counts_text, "Sphere counts: ranges and lists, e.g. 1-64 or 1,9,32");
  app.add_option("--cold", cold_text, "Counts timed as one cold GenerateCover each");
  app.add_option("--models", models_text, "Demo meshes besides the arm (empty: none)");
  app.add_option("--data", data_dir, "Directory of the demo meshes");
  app.add_flag("--no-arm", no_arm, "Leave out the demo arm's links");
  app.add_flag("--quick", quick, "Smoke run: eight only, counts 1-6, cold 4");
  CLI11_PARSE(app, argc, argv);
  if (quick) {
    counts_text = "1-6";
    cold_text = "4";
    models_text = "eight";
    no_arm = true;
  }
  const std::vector<std::int64_t> counts = ParseCounts(counts_text);
  const std::vector<std::int64_t> cold = ParseCounts(cold_text);
  if (counts.empty()) {
    absl::FPrintF(stderr, "cover_curve_bench: --counts gives no count\n");
    return 2;
  }
  std::vector<Named> models;
  const auto read = [&](const std::string& file) -> absl::StatusOr<Mesh> {
    absl::StatusOr<Mesh> mesh = ReadMesh(data_dir + "/" + file);
    if (!mesh.ok()) return mesh.status();
    absl::StatusOr<ValidatedMesh> valid = PrepareMesh(*std::move(mesh));
    if (!valid.ok()) return valid.status();
    return std::move(valid->mesh);
  };
  if (!no_arm) {
    std::vector<Mesh> meshes;
    for (const std::string& file : testing::MeshArmModels()) {
      absl::StatusOr<Mesh> mesh = read(file);
      if (!mesh.ok()) {
        absl::FPrintF(stderr, "cover_curve_bench: %s: %s\n", file, mesh.status().message());
        return 2;
      }
      meshes.push_back(*std::move(mesh));
    }
    absl::StatusOr<testing::MeshArm> arm =
        testing::BuildMeshArm(std::move(meshes), testing::MeshArmJoints::kRevolute);
    if (!arm.ok()) {
      absl::FPrintF(stderr, "cover_curve_bench: %s\n", arm.status().message());
      return 2;
    }
    for (std::size_t l = 0; l < arm->solids.size(); ++l) {
      models.push_back({absl::StrFormat("link%d (%s)", l, testing::MeshArmModels()[l]),
                        std::move(arm->solids[l]), 1000.0, "mm"});
    }
  }
  for (const absl::string_view name : absl::StrSplit(models_text, ',', absl::SkipEmpty())) {
    absl::StatusOr<Mesh> mesh = read(absl::StrCat(name, ".off"));
    if (!mesh.ok()) {
      absl::FPrintF(stderr, "cover_curve_bench: %s: %s\n", name, mesh.status().message());
      return 2;
    }
    absl::StatusOr<Solid> solid = PrepareSolid(*std::move(mesh));
    if (!solid.ok()) return 2;
    const double largest = ComputeBoundingBox(solid->mesh().vertices).extent().maxCoeff();
    models.push_back(
        {std::string(name), *std::move(solid), 100.0 / largest, "% of the largest side"});
  }
  bool ok = true;
  for (const Named& model : models) ok = RunModel(model, counts, cold) && ok;
  return ok ? 0 : 1;
}
