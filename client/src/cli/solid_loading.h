// Loading a mesh for sphere work: read, validate (fix orientation), hash, build the oracle;
// or, with --server, read here and store on the server, which validates it. Shared by the
// subcommands that need a usable solid (generate, evaluate).
#pragma once

#include <optional>
#include <string>

#include "inscribe/boundary_oracle.h"
#include "inscribe/client/client.h"
#include "inscribe/mesh_validation.h"
#include "inscribe/solid.h"
#include "remote_options.h"

namespace inscribe::cli {

struct LoadedSolid {
  Solid solid;
  double seconds = 0.0;  // reading + validation + oracle build
};

struct LoadSolidOptions {
  // Close the mesh's holes before use (ValidateOptions::fill_holes, `--fill-holes`); the hash
  // and the oracle are then those of the repaired mesh, and one line on stderr says so.
  bool fill_holes = false;
};

// Prints the reason on stderr and sets *exit_code (kExitBadInput for unreadable files,
// kExitUnusableMesh for meshes that are not closed solids) when it returns nothing. The solid
// is core's PrepareSolid (its inside-test rule included).
std::optional<LoadedSolid> LoadSolid(const std::string& path, int* exit_code,
                                     const LoadSolidOptions& options = {});

// A mesh stored on the server (PutMesh): the file as read here, and the server's key and
// report of it after its fixes.
struct UploadedSolid {
  Mesh mesh;             // as read (to upload again if the server evicts it)
  MeshReport report;     // the server's, as LoadSolid's
  std::string sha256;    // the server's key: "sha256:<hex>" of the validated mesh
  double seconds = 0.0;  // reading + upload + the server's validation
};

// The remote LoadSolid: reads the file here (kExitBadInput on stderr if it cannot), then
// PutMesh; a refusal (an unusable mesh is FAILED_PRECONDITION) is reported as
// ReportRemoteError does. Prints the same note as LoadSolid when holes were filled.
std::optional<UploadedSolid> UploadSolid(const client::Client& client, const RemoteOptions& remote,
                                         const std::string& path, int* exit_code,
                                         const LoadSolidOptions& options = {});

}  // namespace inscribe::cli
