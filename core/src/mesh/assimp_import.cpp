#include "mesh/assimp_import.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

namespace inscribe::internal {
namespace {

using Transform = Eigen::Matrix4d;

const char* FormatName(const std::string& format) {
  return format == "dae" ? "COLLADA" : format == "glb" ? "binary glTF" : "glTF";
}

Transform ToEigen(const aiMatrix4x4& m) {
  Transform t;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) t(r, c) = static_cast<double>(m[r][c]);
  }
  return t;
}

void ConfigureImporter(Assimp::Importer& importer) {
  // The file's own axes: assimp would otherwise rotate a Z_UP COLLADA scene to Y up through
  // the root's transform. The <unit> scale stays on the root's transform, where it is applied.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
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
        absl::StrCat(what, ": the ", FormatName(format), " file has no scene graph"));
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
        what, ": no triangles in the ", FormatName(format), " file (",
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

// assimp 5.2 reads a COLLADA index list (a <p> element) number by number, and a character
// that is neither a digit, a sign nor white space stops its reader without moving it on: it
// appends zeros until memory runs out (a 2.5 KB file took 11 GB in 30 s). Such a list is
// refused here, before assimp sees the file. The check reads the bytes, so it is stricter than
// XML: anything but digits, signs and white space between <p> and </p> (an entity, a comment,
// CDATA, an element) is refused, wherever the <p> is; and so is a NUL byte, since pugixml,
// assimp's XML reader, would decode UTF-16 or UTF-32 into text this check does not see.
// Cost: one pass over the bytes.
absl::Status CheckColladaIndexLists(const std::string& bytes, const std::string& what) {
  if (const std::size_t nul = bytes.find('\0'); nul != std::string::npos) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": not a readable COLLADA file (a NUL byte at offset ", nul,
                     "; inscribe gives assimp COLLADA as UTF-8 text only)"));
  }
  auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  for (std::size_t tag = bytes.find("<p"); tag != std::string::npos;
       tag = bytes.find("<p", tag + 2)) {
    const std::size_t name_end = tag + 2;
    if (name_end >= bytes.size()) break;
    const char after = bytes[name_end];
    if (after != '>' && after != '/' && !is_space(after)) continue;  // <polylist>, <param>...
    const std::size_t open_end = bytes.find('>', name_end);
    if (open_end == std::string::npos) break;  // assimp's XML reader refuses the file
    if (bytes[open_end - 1] == '/') continue;  // <p/>: an empty list
    std::size_t i = open_end + 1;
    while (i < bytes.size() && bytes[i] != '<' &&
           (std::isdigit(static_cast<unsigned char>(bytes[i])) || bytes[i] == '-' ||
            bytes[i] == '+' || is_space(bytes[i]))) {
      ++i;
    }
    const bool closed = bytes.compare(i, 3, "</p") == 0 && i + 3 < bytes.size() &&
                        (bytes[i + 3] == '>' || is_space(bytes[i + 3]));
    if (i < bytes.size() && !closed) {
      std::int64_t line = 1 + std::count(bytes.begin(), bytes.begin() + i, '\n');
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": line ", line,
                       ": a COLLADA index list (<p>) holds something other than whole numbers"));
    }
    tag = i;
  }
  return absl::OkStatus();
}

// The value of attribute `name` in the start tag `tag` (the text between < and >), if it is
// there as name="value" or name='value' after white space.
std::optional<absl::string_view> AttributeOf(absl::string_view tag, absl::string_view name) {
  for (std::size_t at = tag.find(name); at != absl::string_view::npos;
       at = tag.find(name, at + 1)) {
    const std::size_t eq = at + name.size();
    if (at == 0 || !std::isspace(static_cast<unsigned char>(tag[at - 1])) || eq + 1 >= tag.size() ||
        tag[eq] != '=' || (tag[eq + 1] != '"' && tag[eq + 1] != '\'')) {
      continue;
    }
    const std::size_t end = tag.find(tag[eq + 1], eq + 2);
    if (end == absl::string_view::npos) return std::nullopt;
    return tag.substr(eq + 2, end - eq - 2);
  }
  return std::nullopt;
}

