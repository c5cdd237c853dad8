#include "solid_loading.h"

#include <chrono>
#include <iostream>
#include <utility>

#include "command_outcome.h"
#include "inscribe/mesh_io.h"

namespace inscribe::cli {
namespace {

// The solid is no longer the file's: say so, since hashes and results now differ from it.
void NoteRepairs(const std::string& path, const MeshReport& report) {
  for (const MeshIssue& issue : report.issues) {
    if (issue.code == "holes_filled" ||
        (issue.code == "welded_vertices" && report.weld_collapsed_triangles > 0)) {
      std::cerr << "inscribe: " << path << ": " << issue.message << "\n";
    }
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
  NoteRepairs(path, solid->report);
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
  NoteRepairs(path, stored->report);
  return StoredSolid{*std::move(mesh), std::move(stored->report), std::move(stored->mesh_sha256),
                     SecondsSince(start)};
}

}  // namespace inscribe::cli
