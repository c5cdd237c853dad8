#include "mesh/assimp_import.h"

#include <assimp/BaseImporter.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "mesh/assimp_guards.h"

namespace inscribe::internal {
namespace {

using Transform = Eigen::Matrix4d;

Transform ToEigen(const aiMatrix4x4& m) {
  Transform t;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) t(r, c) = static_cast<double>(m[r][c]);
  }
  return t;
}

void ConfigureImporter(Assimp::Importer& importer, const std::string& format) {
  // The file's own axes: assimp would otherwise rotate a Z_UP COLLADA scene to Y up through
  // the root's transform. The <unit> scale stays on the root's transform, where it is applied.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // Only the readers of `format` (COLLADA's; glTF 1 and 2 for .gltf and .glb): when they cannot
  // read the bytes, assimp 5.2 would try each of its other 60-odd readers on them, none of
  // which the checks of assimp_guards.cpp know (fuzz_scene: a .glb beginning "quick3ds" went to
  // the Quick3D reader, which asked for 1.5 TB). UnregisterLoader hands the reader back.
  for (std::size_t i = importer.GetImporterCount(); i-- > 0;) {
    Assimp::BaseImporter* reader = importer.GetImporter(i);
    std::set<std::string> extensions;
    reader->GetExtensionList(extensions);
    if (extensions.count(format) == 0 && importer.UnregisterLoader(reader) == AI_SUCCESS) {
      delete reader;
    }
  }
}

// Counts the polygons as stored, then triangulates them (aiProcess_Triangulate). No other
// post-processing: welding coincident vertices is validation's, and reported there.
const aiScene* Triangulated(Assimp::Importer& importer, const aiScene* scene, ReadMeshInfo* info) {
  if (scene == nullptr) return nullptr;
  std::int64_t polygons = 0, triangulated = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      if (mesh->mFaces[f].mNumIndices >= 3) ++polygons;
      if (mesh->mFaces[f].mNumIndices > 3) ++triangulated;
    }
  }
  if (info != nullptr) {
    info->polygons = polygons;
    info->polygons_triangulated = triangulated;
  }
  return importer.ApplyPostProcessing(aiProcess_Triangulate);
}

absl::StatusOr<Mesh> SceneToMesh(const aiScene& scene, const std::string& what,
                                 const std::string& format) {
  if (scene.mRootNode == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": the ", SceneFormatName(format), " file has no scene graph"));
  }
  std::vector<Vector3> vertices;
  std::vector<std::array<std::int64_t, 3>> triangles;
  // Depth-first over the nodes with an explicit stack (a file may nest deeply).
  std::vector<std::pair<const aiNode*, Transform>> stack = {
      {scene.mRootNode, ToEigen(scene.mRootNode->mTransformation)}};
  while (!stack.empty()) {
    const auto [node, to_scene] = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      if (node->mMeshes[i] >= scene.mNumMeshes) continue;
      const aiMesh& mesh = *scene.mMeshes[node->mMeshes[i]];
      const auto first = static_cast<std::int64_t>(vertices.size());
      bool used = false;
      for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines bound nothing
        std::array<std::int64_t, 3> t;
        for (int k = 0; k < 3; ++k) t[k] = first + face.mIndices[k];
        triangles.push_back(t);
        used = true;
      }
      if (!used) continue;
      for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
        const aiVector3D& p = mesh.mVertices[v];
        const Eigen::Vector4d q = to_scene * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
        vertices.push_back(q.head<3>() / q.w());
        if (!vertices.back().allFinite()) {
          return absl::InvalidArgumentError(
              absl::StrCat(what, ": a non-finite coordinate (vertex ", v, " of mesh '",
                           mesh.mName.C_Str(), "' under node '", node->mName.C_Str(), "')"));
        }
      }
      if (vertices.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, ": more vertices than inscribe supports"));
      }
    }
    // Reversed onto the stack, so that children are visited (and appended) in file order.
    for (unsigned c = node->mNumChildren; c-- > 0;) {
      stack.emplace_back(node->mChildren[c],
                         to_scene * ToEigen(node->mChildren[c]->mTransformation));
    }
  }
  if (triangles.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": no triangles in the ", SceneFormatName(format), " file (",
        scene.mNumMeshes == 0 ? "it has no meshes" : "its meshes hold only points or lines", ")"));
  }
  if (triangles.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": more triangles than inscribe supports"));
  }
  Mesh out;
  out.vertices.resize(static_cast<Eigen::Index>(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v) {
    out.vertices.row(static_cast<Eigen::Index>(v)) = vertices[v].transpose();
  }
  out.triangles.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      // assimp checks indices against its mesh; one beyond it stays out of range (-1).
      const std::int64_t v = triangles[t][k];
      out.triangles(static_cast<Eigen::Index>(t), k) =
          v < static_cast<std::int64_t>(vertices.size()) ? static_cast<std::int32_t>(v) : -1;
    }
  }
  return out;
}