// assimp 5.2 reads an accessor's values from its source array without checking that the array
// holds them: a <float_array> whose count is missing (or smaller than its accessor's reach)
// is read past its end. Every <accessor> must name (source="#id") an array of this file whose
// count, a plain number, covers offset + count * stride values; and every array's count must
// be a plain number.
absl::Status CheckColladaAccessors(const std::string& bytes, const std::string& what) {
  auto number = [](std::optional<absl::string_view> text,
                   std::uint64_t fallback) -> std::optional<std::uint64_t> {
    if (!text.has_value()) return fallback;
    std::uint64_t n = 0;
    if (!absl::SimpleAtoi(*text, &n)) return std::nullopt;
    return n;
  };
  auto tags = [&](const std::string& name, auto&& visit) -> absl::Status {
    for (std::size_t at = bytes.find(name); at != std::string::npos;
         at = bytes.find(name, at + 1)) {
      const std::size_t after = at + name.size();
      if (at == 0 || bytes[at - 1] != '<' || after >= bytes.size() ||
          !(std::isspace(static_cast<unsigned char>(bytes[after])) || bytes[after] == '>' ||
            bytes[after] == '/')) {
        continue;
      }
      const std::size_t end = bytes.find('>', after);
      if (end == std::string::npos) break;  // assimp's XML reader refuses the file
      if (absl::Status s = visit(absl::string_view(bytes).substr(after, end - after)); !s.ok()) {
        return s;
      }
    }
    return absl::OkStatus();
  };
  std::map<std::string, std::uint64_t, std::less<>> arrays;  // id -> count
  for (const char* array :
       {"float_array", "int_array", "bool_array", "Name_array", "IDREF_array"}) {
    absl::Status s = tags(array, [&](absl::string_view tag) -> absl::Status {
      const std::optional<std::uint64_t> count = number(AttributeOf(tag, "count"), UINT64_MAX);
      if (!count.has_value() || *count == UINT64_MAX) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, ": a COLLADA <", array, "> without a count that is a whole number"));
      }
      if (std::optional<absl::string_view> id = AttributeOf(tag, "id")) {
        arrays[std::string(*id)] = *count;
      }
      return absl::OkStatus();
    });
    if (!s.ok()) return s;
  }
  return tags("accessor", [&](absl::string_view tag) -> absl::Status {
    const std::optional<absl::string_view> source = AttributeOf(tag, "source");
    const std::optional<std::uint64_t> count = number(AttributeOf(tag, "count"), 0);
    const std::optional<std::uint64_t> offset = number(AttributeOf(tag, "offset"), 0);
    const std::optional<std::uint64_t> stride = number(AttributeOf(tag, "stride"), 1);
    const auto array = source.has_value() && absl::StartsWith(*source, "#")
                           ? arrays.find(source->substr(1))
                           : arrays.end();
    // offset + count * stride <= the array's count, without overflow.
    const bool held = array != arrays.end() && count && offset && stride &&
                      *offset <= array->second &&
                      (*stride == 0 || *count <= (array->second - *offset) / *stride);
    if (!held) {
      return absl::InvalidArgumentError(absl::StrCat(what, ": a COLLADA <accessor> (source ",
                                                     source.value_or("none"),
                                                     ") reaches past the array it reads"));
    }
    return absl::OkStatus();
  });
}

absl::Status ImportError(const std::string& what, const std::string& format,
                         const char* assimp_message) {
  return absl::InvalidArgumentError(absl::StrCat(what, ": not a readable ", FormatName(format),
                                                 " file (assimp: ", assimp_message, ")"));
}

// The glTF's JSON: the whole of a .gltf, the first chunk of a .glb (a 12-byte header "glTF",
// version, length; then chunks of length, type and data, little-endian). The checks below
// read it as assimp will, so JSON that does not parse here is refused (assimp's reader is more
// lenient, with invalid UTF-8 for one, and would read what the checks did not see); a .glb
// without the header is assimp's to refuse (null here).
absl::StatusOr<nlohmann::json> GltfJson(const std::string& bytes, const std::string& format,
                                        const std::string& what) {
  std::string text = bytes;
  if (format == "glb") {
    if (bytes.size() < 12 || bytes.compare(0, 4, "glTF") != 0) return nullptr;
    if (bytes.size() < 20 || bytes.compare(16, 4, "JSON") != 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": not a readable binary glTF file (no JSON chunk first)"));
    }
    // assimp 5.2 allocates and fills what the lengths announce (a 189-byte file announcing a
    // 3.7 GB chunk took 3.7 GB and 10 s): the file's and each chunk's length must fit.
    auto le32 = [&](std::size_t at) {
      std::uint64_t v = 0;
      for (int b = 3; b >= 0; --b) v = v << 8 | static_cast<unsigned char>(bytes[at + b]);
      return v;
    };
    for (std::size_t chunk = 12; chunk + 8 <= bytes.size(); chunk += 8 + le32(chunk)) {
      if (le32(chunk) > bytes.size() - chunk - 8 || le32(8) > bytes.size()) {
        return absl::InvalidArgumentError(absl::StrCat(
            what, ": not a readable binary glTF file (a length passes the end of the file)"));
      }
    }
    text = bytes.substr(20, le32(12));
  }
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": not a readable ", FormatName(format),
                                                   " file (its JSON: ", e.what(), ")"));
  }
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

