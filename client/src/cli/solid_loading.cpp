#include "solid_loading.h"

#include <chrono>
#include <iostream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "command_outcome.h"
#include "inscribe/mesh/mesh_io.h"
#include "progress_bar.h"

namespace inscribe::cli {
namespace {

// Every warning and fix validation made (MeshReport::notices), one line each, and when the
// geometry was repaired, that what follows holds for the repaired mesh only.
void NoteRepairs(const std::string& path, const MeshReport& report, const std::string& sha256) {
  for (const MeshIssue& issue : report.notices()) {
    std::cerr << "inscribe: " << path << ": " << SeverityName(issue.severity) << ": "
              << issue.message << "\n";
  }
  if (report.geometry_repaired()) {
    std::cerr << "inscribe: " << path << ": results and certificates hold for the repaired mesh "
              << sha256 << ", not for the file's triangles as given\n";
  }
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

void AddRepairOptions(CLI::App* cmd, RepairOptions* repair) {
  CLI::Option* level =
      cmd->add_option_function<std::string>(
             "--repair",
             [repair](const std::string& name) {
               // IsMember below admits only the names ParseMeshRepair knows.
               repair->level = ParseMeshRepair(name).value_or(repair->level);
             },
             "How much the mesh may be changed to make it usable: none (identical vertices "
             "welded, orientation fixed), safe (also duplicate triangles and walls stored twice "
             "removed, cracks welded within a tolerance from the mesh's size; the default), "
             "fill (also holes closed), wrap (a watertight alpha wrap of all the triangles), "
             "auto (safe, then fill, then wrap, until the mesh is usable)")
          ->check(CLI::IsMember({"none", "safe", "fill", "wrap", "auto"}));
  cmd->add_flag_callback(
         "--fill-holes", [repair] { repair->level = MeshRepair::kFill; },
         "Close the mesh's holes (the same as --repair fill)")
      ->excludes(level);
  cmd->add_option("--weld-tolerance", repair->weld_tolerance,
                  "Also weld vertices this close (mesh units), for files that repeat each vertex "
                  "per face with slightly different coordinates; exactly coincident vertices are "
                  "always welded")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--wrap-alpha", repair->wrap_alpha,
                  absl::StrCat("The wrap's alpha (mesh units): gaps and holes narrower than "
                               "about this are bridged; smaller costs more (about 1/alpha^2). "
                               "Default: the bounding box's diagonal / ",
                               kWrapAlphaDivisor))
      ->check(CLI::PositiveNumber);
  cmd->add_option("--wrap-offset", repair->wrap_offset,
                  absl::StrCat("How far outside the input triangles the wrap lies (mesh "
                               "units). Default: alpha / ",
                               kWrapOffsetDivisor))
      ->check(CLI::PositiveNumber);
}

void AddSolidLoadOptions(CLI::App* cmd, SolidLoadOptions* options) {
  AddRepairOptions(cmd, &options->repair);
  cmd->add_option("--scale", options->scale,
                  "Multiply the mesh's coordinates by this as it is read (0.001: a mesh in "
                  "millimetres to metres); the hash and every result are the scaled mesh's")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
}

absl::StatusOr<Mesh> ReadScaledMesh(const std::string& path, double scale, ReadMeshInfo* info) {
  absl::StatusOr<Mesh> mesh;
  {
    const ProgressStage stage("reading " + path);
    mesh = ReadMesh(path, info);
  }
  if (!mesh.ok()) return BadInputError(mesh.status().message());
  if (scale != 1.0) mesh->vertices *= scale;
  return mesh;
}

absl::StatusOr<LoadedSolid> LoadSolid(const std::string& path, const SolidLoadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Mesh> mesh = ReadScaledMesh(path, options.scale);
  if (!mesh.ok()) return mesh.status();
  SolidOptions solid_options;
  solid_options.validate.repair = options.repair;
  absl::StatusOr<Solid> solid = absl::UnknownError("not prepared");
  {
    const ProgressStage stage(absl::StrCat("validating ", mesh->num_triangles(), " triangles"));
    solid = PrepareSolid(*std::move(mesh), solid_options);
  }
  if (!solid.ok()) return UnusableMeshError(path + ": " + std::string(solid.status().message()));
  NoteRepairs(path, solid->report, solid->sha256);
  return LoadedSolid{*std::move(solid), SecondsSince(start)};
}

absl::StatusOr<StoredSolid> StoreSolid(const client::Client& client, const std::string& path,
                                       const SolidLoadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Mesh> mesh = ReadScaledMesh(path, options.scale);
  if (!mesh.ok()) return mesh.status();
  client::PutMeshOptions put;
  put.repair = options.repair;
  absl::StatusOr<client::PutMeshResult> stored;
  {
    const ProgressStage stage(absl::StrCat("validating ", mesh->num_triangles(), " triangles"));
    stored = client.PutMesh(*mesh, put);
  }
  if (!stored.ok()) {
    if (stored.status().code() == absl::StatusCode::kFailedPrecondition) {
      return WithContext(path, stored.status());
    }
    return stored.status();
  }
  NoteRepairs(path, stored->report, stored->mesh_sha256);
  return StoredSolid{*std::move(mesh), std::move(stored->report), std::move(stored->mesh_sha256),
                     SecondsSince(start)};
}

}  // namespace inscribe::cli
