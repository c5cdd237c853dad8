#include "support/test_meshes.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "inscribe/mesh/mesh_io.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::testing {

std::string TestMeshPath(const std::string& name) {
  const char* env = std::getenv("INSCRIBE_DATA_DIR");
  const std::filesystem::path dir = env != nullptr && *env != '\0'
                                        ? std::filesystem::path(env)
                                        : std::filesystem::path(INSCRIBE_SOURCE_DIR) / "data";
  const std::filesystem::path path = dir / name;
  return std::filesystem::exists(path) ? path.string() : std::string();
}

Mesh LoadTestMesh(const std::string& name) {
  const std::string path = TestMeshPath(name);
  EXPECT_FALSE(path.empty()) << name << " missing";
  absl::StatusOr<Mesh> mesh = ReadMesh(path);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  if (!mesh.ok()) return Mesh{};
  absl::StatusOr<ValidatedMesh> prepared = PrepareMesh(*std::move(mesh));
  EXPECT_TRUE(prepared.ok()) << prepared.status();
  if (!prepared.ok()) return Mesh{};
  return std::move(prepared->mesh);
}

}  // namespace inscribe::testing