// Bytes of one component (glTF's componentType) and components of one element (its type);
// 0 for a value the specification does not define.
std::uint64_t ComponentBytes(const nlohmann::json& type) {
  if (!type.is_number_unsigned()) return 0;
  switch (type.get<std::uint64_t>()) {
    case 5120:
    case 5121:
      return 1;  // (unsigned) byte
    case 5122:
    case 5123:
      return 2;  // (unsigned) short
    case 5125:
    case 5126:
      return 4;  // unsigned int, float
    default:
      return 0;
  }
}
std::uint64_t Components(const nlohmann::json& type) {
  const std::string name = type.is_string() ? type.get<std::string>() : "";
  return name == "SCALAR" ? 1
         : name == "VEC2" ? 2
         : name == "VEC3" ? 3
         : name == "VEC4" ? 4
         : name == "MAT2" ? 4
         : name == "MAT3" ? 9
         : name == "MAT4" ? 16
                          : 0;
}

// assimp 5.2 follows a sparse accessor's indices and values without checking them: without a
// bufferView it reads through a null pointer, and a count beyond the views reads past them.
// Such accessors are refused here by the specification's rules: `indices` and `values` each
// name an existing buffer view that holds `count` indices (values) from its byteOffset.
absl::Status CheckGltfSparseAccessors(const nlohmann::json& gltf, const std::string& what) {
  if (!gltf.is_object() || !gltf.contains("accessors") || !gltf["accessors"].is_array()) {
    return absl::OkStatus();
  }
  const nlohmann::json& accessors = gltf["accessors"];
  const nlohmann::json no_views = nlohmann::json::array();
  const nlohmann::json& views = gltf.contains("bufferViews") && gltf["bufferViews"].is_array()
                                    ? gltf["bufferViews"]
                                    : no_views;
  // Reads object[key] into *out: false when it is not an unsigned integer, or when it is
  // missing and has no default (`fallback` empty).
  auto unsigned_field = [](const nlohmann::json& object, const char* key,
                           std::optional<std::uint64_t> fallback, std::uint64_t* out) {
    if (!object.contains(key)) {
      *out = fallback.value_or(0);
      return fallback.has_value();
    }
    if (!object[key].is_number_unsigned()) return false;
    *out = object[key].get<std::uint64_t>();
    return true;
  };
  // True when `part` (sparse.indices or sparse.values) names a view that holds `count`
  // elements of `element_bytes` from its byteOffset.
  auto holds = [&](const nlohmann::json& part, std::uint64_t count, std::uint64_t element_bytes) {
    std::uint64_t view = 0, offset = 0, length = 0;
    if (!part.is_object() || element_bytes == 0 ||
        !unsigned_field(part, "bufferView", std::nullopt, &view) ||
        !unsigned_field(part, "byteOffset", 0, &offset) || view >= views.size() ||
        !views[view].is_object() ||
        !unsigned_field(views[view], "byteLength", std::nullopt, &length)) {
      return false;
    }
    return offset <= length && count <= (length - offset) / element_bytes;
  };
  for (std::size_t a = 0; a < accessors.size(); ++a) {
    const nlohmann::json& accessor = accessors[a];
    if (!accessor.is_object() || !accessor.contains("sparse")) continue;
    const nlohmann::json& sparse = accessor["sparse"];
    std::uint64_t count = 0;
    const bool valid =
        sparse.is_object() && unsigned_field(sparse, "count", std::nullopt, &count) &&
        sparse.contains("indices") && sparse.contains("values") &&
        holds(sparse["indices"], count,
              sparse["indices"].is_object() && sparse["indices"].contains("componentType")
                  ? ComponentBytes(sparse["indices"]["componentType"])
                  : 0) &&
        holds(sparse["values"], count,
              accessor.contains("componentType") && accessor.contains("type")
                  ? ComponentBytes(accessor["componentType"]) * Components(accessor["type"])
                  : 0);
    if (!valid) {
      return absl::InvalidArgumentError(
          absl::StrCat(what, ": the glTF's accessor ", a,
                       " is sparse without indices and values that its buffer views hold"));
    }
  }
  return absl::OkStatus();
}

