// Writes the seed corpus of fuzz_scene: COLLADA files from assimp's exporter (and edits of
// them), glTF and binary glTF files built here from their specification's parts (accessors,
// buffer views, primitives of every mode and index type, node trees, sparse accessors), each
// read once with ParseMesh to show what it gives. Run by hand when the import changes:
//   build/tests/fuzz/make_scene_seeds tests/fuzz/corpus/scene
// Each file is one selector byte (fuzz_scene.cpp: the format, and the file path) and the scene.
// The same program writes the same bytes on any machine with the same assimp.
#include <assimp/scene.h>

#include <assimp/Exporter.hpp>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "inscribe/mesh/mesh_io.h"
#include "support/assimp_scenes.h"
#include "support/synthetic_meshes.h"

namespace {

using inscribe::Mesh;
using inscribe::Vector3;
using nlohmann::json;

// fuzz_scene's selector byte: the format's index, plus 4 for the file path.
enum Selector : char { kDae = 0, kGltf = 1, kGlb = 2, kFromFile = 4 };

int written = 0;

void Seed(const std::string& dir, const std::string& name, char selector,
          const std::string& bytes) {
  std::ofstream(dir + "/" + name, std::ios::binary) << selector << bytes;
  static const char* const kFormats[] = {"dae", "gltf", "glb", "gltf"};
  const absl::StatusOr<Mesh> mesh = inscribe::ParseMesh(bytes, kFormats[selector & 3]);
  std::printf("%-32s %6zu bytes  %s\n", name.c_str(), bytes.size() + 1,
              mesh.ok() ? absl::StrCat("OK, ", mesh->num_triangles(), " triangles").c_str()
                        : std::string(mesh.status().message()).c_str());
  ++written;
}

// --- COLLADA, from assimp's exporter ---

std::string Exported(const aiScene& scene, const char* format_id) {
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, format_id);
  if (blob == nullptr) {
    std::fprintf(stderr, "make_scene_seeds: assimp cannot export %s: %s\n", format_id,
                 exporter.GetErrorString());
    std::exit(1);
  }
  return std::string(static_cast<const char*>(blob->data), blob->size);
}

// `text` with the first `from` replaced by `to`; the edit must apply.
std::string Edited(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at == std::string::npos) {
    std::fprintf(stderr, "make_scene_seeds: '%s' is not in the exported file\n", from.c_str());
    std::exit(1);
  }
  return std::string(text).replace(at, from.size(), to);
}

Eigen::Matrix4d Pose(double angle_z, const Vector3& translation, double scale = 1.0) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = scale * Eigen::AngleAxisd(angle_z, Vector3::UnitZ()).toRotationMatrix();
  m.topRightCorner<3, 1>() = translation;
  return m;
}

