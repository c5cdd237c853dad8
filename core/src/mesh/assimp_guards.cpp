#include "mesh/assimp_guards.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"

namespace inscribe::internal {
namespace {

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

// The text of `element` (all its text and CDATA children, joined by spaces): at least what
// assimp's reader takes for it (its first text child).
std::string TextOf(const tinyxml2::XMLElement& element) {
  std::string text;
  for (const tinyxml2::XMLNode* child = element.FirstChild(); child != nullptr;
       child = child->NextSibling()) {
    if (const tinyxml2::XMLText* part = child->ToText()) absl::StrAppend(&text, " ", part->Value());
  }
  return text;
}

// The sum of the whole numbers in `text`, at most `limit`; nullopt when something else is there.
std::optional<std::uint64_t> SumOfNumbers(absl::string_view text, std::uint64_t limit,
                                          bool* above_limit) {
  std::uint64_t sum = 0;
  *above_limit = false;
  for (absl::string_view token :
       absl::StrSplit(text, absl::ByAnyChar(" \t\r\n"), absl::SkipEmpty())) {
    std::uint64_t n = 0;
    if (!absl::SimpleAtoi(token, &n) ||
        !absl::ascii_isdigit(static_cast<unsigned char>(token[0]))) {
      return std::nullopt;
    }
    if (n > limit - sum) {
      *above_limit = true;
      return limit;
    }
    sum += n;
  }
  return sum;
}

// Every element under `root`, itself first, in document order (as assimp walks a primitive's
// children); `visit` returns false to stop.
template <typename Visit>
void InDocumentOrder(const tinyxml2::XMLElement& root, Visit&& visit) {
  std::vector<const tinyxml2::XMLElement*> stack = {&root};
  while (!stack.empty()) {
    const tinyxml2::XMLElement* element = stack.back();
    stack.pop_back();
    if (!visit(*element)) return;
    std::vector<const tinyxml2::XMLElement*> children;
    for (const tinyxml2::XMLElement* c = element->FirstChildElement(); c != nullptr;
         c = c->NextSiblingElement()) {
      children.push_back(c);
    }
    stack.insert(stack.end(), children.rbegin(), children.rend());
  }
}

// assimp 5.2 sizes its buffers by the numbers a COLLADA file announces before it reads what
// they count: <polylist count="4000000000"> reserves 32 GB, a <triangles> count three times
// that, an <input offset="4000000000"> multiplies every index count of its primitive, and the
// counts of arrays and <vertex_weights> and the numbers of a <vcount> do the same. None can
// count more than the file holds, so each is refused beyond the file's size in bytes: every
// count attribute, every <input>'s offset, the sum of a <vcount>'s numbers, and the indices a
// <lines>, <triangles> or <polylist> announces (its count times 2 or 3 corners, or its
// <vcount>'s sum, times its inputs' largest offset + 1), which assimp reserves at once.
// assimp 5.2 also takes each polygon's corner count from the <vcount> of a <polylist> without
// checking that it read one: a <p> before any <vcount> (or without one) indexes an empty list
// (a crash; fuzz_scene). Such a <polylist> is refused. The XML is read with tinyxml2 and XML
// it cannot read is refused, since assimp's reader would see what these checks did not.
absl::Status CheckColladaCounts(const std::string& bytes, const std::string& what) {
  tinyxml2::XMLDocument document;
  if (document.Parse(bytes.data(), bytes.size()) != tinyxml2::XML_SUCCESS) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": not a readable COLLADA file (its XML: ", document.ErrorStr(), ")"));
  }
  const std::uint64_t limit = bytes.size();
  auto refused = [&](const tinyxml2::XMLElement& element, const auto&... message) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": line ", element.GetLineNum(), ": a COLLADA <", element.Name(), "> ", message...));
  };
  // A whole number within the file's size, or an error naming `attribute`.
  auto bounded = [&](const tinyxml2::XMLElement& element, const char* attribute,
                     std::uint64_t* out) -> absl::Status {
    *out = 0;
    const char* text = element.Attribute(attribute);
    if (text == nullptr) return absl::OkStatus();
    if (!absl::SimpleAtoi(text, out) || *out > limit) {
      return refused(element, "has ", attribute, "=\"", text,
                     "\", which is not a whole number within the file's size (", limit, " bytes)");
    }
    return absl::OkStatus();
  };
  absl::Status status;
  std::vector<const tinyxml2::XMLElement*> primitives;
  if (document.RootElement() == nullptr) return absl::OkStatus();  // assimp's to refuse
  InDocumentOrder(*document.RootElement(), [&](const tinyxml2::XMLElement& element) {
    const absl::string_view name = element.Name();
    std::uint64_t ignored = 0;
    status = bounded(element, "count", &ignored);
    if (status.ok() && name == "input") status = bounded(element, "offset", &ignored);
    if (status.ok() && name == "vcount") {
      bool above = false;
      if (!SumOfNumbers(TextOf(element), limit, &above).has_value()) {
        status = refused(element, "holds something other than whole numbers");
      } else if (above) {
        status = refused(element, "adds up to more than the file's size (", limit, " bytes)");
      }
    }
    if (name == "lines" || name == "triangles" || name == "polylist") {
      primitives.push_back(&element);
    }
    return status.ok();
  });
  if (!status.ok()) return status;

  for (const tinyxml2::XMLElement* primitive : primitives) {
    const absl::string_view name = primitive->Name();
    std::uint64_t count = 0, offsets = 1, corners = 0;
    bounded(*primitive, "count", &count).IgnoreError();  // checked above
    bool vcount = false, p_before_vcount = false;
    InDocumentOrder(*primitive, [&](const tinyxml2::XMLElement& element) {
      const absl::string_view child = element.Name();
      std::uint64_t offset = 0;
      if (child == "input" && bounded(element, "offset", &offset).ok()) {
        offsets = std::max(offsets, offset + 1);
      }
      if (child == "vcount") {
        bool above = false;
        corners += SumOfNumbers(TextOf(element), limit, &above).value_or(0);  // checked above
        vcount = true;
      }
      if (child == "p" && !vcount) p_before_vcount = true;
      return true;
    });
    if (name == "polylist" && count > 0 && p_before_vcount) {
      return refused(*primitive,
                     "has a <p> without a <vcount> before it (each polygon's number of corners)");
    }
    if (name != "polylist") corners = count * (name == "lines" ? 2 : 3);
    if (corners > limit / offsets) {
      return refused(*primitive, "announces ", corners, " corners of ", offsets,
                     " indices each, more than the file's size (", limit, " bytes) holds");
    }
  }
  return absl::OkStatus();
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
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": not a readable ", SceneFormatName(format), " file (its JSON: ", e.what(), ")"));
  }
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

