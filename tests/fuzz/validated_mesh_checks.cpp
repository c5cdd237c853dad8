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

void CheckValidation(const char* target, Mesh mesh, bool fill_holes) {
  const bool broken = HasBadCoordinatesOrIndices(mesh);
  ValidateOptions options;
  options.fill_holes = fill_holes;
  const ValidatedMesh validated = ValidateMesh(std::move(mesh), options);
  // As given, less what welding collapsed, plus what hole filling added.
  if (validated.report.triangles - validated.report.weld_collapsed_triangles !=
      validated.mesh.num_triangles() - validated.report.hole_triangles_added) {
    Fail(target, "the report's triangle count does not match the returned mesh");
  }
  if (validated.report.vertices - validated.report.welded_vertices !=
      validated.mesh.num_vertices()) {
    Fail(target, "the report's vertex count does not match the returned mesh");
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
