// What the mesh fuzz targets (fuzz_mesh, fuzz_scene) check of ValidateMesh on a mesh a reader
// returned: the report agrees with the mesh it returns, a mesh with bad coordinates or indices
// is not usable, an unusable one says why, a usable one has a finite positive volume and a
// finite extent (generation sizes its grid from them). A broken promise prints
// "<target>: <what>" and aborts, which the fuzzers report as a finding.
#pragma once

#include "inscribe/geometry/mesh.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::fuzz {

[[noreturn]] void Fail(const char* target, const char* what);

// True when `mesh` has a non-finite coordinate or an index outside [0, #V).
bool HasBadCoordinatesOrIndices(const Mesh& mesh);

// ValidateMesh(mesh) with the given repair level, and the checks above.
void CheckValidation(const char* target, Mesh mesh, MeshRepair repair);

}  // namespace inscribe::fuzz