// Per primitive, what assimp 5.2 mishandles by its mode (default 4, TRIANGLES):
// - An indexed LINE_LOOP (2): assimp skips each line with an index past the positions, then
//   closes the loop from its first line, read through a null pointer when that one was skipped
//   (a crash). inscribe leaves lines out of the mesh anyway, so such primitives are refused.
// - A LINE_STRIP (3) of fewer than 2 vertices, or a TRIANGLE_STRIP (5) or TRIANGLE_FAN (6) of
//   fewer than 3 (its indices' count, or without indices its POSITION accessor's): assimp
//   allocates count - 1 (count - 2) faces, which wraps below zero to 2^64 - 1 bytes (64 GB
//   without indices), and at exactly one short of the least it writes a face into an empty
//   array (fuzz_scene: a mutated strip/fan .glb). Such primitives hold no line or triangle.
// An indexed TRIANGLE_FAN with an index past the positions is assimp's to read: it builds
// each triangle from the indices (not from the triangle before, as the LINE_LOOP's closing
// line is), and drops those that reach past, as it does for TRIANGLES (test
// AssimpImportTest.FansWithAnIndexPastThePositionsAreRead).
absl::Status CheckGltfPrimitives(const nlohmann::json& gltf, const std::string& what) {
  if (!gltf.is_object() || !gltf.contains("meshes") || !gltf["meshes"].is_array()) {
    return absl::OkStatus();
  }
  const nlohmann::json no_accessors = nlohmann::json::array();
  const nlohmann::json& accessors =
      gltf.contains("accessors") && gltf["accessors"].is_array() ? gltf["accessors"] : no_accessors;
  // The count of the accessor `index` names: 0 when it names none or has no whole count (the
  // least assimp could take it for); nullopt when `index` is not an accessor's index at all,
  // which assimp refuses.
  auto count_of = [&](const nlohmann::json& index) -> std::optional<std::uint64_t> {
    if (!index.is_number_unsigned() || index.get<std::uint64_t>() >= accessors.size()) {
      return std::nullopt;
    }
    const nlohmann::json& accessor = accessors[index.get<std::size_t>()];
    if (!accessor.is_object() || !accessor.contains("count") ||
        !accessor["count"].is_number_unsigned()) {
      return 0;
    }
    return accessor["count"].get<std::uint64_t>();
  };
  for (std::size_t m = 0; m < gltf["meshes"].size(); ++m) {
    const nlohmann::json& mesh = gltf["meshes"][m];
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) {
      continue;
    }
    for (std::size_t p = 0; p < mesh["primitives"].size(); ++p) {
      const nlohmann::json& primitive = mesh["primitives"][p];
      if (!primitive.is_object()) continue;
      // assimp reads the mode as an integer and keeps TRIANGLES for anything else.
      const std::int64_t mode = primitive.contains("mode") && primitive["mode"].is_number_integer()
                                    ? primitive["mode"].get<std::int64_t>()
                                    : 4;
      const bool indexed = primitive.contains("indices");
      if (indexed && mode == 2) {
        return absl::InvalidArgumentError(absl::StrCat(
            what, ": the glTF's mesh ", m,
            " has an indexed LINE_LOOP primitive, which inscribe does not read (lines bound "
            "nothing; leave them out of the file)"));
      }
      if (mode != 3 && mode != 5 && mode != 6) continue;
      const char* kind = mode == 3 ? "LINE_STRIP" : mode == 5 ? "TRIANGLE_STRIP" : "TRIANGLE_FAN";
      const std::uint64_t least = mode == 3 ? 2 : 3;
      std::optional<std::uint64_t> count = 0;
      if (indexed) {
        count = count_of(primitive["indices"]);
      } else if (primitive.contains("attributes") && primitive["attributes"].is_object() &&
                 primitive["attributes"].contains("POSITION")) {
        count = count_of(primitive["attributes"]["POSITION"]);
      }
      if (count.has_value() && *count < least) {
        return absl::InvalidArgumentError(
            absl::StrCat(what, ": the glTF's mesh ", m, " primitive ", p, " is a ", kind, " of ",
                         *count, *count == 1 ? " vertex" : " vertices",
                         indexed ? " (its indices' count)" : "", "; one needs at least ", least));
      }
    }
  }
  return absl::OkStatus();
}

}  // namespace

const char* SceneFormatName(const std::string& format) {
  return format == "dae" ? "COLLADA" : format == "glb" ? "binary glTF" : "glTF";
}

absl::Status CheckSceneBeforeAssimp(const std::string& bytes, const std::string& format,
                                    const std::string& what) {
  if (format == "dae") {
    if (absl::Status indices = CheckColladaIndexLists(bytes, what); !indices.ok()) return indices;
    if (absl::Status counts = CheckColladaCounts(bytes, what); !counts.ok()) return counts;
    return CheckColladaAccessors(bytes, what);
  }
  absl::StatusOr<nlohmann::json> gltf = GltfJson(bytes, format, what);
  if (!gltf.ok()) return gltf.status();
  if (absl::Status uris = CheckGltfDataUris(*gltf, what); !uris.ok()) return uris;
  if (absl::Status primitives = CheckGltfPrimitives(*gltf, what); !primitives.ok()) {
    return primitives;
  }
  return CheckGltfSparseAccessors(*gltf, what);
}

}  // namespace inscribe::internal
