// A closed solid ready for sphere work, made once: the validated mesh, its report and content
// hash, and the boundary oracle with the inside test the report calls for. Every path that
// generates, evaluates or certifies spheres (CLI, server, robot links, bindings) starts here.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe {

struct Solid {
  MeshReport report;      // of the validated mesh (usable)
  std::string sha256;     // "sha256:<64 hex>" of the validated mesh (FormatSha256(MeshSha256))
  BoundaryOracle oracle;  // over the validated mesh, with InsideTestFor(report)

  const Mesh& mesh() const { return oracle.mesh(); }
};

// The inside test a solid with this report needs: the pseudonormal only when validation checked
// the mesh for self-intersections and found none, and found no non-manifold vertex, no
// zero-area triangle and no flat shell (the conditions under which its sign is proved right); the
// exact winding number otherwise (self-intersections, checks not made, options that skip them). The
// one place this rule lives.
InsideTest InsideTestFor(const MeshReport& report);

struct SolidOptions {
  ValidateOptions validate;
  BoundaryOracleBackend backend = BoundaryOracleBackend::kFlatBvh;
};

// ValidateMesh (orientation fixed, holes filled when asked), then MakeSolid. Errors:
// FAILED_PRECONDITION carrying the report's first error ("mesh is not closed: ...") when the
// mesh is not a usable solid; the oracle's errors. Cost: validation O(#T log #T) plus the
// oracle build O(#T log #T).
absl::StatusOr<Solid> PrepareSolid(Mesh mesh, const SolidOptions& options = {});

// A solid from a mesh that ValidateMesh already produced with `report` (e.g. read back from a
// cache). `sha256` empty = computed here. FAILED_PRECONDITION as PrepareSolid when the report
// says the mesh is unusable.
absl::StatusOr<Solid> MakeSolid(ValidatedMesh validated, std::string sha256 = "",
                                BoundaryOracleBackend backend = BoundaryOracleBackend::kFlatBvh);

}  // namespace inscribe
