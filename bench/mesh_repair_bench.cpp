// The repair ladder on the broken-mesh corpus (tests/support/broken_meshes.cpp) and the wrap's
// cost at scale. Two tables:
//   1. per corpus mesh: which levels make it usable, the time of each, and whether a cover of
//      the mesh `auto` gives is certified (GenerateSphereSet, kind cover, 32 spheres);
//   2. the wrap of icospheres of about 10k, 100k and 1M triangles (and the demo meshes given
//      with --meshes) at the default alpha: time, the wrap's triangles, its reach over the
//      offset, against plain validation (none) of the same input in the same run.
//
//   mesh_repair_bench [--quick] [--meshes a.off,b.off] [--sizes 5,6,8]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "absl/strings/str_split.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "support/broken_meshes.h"
#include "support/synthetic_meshes.h"

namespace inscribe {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

ValidatedMesh Timed(const Mesh& mesh, MeshRepair level, double* seconds) {
  ValidateOptions options;
  options.repair.level = level;
  const auto start = std::chrono::steady_clock::now();
  ValidatedMesh v = ValidateMesh(mesh, options);
  *seconds = SecondsSince(start);
  return v;
}

int CorpusTable() {
  std::printf("## The corpus: usable at each level (time, s), and auto's cover\n\n");
  std::printf("| mesh | needs | none | safe | fill | wrap | auto | cover of auto |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- |\n");
  int failures = 0, usable_by_one_option = 0, total = 0;
  for (const testing::BrokenMesh& entry : testing::BrokenMeshCorpus()) {
    std::printf("| %s | %s |", entry.name.c_str(), MeshRepairName(entry.needs));
    bool one_option = false;
    ValidatedMesh automatic;
    for (MeshRepair level : {MeshRepair::kNone, MeshRepair::kSafe, MeshRepair::kFill,
                             MeshRepair::kWrap, MeshRepair::kAuto}) {
      double seconds = 0.0;
      ValidatedMesh v = Timed(entry.mesh, level, &seconds);
      std::printf(" %s %.3f |", v.report.usable() ? "yes" : "no", seconds);
      if (level != MeshRepair::kNone && v.report.usable()) one_option = true;
      if (level == MeshRepair::kAuto) automatic = std::move(v);
    }
    ++total;
    usable_by_one_option += one_option ? 1 : 0;
    std::string cover = "-";
    if (automatic.report.usable()) {
      absl::StatusOr<Solid> solid = MakeSolid(std::move(automatic));
      SphereSetParameters parameters;
      parameters.kind = SphereSetKind::kCover;
      parameters.max_spheres = 32;
      parameters.evaluate = false;
      absl::StatusOr<GeneratedSphereSet> set =
          solid.ok() ? GenerateSphereSet(*solid, parameters)
                     : absl::StatusOr<GeneratedSphereSet>(solid.status());
      if (set.ok() && set->cover && set->cover->certificate.certified) {
        char text[64];
        std::snprintf(text, sizeof(text), "certified, delta %.3g", set->cover->certificate.delta);
        cover = text;
      } else {
        cover = set.ok() ? "NOT certified" : std::string(set.status().message()).substr(0, 60);
        ++failures;
      }
    } else {
      ++failures;
    }
    std::printf(" %s |\n", cover.c_str());
  }
  std::printf(
      "\n%d of %d usable with the defaults or one --repair option; %d without a certified "
      "cover from auto\n\n",
      usable_by_one_option, total, failures);
  return failures;
}

void WrapRow(const std::string& name, const Mesh& mesh) {
  double plain_seconds = 0.0, wrap_seconds = 0.0;
  const ValidatedMesh plain = Timed(mesh, MeshRepair::kNone, &plain_seconds);
  const ValidatedMesh wrapped = Timed(mesh, MeshRepair::kWrap, &wrap_seconds);
  const MeshReport& r = wrapped.report;
  std::printf("| %s | %lld | %.3f | %.3f | %.1fx | %lld | %.3g | %.3g | %.2f | %s |\n",
              name.c_str(), static_cast<long long>(mesh.num_triangles()), plain_seconds,
              wrap_seconds, wrap_seconds / plain_seconds, static_cast<long long>(r.wrap_triangles),
              r.wrap_alpha, r.wrap_offset, r.wrap_offset > 0 ? r.wrap_reach / r.wrap_offset : 0.0,
              r.usable() ? "yes" : r.first_error().substr(0, 50).c_str());
}

}  // namespace
}  // namespace inscribe

int main(int argc, char** argv) {
  CLI::App app{"The repair ladder on the broken-mesh corpus, and the wrap at scale"};
  bool quick = false;
  std::string meshes, sizes = "5,6,8";
  app.add_flag("--quick", quick, "The corpus and the 20k-triangle wrap only (the suite's smoke)");
  app.add_option("--meshes", meshes, "Comma-separated mesh files to wrap as well");
  app.add_option("--sizes", sizes, "Icosphere subdivision levels (20 * 4^L triangles)");
  CLI11_PARSE(app, argc, argv);
  const int failures = inscribe::CorpusTable();
  std::printf("## The wrap at the default alpha (diagonal / 50), against validation alone\n\n");
  std::printf(
      "| input | triangles | none, s | wrap, s | wrap / none | wrap triangles | alpha | "
      "offset | reach / offset | usable |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  const std::vector<std::string> levels = absl::StrSplit(quick ? std::string("5") : sizes, ',');
  for (const std::string& level : levels) {
    const int l = std::stoi(level);
    inscribe::WrapRow("icosphere " + level, inscribe::testing::Icosphere(l));
  }
  if (!meshes.empty() && !quick) {
    const std::vector<std::string> paths = absl::StrSplit(meshes, ',');
    for (const std::string& path : paths) {
      absl::StatusOr<inscribe::Mesh> mesh = inscribe::ReadMesh(path);
      if (!mesh.ok()) {
        std::fprintf(stderr, "%s\n", std::string(mesh.status().message()).c_str());
        return 2;
      }
      inscribe::WrapRow(path, *mesh);
    }
  }
  return failures == 0 ? 0 : 1;
}
