// libFuzzer target: the mesh loader. The first byte picks the format (bits 0-1: off, obj, stl,
// ply) and hole filling (bit 2); the rest goes through ParseMesh, the path ReadMesh, the CLI
// and the server take, and a mesh that parses through ValidateMesh as they do. Findings:
// crashes, sanitizer reports, hangs, and broken promises, which abort: a mesh with non-finite
// coordinates or bad indices that validation calls usable, an inconsistent report. Inputs are meant
// to stay small (-max_len 4096): validation costs O(#T log #T), hole filling up to O(n^2) per loop.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"

namespace {

[[noreturn]] void Fail(const char* what) {
  std::fprintf(stderr, "fuzz_mesh: %s\n", what);
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const kFormats[] = {"off", "obj", "stl", "ply"};
  const char* format = kFormats[data[0] & 3];
  const bool fill_holes = (data[0] & 4) != 0;
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);

  inscribe::ReadMeshInfo info;
  absl::StatusOr<inscribe::Mesh> mesh = inscribe::ParseMesh(bytes, format, &info);
  if (!mesh.ok()) {
    if (mesh.status().message().empty()) Fail("a refused mesh has an empty error message");
    return 0;
  }
  // ParseMesh passes non-finite coordinates (binary STL and PLY hold any bit pattern) and
  // indices past int32 (as -1) through; validation must then refuse the mesh.
  bool broken = !mesh->vertices.allFinite();
  const std::int64_t vertices = mesh->num_vertices();
  for (std::int64_t t = 0; t < mesh->num_triangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t index = mesh->triangles(t, k);
      broken = broken || index < 0 || index >= vertices;
    }
  }
  if (info.polygons_triangulated > info.polygons) Fail("more polygons triangulated than read");

  inscribe::ValidateOptions options;
  options.fill_holes = fill_holes;
  const inscribe::ValidatedMesh validated = inscribe::ValidateMesh(*std::move(mesh), options);
  // As given, less what welding collapsed, plus what hole filling added.
  if (validated.report.triangles - validated.report.weld_collapsed_triangles !=
      validated.mesh.num_triangles() - validated.report.hole_triangles_added) {
    Fail("the report's triangle count does not match the returned mesh");
  }
  if (validated.report.vertices - validated.report.welded_vertices !=
      validated.mesh.num_vertices()) {
    Fail("the report's vertex count does not match the returned mesh");
  }
  if (broken && validated.report.usable()) Fail("a mesh with bad coordinates or indices is usable");
  if (!validated.report.usable() && validated.report.first_error().empty()) {
    Fail("an unusable mesh has no error message");
  }
  // Generation sizes its grid from these: a usable mesh must give finite, positive figures.
  if (validated.report.usable() &&
      !(std::isfinite(validated.report.volume) && validated.report.volume > 0.0 &&
        validated.report.bbox.extent().allFinite())) {
    Fail("a usable mesh has a non-finite or non-positive volume or extent");
  }
  return 0;
}
