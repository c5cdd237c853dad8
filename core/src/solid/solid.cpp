#include "inscribe/solid/solid.h"

#include <utility>

#include "inscribe/geometry/mesh_hash.h"

namespace inscribe {

InsideTest InsideTestFor(const MeshReport& report) {
  const bool pseudonormal_proved = report.self_intersections_checked &&
                                   report.self_intersecting_pairs == 0 &&
                                   report.non_manifold_vertices == 0 &&
                                   report.degenerate_triangles == 0 && report.flat_shells == 0;
  return pseudonormal_proved ? InsideTest::kPseudonormal : InsideTest::kExactWinding;
}

absl::StatusOr<Solid> MakeSolid(ValidatedMesh validated, std::string sha256,
                                BoundaryOracleBackend backend) {
  if (!validated.report.usable()) {
    return absl::FailedPreconditionError(validated.report.first_error());
  }
  if (sha256.empty()) sha256 = FormatSha256(MeshSha256(validated.mesh));
  BoundaryOracleOptions options;
  options.inside_test = InsideTestFor(validated.report);
  options.backend = backend;
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(validated.mesh, options);
  if (!oracle.ok()) return oracle.status();
  return Solid{std::move(validated.report), std::move(sha256), *std::move(oracle)};
}

absl::StatusOr<Solid> PrepareSolid(Mesh mesh, const SolidOptions& options) {
  return MakeSolid(ValidateMesh(std::move(mesh), options.validate), "", options.backend);
}

}  // namespace inscribe
