// libFuzzer target: the mesh loader. The first byte picks the format (bits 0-1: off, obj, stl,
// ply) and the repair level (bits 2-3: safe, fill, none, auto); the rest goes through ParseMesh,
// the path ReadMesh, the CLI and the server take, and a mesh that parses through ValidateMesh as
// they do. Findings: crashes, sanitizer reports, hangs, and broken promises, which abort: a refusal
// without a message, and validation's promises (validated_mesh_checks.h). ParseMesh passes
// non-finite coordinates (binary STL and PLY hold any bit pattern) and indices past int32 (as -1)
// through; validation must then refuse the mesh. Inputs are meant to stay small (-max_len 4096):
// validation costs O(#T log #T), hole filling up to O(n^2) per loop, the wrap grows with the
// mesh's area over alpha^2 (alpha from its size: bounded).
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

#include "inscribe/mesh/mesh_io.h"
#include "validated_mesh_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using inscribe::fuzz::Fail;
  constexpr const char* kTarget = "fuzz_mesh";
  if (size < 1) return 0;
  static const char* const kFormats[] = {"off", "obj", "stl", "ply"};
  const char* format = kFormats[data[0] & 3];
  static const inscribe::MeshRepair kRepairs[] = {
      inscribe::MeshRepair::kSafe, inscribe::MeshRepair::kFill, inscribe::MeshRepair::kNone,
      inscribe::MeshRepair::kAuto};
  const inscribe::MeshRepair repair = kRepairs[(data[0] >> 2) & 3];
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);

  inscribe::ReadMeshInfo info;
  absl::StatusOr<inscribe::Mesh> mesh = inscribe::ParseMesh(bytes, format, &info);
  if (!mesh.ok()) {
    if (mesh.status().message().empty()) Fail(kTarget, "a refused mesh has an empty error message");
    return 0;
  }
  if (info.polygons_triangulated > info.polygons) {
    Fail(kTarget, "more polygons triangulated than read");
  }
  inscribe::fuzz::CheckValidation(kTarget, *std::move(mesh), repair);
  return 0;
}
