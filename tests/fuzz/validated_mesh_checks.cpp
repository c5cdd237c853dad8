#include "validated_mesh_checks.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "inscribe/solid/mesh_validation.h"

namespace inscribe::fuzz {

void Fail(const char* target, const char* what) {
  std::fprintf(stderr, "%s: %s\n", target, what);
  std::abort();
}

bool HasBadCoordinatesOrIndices(const Mesh& mesh) {
  if (!mesh.vertices.allFinite()) return true;
  const std::int64_t vertices = mesh.num_vertices();
  for (std::int64_t t = 0; t < mesh.num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t index = mesh.triangles(t, k);
      if (index < 0 || index >= vertices) return true;
    }
  }
  return false;
}

void CheckValidation(const char* target, Mesh mesh, MeshRepair repair) {
  const bool broken = HasBadCoordinatesOrIndices(mesh);
  ValidateOptions options;
  options.repair.level = repair;
  const ValidatedMesh validated = ValidateMesh(std::move(mesh), options);
  const MeshReport& report = validated.report;
  if (report.wrapped) {
    if (!report.usable() || !report.closed() ||
        report.wrap_triangles != validated.mesh.num_triangles() || !(report.wrap_reach >= 0.0)) {
      Fail(target, "a wrapped mesh is not a usable closed mesh with its own counts");
    }
  } else {
    // As given, less what welding collapsed and the safe fixes removed, plus what hole
    // filling added.
    if (report.triangles - report.weld_collapsed_triangles - report.duplicate_triangles_removed -
            2 * report.double_walls_removed !=
        validated.mesh.num_triangles() - report.hole_triangles_added) {
      Fail(target, "the report's triangle count does not match the returned mesh");
    }
    if (report.vertices - report.welded_vertices - report.crack_vertices_welded !=
        validated.mesh.num_vertices()) {
      Fail(target, "the report's vertex count does not match the returned mesh");
    }
  }
  if (broken && validated.report.usable()) {
    Fail(target, "a mesh with bad coordinates or indices is usable");
  }
  if (!validated.report.usable() && validated.report.first_error().empty()) {
    Fail(target, "an unusable mesh has no error message");
  }
  if (validated.report.usable() &&
      !(std::isfinite(validated.report.volume) && validated.report.volume > 0.0 &&
        validated.report.bbox.extent().allFinite())) {
    Fail(target, "a usable mesh has a non-finite or non-positive volume or extent");
  }
}

}  // namespace inscribe::fuzz