// The cube's faces as six quads, outward.
void MakeQuads(aiMesh& mesh) {
  static const unsigned kQuads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                        {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  delete[] mesh.mFaces;
  mesh.mPrimitiveTypes = aiPrimitiveType_POLYGON;
  mesh.mNumFaces = 6;
  mesh.mFaces = new aiFace[6];
  for (unsigned f = 0; f < 6; ++f) {
    mesh.mFaces[f].mNumIndices = 4;
    mesh.mFaces[f].mIndices = new unsigned[4];
    std::memcpy(mesh.mFaces[f].mIndices, kQuads[f], sizeof kQuads[f]);
  }
}

void ColladaSeeds(const std::string& dir) {
  const Mesh cube = inscribe::testing::UnitCube();
  const Mesh tetra = inscribe::testing::Tetrahedron(Vector3(0, 0, 0), Vector3(1, 0, 0),
                                                    Vector3(0, 1, 0), Vector3(0, 0, 1));
  const std::unique_ptr<aiScene> one =
      inscribe::testing::MakeScene({cube}, {{0, Eigen::Matrix4d::Identity()}});
  const std::string dae = Exported(*one, "collada");
  Seed(dir, "dae-cube", kDae, dae);
  Seed(dir, "file-dae-cube", kDae | kFromFile, dae);

  // A tetrahedron and a cube placed twice, the second under the tetrahedron's node.
  const std::unique_ptr<aiScene> nested =
      inscribe::testing::MakeScene({cube, tetra}, {{0, Pose(0.0, Vector3(0, 0, 0))},
                                                   {1, Pose(M_PI / 2, Vector3(3, 0, 0), 0.5)},
                                                   {0, Pose(M_PI / 3, Vector3(0, 2, 1)), 1}});
  Seed(dir, "dae-nested-instanced", kDae, Exported(*nested, "collada"));

  Seed(dir, "dae-centimetre-z-up", kDae,
       Edited(Edited(dae, "<up_axis>Y_UP</up_axis>", "<up_axis>Z_UP</up_axis>"), "meter=\"1\"",
              "meter=\"0.01\""));
  Seed(dir, "dae-unit-zero", kDae, Edited(dae, "meter=\"1\"", "meter=\"0\""));
  // The first position made NaN, then one made huge (1e38 * the unit).
  const std::size_t start = dae.find('>', dae.find("<float_array")) + 1;
  const std::string first = dae.substr(start, dae.find(' ', start) - start);
  Seed(dir, "dae-nan", kDae, Edited(dae, ">" + first + " ", ">nan "));
  Seed(dir, "dae-huge-unit", kDae,
       Edited(Edited(dae, ">" + first + " ", ">3e38 "), "meter=\"1\"", "meter=\"1e30\""));
  // A triangle's corner past the positions.
  const std::size_t p = dae.find("<p>");
  Seed(dir, "dae-index-out-of-range", kDae, std::string(dae).replace(p, 4, "<p>4000000 "));
  Seed(dir, "dae-mismatched-tag", kDae, Edited(dae, "<instance_geometry", "<instance_nothing"));
  // A letter in an index list: assimp 5.2 stalls on it, appending zeros until memory runs out.
  Seed(dir, "dae-index-list-letter", kDae, std::string(dae).insert(p + 3, "0 x "));

  const std::unique_ptr<aiScene> quads =
      inscribe::testing::MakeScene({cube}, {{0, Eigen::Matrix4d::Identity()}});
  MakeQuads(*quads->mMeshes[0]);
  const std::string quads_dae = Exported(*quads, "collada");
  Seed(dir, "dae-quads", kDae, quads_dae);
  // Broken: a <polylist> without its <vcount> (assimp 5.2 indexes the empty list: a crash),
  // and one announcing more polygons than the file holds (it reserves 32 GB for them).
  const std::size_t vcount = quads_dae.find("<vcount>");
  Seed(dir, "dae-polylist-without-vcount", kDae,
       std::string(quads_dae).erase(vcount, quads_dae.find("</vcount>") + 9 - vcount));
  Seed(dir, "dae-polylist-count-past-file", kDae,
       Edited(quads_dae, "<polylist count=\"6\"", "<polylist count=\"4000000000\""));
  for (unsigned f = 0; f < 6; ++f) quads->mMeshes[0]->mFaces[f].mNumIndices = 2;
  quads->mMeshes[0]->mPrimitiveTypes = aiPrimitiveType_LINE;
  Seed(dir, "dae-lines", kDae, Exported(*quads, "collada"));

  // A binary glTF from assimp's own exporter, beside the ones built below.
  Seed(dir, "glb-exported-nested", kGlb, Exported(*nested, "glb2"));
}

// --- glTF 2.0, built from its parts ---

constexpr int kFloat = 5126, kUint8 = 5121, kUint16 = 5123, kUint32 = 5125;
constexpr int kModePoints = 0, kModeLines = 1, kModeTriangles = 4, kModeStrip = 5, kModeFan = 6;

class Gltf {
 public:
  Gltf() {
    json_["asset"] = {{"version", "2.0"}, {"generator", "inscribe make_scene_seeds"}};
    json_["scene"] = 0;
    json_["scenes"] = json::array({{{"nodes", json::array()}}});
  }

  // Appends `bytes` to the buffer as a view, 4-byte aligned; returns its index.
  int View(const std::string& bytes, int stride = 0) {
    while (bin_.size() % 4 != 0) bin_ += '\0';
    json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes.size()}};
    if (stride > 0) view["byteStride"] = stride;
    bin_ += bytes;
    return Append("bufferViews", view);
  }
  int Accessor(int view, int component_type, std::size_t count, const char* type,
               std::size_t offset = 0) {
    json accessor = {
        {"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
    if (offset > 0) accessor["byteOffset"] = offset;
    return Append("accessors", accessor);
  }
  // A primitive of `mode` over POSITION accessor `positions` and `indices` (-1: none).
  static json Primitive(int positions, int indices, int mode = kModeTriangles) {
    json primitive = {{"attributes", {{"POSITION", positions}}}, {"mode", mode}};
    if (indices >= 0) primitive["indices"] = indices;
    return primitive;
  }
  int MeshOf(const std::vector<json>& primitives) {
    return Append("meshes", {{"primitives", primitives}});
  }
  // A node holding `mesh` (-1: none); a root of the scene when `parent` is -1.
  int Node(int mesh, json transform = json::object(), int parent = -1) {
    json node = std::move(transform);
    if (mesh >= 0) node["mesh"] = mesh;
    const int index = Append("nodes", node);
    if (parent < 0) {
      json_["scenes"][0]["nodes"].push_back(index);
    } else {
      json_["nodes"][parent]["children"].push_back(index);
    }
    return index;
  }
  json& Json() { return json_; }

  // Positions as float VEC3 and triangle corners as `index_type`: the accessors' indices.
  std::pair<int, int> Add(const Mesh& mesh, int index_type) {
    std::string positions;
    for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v) {
      for (int k = 0; k < 3; ++k) Put(positions, static_cast<float>(mesh.vertices(v, k)));
    }
    const int p = Accessor(View(positions), kFloat, mesh.num_vertices(), "VEC3");
    std::string corners;
    for (Eigen::Index t = 0; t < mesh.num_triangles(); ++t) {
      for (int k = 0; k < 3; ++k) PutIndex(corners, index_type, mesh.triangles(t, k));
    }
    const int i = Accessor(View(corners), index_type, 3 * mesh.num_triangles(), "SCALAR");
    return {p, i};
  }

  // The .gltf text with the buffer embedded as a data: URI (or named `uri` when given).
  std::string Text(const std::string& uri = "") const {
    json out = json_;
    out["buffers"] = json::array(
        {{{"byteLength", bin_.size()},
          {"uri", uri.empty() ? "data:application/octet-stream;base64," + absl::Base64Escape(bin_)
                              : uri}}});
    return out.dump(1);
  }
  // The .glb: header, JSON chunk (padded with spaces), BIN chunk (padded with zeros).
  std::string Binary() const {
    json out = json_;
    out["buffers"] = json::array({{{"byteLength", bin_.size()}}});
    std::string text = out.dump();
    while (text.size() % 4 != 0) text += ' ';
    std::string bin = bin_;
    while (bin.size() % 4 != 0) bin += '\0';
    std::string glb = "glTF";
    Put(glb, std::uint32_t{2});
    Put(glb, static_cast<std::uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
    Put(glb, static_cast<std::uint32_t>(text.size()));
    glb += "JSON" + text;
    Put(glb, static_cast<std::uint32_t>(bin.size()));
    glb += std::string("BIN\0", 4) + bin;
    return glb;
  }

  template <typename T>
  static void Put(std::string& out, T value) {
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  static void PutIndex(std::string& out, int type, std::int64_t index) {
    if (type == kUint8) Put(out, static_cast<std::uint8_t>(index));
    if (type == kUint16) Put(out, static_cast<std::uint16_t>(index));
    if (type == kUint32) Put(out, static_cast<std::uint32_t>(index));
  }

 private:
  int Append(const char* array, json value) {
    json_[array].push_back(std::move(value));
    return static_cast<int>(json_[array].size()) - 1;
  }

  json json_;
  std::string bin_;
};

json Matrix(const Eigen::Matrix4d& m) {
  json out = json::array();
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) out.push_back(m(r, c));  // column-major
  }
  return {{"matrix", out}};
}

