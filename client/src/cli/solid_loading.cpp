#include "solid_loading.h"

#include <chrono>
#include <iostream>

#include "exit_codes.h"
#include "inscribe/mesh_hash.h"
#include "inscribe/mesh_io.h"

namespace inscribe::cli {
namespace {

// The solid is no longer the file's: say so, since hashes and results now differ from it.
void NoteRepairs(const std::string& path, const MeshReport& report) {
  for (const MeshIssue& issue : report.issues) {
    if (issue.code == "holes_filled") {
      std::cerr << "inscribe: " << path << ": " << issue.message << "\n";
    }
  }
}

}  // namespace

std::optional<LoadedSolid> LoadSolid(const std::string& path, int* exit_code,
                                     const LoadSolidOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Mesh> mesh = ReadMesh(path, nullptr);
  if (!mesh.ok()) {
    std::cerr << "inscribe: " << mesh.status().message() << "\n";
    *exit_code = kExitBadInput;
    return std::nullopt;
  }
  SolidOptions solid_options;
  solid_options.validate.fill_holes = options.fill_holes;
  absl::StatusOr<Solid> solid = PrepareSolid(*std::move(mesh), solid_options);
  if (!solid.ok()) {
    std::cerr << "inscribe: " << path << ": " << solid.status().message() << "\n";
    *exit_code = kExitUnusableMesh;
    return std::nullopt;
  }
  NoteRepairs(path, solid->report);
  return LoadedSolid{
      *std::move(solid),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

std::optional<UploadedSolid> UploadSolid(const client::Client& client, const RemoteOptions& remote,
                                         const std::string& path, int* exit_code,
                                         const LoadSolidOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<Mesh> mesh = ReadMesh(path, nullptr);
  if (!mesh.ok()) {
    std::cerr << "inscribe: " << mesh.status().message() << "\n";
    *exit_code = kExitBadInput;
    return std::nullopt;
  }
  absl::StatusOr<client::PutMeshResult> stored = client.PutMesh(*mesh, options.fill_holes);
  if (!stored.ok()) {
    *exit_code = ReportRemoteError(stored.status(), remote);
    return std::nullopt;
  }
  NoteRepairs(path, stored->report);
  return UploadedSolid{
      *std::move(mesh), std::move(stored->report), std::move(stored->mesh_sha256),
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
}

}  // namespace inscribe::cli
