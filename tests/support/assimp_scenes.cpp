#include "support/assimp_scenes.h"

#include <string>

namespace inscribe::testing {
namespace {

aiMatrix4x4 ToAssimp(const Eigen::Matrix4d& m) {
  aiMatrix4x4 out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out[r][c] = static_cast<ai_real>(m(r, c));
  }
  return out;
}

aiMesh* ToAssimp(const Mesh& mesh) {
  auto* out = new aiMesh();
  out->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  out->mMaterialIndex = 0;
  out->mNumVertices = static_cast<unsigned>(mesh.num_vertices());
  out->mVertices = new aiVector3D[out->mNumVertices];
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
    out->mVertices[v] = aiVector3D(static_cast<ai_real>(mesh.vertices(v, 0)),
                                   static_cast<ai_real>(mesh.vertices(v, 1)),
                                   static_cast<ai_real>(mesh.vertices(v, 2)));
  }
  out->mNumFaces = static_cast<unsigned>(mesh.num_triangles());
  out->mFaces = new aiFace[out->mNumFaces];
  for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
    out->mFaces[t].mNumIndices = 3;
    out->mFaces[t].mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k)
      out->mFaces[t].mIndices[k] = static_cast<unsigned>(mesh.triangles(t, k));
  }
  return out;
}

}  // namespace

std::unique_ptr<aiScene> MakeScene(const std::vector<Mesh>& meshes,
                                   const std::vector<Placement>& placements) {
  auto scene = std::make_unique<aiScene>();
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene->mNumMeshes = static_cast<unsigned>(meshes.size());
  scene->mMeshes = new aiMesh*[meshes.size()];
  for (std::size_t m = 0; m < meshes.size(); ++m) scene->mMeshes[m] = ToAssimp(meshes[m]);
  scene->mRootNode = new aiNode("root");
  std::vector<aiNode*> nodes;
  std::vector<std::vector<aiNode*>> children(placements.size() + 1);  // [0]: the root's
  for (std::size_t i = 0; i < placements.size(); ++i) {
    auto* node = new aiNode("node" + std::to_string(i));
    node->mTransformation = ToAssimp(placements[i].transform);
    node->mNumMeshes = 1;
    node->mMeshes = new unsigned[1]{static_cast<unsigned>(placements[i].mesh)};
    nodes.push_back(node);
    children[static_cast<std::size_t>(placements[i].parent + 1)].push_back(node);
  }
  auto attach = [](aiNode* parent, const std::vector<aiNode*>& kids) {
    if (kids.empty()) return;
    parent->mNumChildren = static_cast<unsigned>(kids.size());
    parent->mChildren = new aiNode*[kids.size()];
    for (std::size_t c = 0; c < kids.size(); ++c) {
      parent->mChildren[c] = kids[c];
      kids[c]->mParent = parent;
    }
  };
  attach(scene->mRootNode, children[0]);
  for (std::size_t i = 0; i < nodes.size(); ++i) attach(nodes[i], children[i + 1]);
  return scene;
}

}  // namespace inscribe::testing