// Both forms of every glTF seed: text with an embedded buffer, and binary.
void Both(const std::string& dir, const std::string& name, const Gltf& gltf) {
  Seed(dir, "gltf-" + name, kGltf, gltf.Text());
  Seed(dir, "glb-" + name, kGlb, gltf.Binary());
}

void GltfSeeds(const std::string& dir) {
  const Mesh cube = inscribe::testing::UnitCube();
  const Mesh octahedron = inscribe::testing::Octahedron(Vector3(0, 0, 0), 1.0);

  {  // A cube with 32-bit indices under a matrix.
    Gltf g;
    const auto [p, i] = g.Add(cube, kUint32);
    g.Node(g.MeshOf({Gltf::Primitive(p, i)}), Matrix(Pose(0.5, Vector3(1, 2, 3))));
    Both(dir, "cube", g);
    Seed(dir, "file-gltf-cube", kGltf | kFromFile, g.Text());
    Seed(dir, "gltf-external-buffer", kGltf, g.Text("cube.bin"));
    Seed(dir, "file-gltf-external-buffer", kGltf | kFromFile, g.Text("cube.bin"));
  }
  {  // An octahedron with 16-bit indices placed by translation, rotation and scale, under a
     // node placing a cube with 8-bit indices; the octahedron instanced again at the root.
    Gltf g;
    const auto [cp, ci] = g.Add(cube, kUint8);
    const auto [op, oi] = g.Add(octahedron, kUint16);
    const int cube_mesh = g.MeshOf({Gltf::Primitive(cp, ci)});
    const int octahedron_mesh = g.MeshOf({Gltf::Primitive(op, oi)});
    const int root = g.Node(cube_mesh, {{"translation", {2, 0, 0}}});
    g.Node(octahedron_mesh,
           {{"translation", {0, 3, 0}},
            {"rotation", {0, 0, 0.38268343, 0.92387953}},
            {"scale", {0.5, 0.5, 0.5}}},
           root);
    g.Node(octahedron_mesh, {{"translation", {-3, 0, 0}}});
    Both(dir, "nested-instanced", g);
  }
  {  // Two primitives in one mesh, one of them without indices (corners in order).
    Gltf g;
    const auto [p, i] = g.Add(cube, kUint16);
    std::string corners;
    for (Eigen::Index t = 0; t < octahedron.num_triangles(); ++t) {
      for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < 3; ++c) {
          Gltf::Put(corners,
                    static_cast<float>(octahedron.vertices(octahedron.triangles(t, k), c)));
        }
      }
    }
    const int soup = g.Accessor(g.View(corners), kFloat, 3 * octahedron.num_triangles(), "VEC3");
    g.Node(g.MeshOf({Gltf::Primitive(p, i), Gltf::Primitive(soup, -1)}));
    Both(dir, "two-primitives-unindexed", g);
  }
  {  // Positions interleaved with normals (byteStride 24), the accessor at an offset.
    Gltf g;
    std::string interleaved;
    for (Eigen::Index v = 0; v < cube.num_vertices(); ++v) {
      for (int k = 0; k < 3; ++k) Gltf::Put(interleaved, static_cast<float>(cube.vertices(v, k)));
      for (int k = 0; k < 3; ++k) Gltf::Put(interleaved, 0.0f);
    }
    const int view = g.View(interleaved, 24);
    const int p = g.Accessor(view, kFloat, cube.num_vertices(), "VEC3");
    const int n = g.Accessor(view, kFloat, cube.num_vertices(), "VEC3", 12);
    std::string corners;
    for (Eigen::Index t = 0; t < cube.num_triangles(); ++t) {
      for (int k = 0; k < 3; ++k) Gltf::PutIndex(corners, kUint16, cube.triangles(t, k));
    }
    const int i = g.Accessor(g.View(corners), kUint16, 3 * cube.num_triangles(), "SCALAR");
    json primitive = Gltf::Primitive(p, i);
    primitive["attributes"]["NORMAL"] = n;
    g.Node(g.MeshOf({primitive}));
    Both(dir, "byte-stride", g);
  }
  {  // Strips, fans, lines and points over the same positions.
    Gltf g;
    const auto [p, i] = g.Add(cube, kUint16);
    std::string strip, fan;
    for (int v : {0, 1, 2, 3, 6, 7, 4, 5}) Gltf::PutIndex(strip, kUint8, v);
    for (int v : {0, 1, 3, 2, 6, 4}) Gltf::PutIndex(fan, kUint32, v);
    const int s = g.Accessor(g.View(strip), kUint8, 8, "SCALAR");
    const int f = g.Accessor(g.View(fan), kUint32, 6, "SCALAR");
    g.Node(g.MeshOf({Gltf::Primitive(p, s, kModeStrip)}));
    g.Node(g.MeshOf({Gltf::Primitive(p, f, kModeFan)}), {{"translation", {0, 0, 2}}});
    Both(dir, "strip-fan", g);
    // Broken: a strip of one index and a fan of two (assimp 5.2 allocates count - 2 faces,
    // 2^64 - 1 bytes for the strip), and a fan with an index past the positions (read: the
    // triangles reaching past are dropped).
    g.Json()["accessors"][s]["count"] = 1;
    g.Json()["accessors"][f]["count"] = 2;
    Both(dir, "strip-fan-too-few-indices", g);
    Gltf past;
    const int pp = past.Add(cube, kUint16).first;  // the cube's own indices unused
    std::string past_fan;
    for (int v : {0, 1, 3, 9, 2, 6}) Gltf::PutIndex(past_fan, kUint16, v);
    const int pf = past.Accessor(past.View(past_fan), kUint16, 6, "SCALAR");
    past.Node(past.MeshOf({Gltf::Primitive(pp, pf, kModeFan)}));
    Both(dir, "fan-index-past-positions", past);
    Gltf lines;
    const auto [lp, li] = lines.Add(cube, kUint16);
    lines.Node(lines.MeshOf({Gltf::Primitive(lp, li, kModeLines)}));
    lines.Node(lines.MeshOf({Gltf::Primitive(lp, -1, kModePoints)}));
    Both(dir, "lines-points", lines);
  }
  {  // A sparse accessor moving two of the cube's corners.
    Gltf g;
    const auto [p, i] = g.Add(cube, kUint32);
    std::string moved_indices, moved_values;
    for (std::uint16_t v : {0, 7}) Gltf::Put(moved_indices, v);
    for (float x : {-0.5f, -0.5f, -0.5f, 1.5f, 1.5f, 1.5f}) Gltf::Put(moved_values, x);
    const int iv = g.View(moved_indices);
    const int vv = g.View(moved_values);
    g.Json()["accessors"][p]["sparse"] = {
        {"count", 2},
        {"indices", {{"bufferView", iv}, {"componentType", kUint16}}},
        {"values", {{"bufferView", vv}}}};
    g.Node(g.MeshOf({Gltf::Primitive(p, i)}));
    Both(dir, "sparse", g);
    // Broken: the indices without their view (assimp 5.2 reads through a null pointer), and
    // more moved corners than the views hold.
    json& sparse = g.Json()["accessors"][p]["sparse"];
    sparse["indices"].erase("bufferView");
    Both(dir, "sparse-indices-without-view", g);
    sparse["indices"]["bufferView"] = iv;
    sparse["count"] = 3;
    Both(dir, "sparse-count-past-views", g);
  }
  {  // Broken: an index past the positions, an accessor past its view, a NaN position.
    Gltf g;
    Mesh bad = cube;
    bad.triangles(5, 1) = 9;
    const auto [p, i] = g.Add(bad, kUint16);
    g.Node(g.MeshOf({Gltf::Primitive(p, i)}));
    Both(dir, "index-out-of-range", g);
    g.Json()["accessors"][p]["count"] = 9;
    Both(dir, "accessor-past-view", g);
    Gltf n;
    Mesh nan = cube;
    nan.vertices(3, 1) = std::numeric_limits<double>::quiet_NaN();
    const auto [np, ni] = n.Add(nan, kUint16);
    n.Node(n.MeshOf({Gltf::Primitive(np, ni)}));
    Both(dir, "nan", n);
    // Not base64: assimp 5.2 leaked its decoding buffer on a byte above 0x7f.
    Seed(dir, "gltf-data-uri-not-base64", kGltf, Edited(n.Text(), ";base64,", ";base64,\xc3\xa9"));
  }
  {  // Empty: a scene of nodes without meshes.
    Gltf g;
    g.Node(-1, {{"name", "empty"}});
    Both(dir, "no-meshes", g);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_scene_seeds DIR\n");
    return 64;
  }
  const std::string dir = argv[1];
  ColladaSeeds(dir);
  GltfSeeds(dir);
  std::printf("%d seeds in %s\n", written, dir.c_str());
  return 0;
}