absl::Status ImportError(const std::string& what, const std::string& format,
                         const char* assimp_message) {
  return absl::InvalidArgumentError(absl::StrCat(what, ": not a readable ", SceneFormatName(format),
                                                 " file (assimp: ", assimp_message, ")"));
}

// A .gltf names its buffers by URI; from bytes, only embedded ("data:") ones can be had.
std::string ExternalBufferOf(const nlohmann::json& gltf) {
  if (!gltf.is_object() || !gltf.contains("buffers") || !gltf["buffers"].is_array()) return "";
  for (const nlohmann::json& buffer : gltf["buffers"]) {
    if (buffer.is_object() && buffer.contains("uri") && buffer["uri"].is_string()) {
      const std::string uri = buffer["uri"].get<std::string>();
      if (!absl::StartsWith(uri, "data:")) return uri;
    }
  }
  return "";
}

}  // namespace

bool IsSceneFormat(const std::string& format) {
  return format == "dae" || format == "gltf" || format == "glb";
}

absl::StatusOr<Mesh> ImportSceneFile(const std::string& path, ReadMeshInfo* info) {
  std::string format = std::filesystem::path(path).extension().string();
  if (!format.empty()) format.erase(0, 1);
  for (char& c : format) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream read;
    read << in.rdbuf();
    const std::string bytes = read.str();
    // An unreadable or empty file is assimp's to report, as before.
    if (in && !bytes.empty()) {
      if (absl::Status checked = CheckSceneBeforeAssimp(bytes, format, path); !checked.ok()) {
        return checked;
      }
    }
  }
  Assimp::Importer importer;
  ConfigureImporter(importer, format);
  const aiScene* scene = Triangulated(importer, importer.ReadFile(path, 0), info);
  if (scene == nullptr) return ImportError(path, format, importer.GetErrorString());
  return SceneToMesh(*scene, path, format);
}

absl::StatusOr<Mesh> ImportSceneBytes(const std::string& bytes, const std::string& format,
                                      const std::string& what, ReadMeshInfo* info) {
  if (bytes.empty()) return absl::InvalidArgumentError(absl::StrCat(what, ": file is empty"));
  if (absl::Status checked = CheckSceneBeforeAssimp(bytes, format, what); !checked.ok()) {
    return checked;
  }
  if (format == "gltf") {
    const std::string uri = ExternalBufferOf(nlohmann::json::parse(bytes));  // parsed above
    if (!uri.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(
          what, ": the glTF's buffer '", uri,
          "' is a separate file, which cannot be read from bytes; send a .glb or a .gltf with "
          "embedded (data:) buffers"));
    }
  }
  Assimp::Importer importer;
  ConfigureImporter(importer, format);
  const aiScene* scene = Triangulated(
      importer, importer.ReadFileFromMemory(bytes.data(), bytes.size(), 0, format.c_str()), info);
  if (scene == nullptr) return ImportError(what, format, importer.GetErrorString());
  return SceneToMesh(*scene, what, format);
}

}  // namespace inscribe::internal
