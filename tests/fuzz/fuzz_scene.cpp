// libFuzzer target: scene files through assimp (core/src/mesh/assimp_import.cpp). The first byte
// picks the format (its value mod 4: dae, gltf, glb, and gltf again), whether the rest goes
// through ParseMesh or is written to a file that ReadMesh reads (bit 2: the file path of the
// CLI and the URDF spherizer, where a .gltf may name sibling buffer files, of which there are
// none) and hole filling in the validation that follows (bit 3). Findings: crashes, sanitizer
// reports, hangs, and broken promises of mesh_io.h, which abort: a refusal that is not
// INVALID_ARGUMENT or NOT_FOUND naming the source, and a returned mesh without triangles, with
// a non-finite coordinate, an index out of range or more polygons triangulated than read; then
// validation's promises (validated_mesh_checks.h). assimp itself is Debian's, built without
// coverage: only the branches of inscribe's code guide the fuzzer, so the seeds and the
// dictionary (scene.dict) carry the formats' structure.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "absl/strings/match.h"
#include "inscribe/mesh/mesh_io.h"
#include "validated_mesh_checks.h"

namespace {

constexpr const char* kTarget = "fuzz_scene";

// This process's own directory for the file ReadMesh reads, removed at exit.
const std::filesystem::path& ScratchDirectory() {
  static const std::filesystem::path dir = [] {
    std::filesystem::path d = std::filesystem::temp_directory_path() /
                              ("inscribe_fuzz_scene_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(ScratchDirectory(), ignored);
    });
    return d;
  }();
  return dir;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using inscribe::fuzz::Fail;
  if (size < 1) return 0;
  static const char* const kFormats[] = {"dae", "gltf", "glb", "gltf"};
  const std::string format = kFormats[data[0] & 3];
  const bool from_file = (data[0] & 4) != 0;
  const inscribe::MeshRepair repair =
      (data[0] & 8) != 0 ? inscribe::MeshRepair::kFill : inscribe::MeshRepair::kSafe;
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);

  inscribe::ReadMeshInfo info;
  absl::StatusOr<inscribe::Mesh> mesh;
  std::string source = format + " data";
  if (from_file) {
    source = (ScratchDirectory() / ("scene." + format)).string();
    std::ofstream(source, std::ios::binary | std::ios::trunc) << bytes;
    mesh = inscribe::ReadMesh(source, &info);
  } else {
    mesh = inscribe::ParseMesh(bytes, format, &info);
  }
  if (!mesh.ok()) {
    const absl::StatusCode code = mesh.status().code();
    if (code != absl::StatusCode::kInvalidArgument && code != absl::StatusCode::kNotFound) {
      Fail(kTarget, "a refusal is neither INVALID_ARGUMENT nor NOT_FOUND");
    }
    if (!absl::StrContains(mesh.status().message(), source)) {
      Fail(kTarget, "a refusal does not name its source");
    }
    return 0;
  }
  if (mesh->num_triangles() == 0) Fail(kTarget, "a scene read without triangles");
  if (inscribe::fuzz::HasBadCoordinatesOrIndices(*mesh)) {
    Fail(kTarget, "a scene read with a non-finite coordinate or an index out of range");
  }
  if (info.polygons_triangulated > info.polygons) {
    Fail(kTarget, "more polygons triangulated than read");
  }
  inscribe::fuzz::CheckValidation(kTarget, *std::move(mesh), repair);
  return 0;
}
