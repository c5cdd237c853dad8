#include "solid_loading.h"

#include <chrono>
#include <iostream>
#include <utility>

#include "command_outcome.h"
#include "inscribe/mesh/mesh_io.h"

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

void AddWeldToleranceOption(CLI::App* cmd, double* weld_tolerance) {
  cmd->add_option("--weld-tolerance", *weld_tolerance,
                  "Also weld vertices this close (mesh units), for files that repeat each vertex "
                  "per face with slightly different coordinates; exactly coincident vertices are "
                  "always welded")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
}

absl::StatusOr<LoadedSolid> LoadSolid(const std::string& path, const SolidLoadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Mesh> mesh = ReadMesh(path, nullptr);
  if (!mesh.ok()) return BadInputError(mesh.status().message());
  SolidOptions solid_options;
  solid_options.validate.fill_holes = options.fill_holes;
  solid_options.validate.weld_tolerance = options.weld_tolerance;
  absl::StatusOr<Solid> solid = PrepareSolid(*std::move(mesh), solid_options);
  if (!solid.ok()) return UnusableMeshError(path + ": " + std::string(solid.status().message()));
  NoteRepairs(path, solid->report, solid->sha256);
  return LoadedSolid{*std::move(solid), SecondsSince(start)};
}

absl::StatusOr<StoredSolid> StoreSolid(const client::Client& client, const std::string& path,
                                       const SolidLoadOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Mesh> mesh = ReadMesh(path, nullptr);
  if (!mesh.ok()) return BadInputError(mesh.status().message());
  client::PutMeshOptions put;
  put.fill_holes = options.fill_holes;
  put.weld_tolerance = options.weld_tolerance;
  absl::StatusOr<client::PutMeshResult> stored = client.PutMesh(*mesh, put);
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
