// Loading a mesh for sphere work. view, which works locally, reads and validates it here
// (LoadSolid); the commands that call the service read it here and store it there
// (StoreSolid), where it is validated.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "absl/status/statusor.h"
#include "inscribe/client/client.h"
#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"

namespace inscribe::cli {

// How the commands that validate a mesh read and repair it: a scale applied to the file's
// coordinates as read (`--scale`, e.g. 0.001 for a mesh in millimetres; the hash and every
// result are then the scaled mesh's), and core's RepairOptions (level, weld tolerance, wrap
// parameters). The hash, the oracle and every result are those of the repaired mesh, and
// stderr says what was done.
struct SolidLoadOptions {
  RepairOptions repair;
  double scale = 1.0;
};

// Registers the repair options on `cmd`, the one definition every command that validates a
// mesh shares: `--repair none|safe|fill|wrap|auto` (default safe), `--fill-holes` (the same as
// `--repair fill`), `--weld-tolerance D` (a finite distance >= 0, mesh units), `--wrap-alpha A`
// and `--wrap-offset O` (mesh units > 0; default from the mesh's size).
void AddRepairOptions(CLI::App* cmd, RepairOptions* repair);
// AddRepairOptions and `--scale S` (finite, > 0).
void AddSolidLoadOptions(CLI::App* cmd, SolidLoadOptions* options);

// The file at `path` read (ReadMesh) and scaled by `scale`: BadInputError naming the file when
// it cannot be read.
absl::StatusOr<Mesh> ReadScaledMesh(const std::string& path, double scale,
                                    ReadMeshInfo* info = nullptr);

struct LoadedSolid {
  Solid solid;
  double seconds = 0.0;  // reading + validation + oracle build
};

// core's PrepareSolid on the file at `path`. BadInputError for an unreadable file,
// UnusableMeshError ("PATH: why") for a mesh that is not a closed solid.
absl::StatusOr<LoadedSolid> LoadSolid(const std::string& path,
                                      const SolidLoadOptions& options = {});

// A mesh stored in the service (PutMesh): the file as read here, and the service's key and
// report of it after its fixes.
struct StoredSolid {
  Mesh mesh;             // as read (to store again if the service evicts it)
  MeshReport report;     // the service's
  std::string sha256;    // the service's key: "sha256:<hex>" of the validated mesh
  double seconds = 0.0;  // reading + storing + the service's validation
};

// Reads the file here (BadInputError if it cannot), then PutMesh; the service's refusal of an
// unusable mesh (FAILED_PRECONDITION) comes back as "PATH: why".
absl::StatusOr<StoredSolid> StoreSolid(const client::Client& client, const std::string& path,
                                       const SolidLoadOptions& options = {});

}  // namespace inscribe::cli