// assimp 5.2 decodes an embedded (data:...;base64,) buffer or image into memory it has just
// allocated and throws on a byte above 0x7f without freeing it, so every such file leaked
// (fuzz_scene, LeakSanitizer). The specification's base64 alphabet is checked here instead.
absl::Status CheckGltfDataUris(const nlohmann::json& gltf, const std::string& what) {
  if (!gltf.is_object()) return absl::OkStatus();
  for (const char* list : {"buffers", "images"}) {
    if (!gltf.contains(list) || !gltf[list].is_array()) continue;
    for (std::size_t i = 0; i < gltf[list].size(); ++i) {
      const nlohmann::json& item = gltf[list][i];
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string& uri = item["uri"].get_ref<const std::string&>();
      const std::size_t comma = uri.find(',');
      if (!absl::StartsWith(uri, "data:") || comma == std::string::npos ||
          !absl::EndsWith(uri.substr(0, comma), ";base64")) {
        continue;
      }
      for (std::size_t c = comma + 1; c < uri.size(); ++c) {
        const unsigned char b = static_cast<unsigned char>(uri[c]);
        if (!absl::ascii_isalnum(b) && b != '+' && b != '/' && b != '=') {
          return absl::InvalidArgumentError(
              absl::StrCat(what, ": the glTF's ", list, "[", i,
                           "] is an embedded (data:) URI that is not base64"));
        }
      }
    }
  }
  return absl::OkStatus();
}

// assimp 5.2 builds an indexed LINE_LOOP (mode 2) by skipping each line with an index past the
// positions and then closing the loop from its first line, which it read through a null pointer
// when that one was skipped (a crash). inscribe leaves lines out of the mesh anyway, so such
// primitives are refused rather than decoded here (a TRIANGLE_FAN has the same flaw for its
// first triangle and is still given to assimp: it holds triangles).
absl::Status CheckGltfLineLoops(const nlohmann::json& gltf, const std::string& what) {
  if (!gltf.is_object() || !gltf.contains("meshes") || !gltf["meshes"].is_array()) {
    return absl::OkStatus();
  }
  for (std::size_t m = 0; m < gltf["meshes"].size(); ++m) {
    const nlohmann::json& mesh = gltf["meshes"][m];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) {
      continue;
    }
    for (const nlohmann::json& primitive : mesh["primitives"]) {
      if (primitive.is_object() && primitive.contains("indices") && primitive.contains("mode") &&
          primitive["mode"] == 2) {
        return absl::InvalidArgumentError(absl::StrCat(
            what, ": the glTF's mesh ", m,
            " has an indexed LINE_LOOP primitive, which inscribe does not read (lines bound "
            "nothing; leave them out of the file)"));
      }
    }
  }
  return absl::OkStatus();
}

// What assimp 5.2 cannot be trusted with, refused before it reads the file (above).
absl::Status CheckBeforeAssimp(const std::string& bytes, const std::string& format,
                               const std::string& what) {
  if (format == "dae") {
    if (absl::Status indices = CheckColladaIndexLists(bytes, what); !indices.ok()) return indices;
    return CheckColladaAccessors(bytes, what);
  }
  absl::StatusOr<nlohmann::json> gltf = GltfJson(bytes, format, what);
  if (!gltf.ok()) return gltf.status();
  if (absl::Status uris = CheckGltfDataUris(*gltf, what); !uris.ok()) return uris;
  if (absl::Status loops = CheckGltfLineLoops(*gltf, what); !loops.ok()) return loops;
  return CheckGltfSparseAccessors(*gltf, what);
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
      if (absl::Status checked = CheckBeforeAssimp(bytes, format, path); !checked.ok()) {
        return checked;
      }
    }
  }
  Assimp::Importer importer;
  ConfigureImporter(importer);
  const aiScene* scene = Triangulated(importer, importer.ReadFile(path, 0), info);
  if (scene == nullptr) return ImportError(path, format, importer.GetErrorString());
  return SceneToMesh(*scene, path, format);
}

absl::StatusOr<Mesh> ImportSceneBytes(const std::string& bytes, const std::string& format,
                                      const std::string& what, ReadMeshInfo* info) {
  if (bytes.empty()) return absl::InvalidArgumentError(absl::StrCat(what, ": file is empty"));
  if (absl::Status checked = CheckBeforeAssimp(bytes, format, what); !checked.ok()) {
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
  ConfigureImporter(importer);
  const aiScene* scene = Triangulated(
      importer, importer.ReadFileFromMemory(bytes.data(), bytes.size(), 0, format.c_str()), info);
  if (scene == nullptr) return ImportError(what, format, importer.GetErrorString());
  return SceneToMesh(*scene, what, format);
}

}  // namespace inscribe::internal
