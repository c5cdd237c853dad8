// Loading a mesh for sphere work: read, validate (fix orientation), hash, build the oracle.
// Shared by the subcommands that need a usable solid (generate, evaluate).
#pragma once

#include <optional>
#include <string>

#include "inscribe/boundary_oracle.h"
#include "inscribe/mesh_validation.h"

namespace inscribe::cli {

struct LoadedSolid {
  MeshReport report;
  std::string sha256;  // "sha256:<hex>" of the validated mesh
  BoundaryOracle oracle;
  double seconds = 0.0;  // reading + validation + oracle build
};

struct LoadSolidOptions {
  // Close the mesh's holes before use (ValidateOptions::fill_holes, `--fill-holes`); the hash
  // and the oracle are then those of the repaired mesh, and one line on stderr says so.
  bool fill_holes = false;
};

// Prints the reason on stderr and sets *exit_code (kExitBadInput for unreadable files,
// kExitUnusableMesh for meshes that are not closed solids) when it returns nothing. Meshes
// whose report shows self-intersections get the ray-parity inside test (see InsideTest).
std::optional<LoadedSolid> LoadSolid(const std::string& path, int* exit_code,
                                     const LoadSolidOptions& options = {});

}  // namespace inscribe::cli
