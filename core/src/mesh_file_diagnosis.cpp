#include "mesh_file_diagnosis.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/string_view.h"

namespace inscribe::internal {
namespace {

struct Line {
  int number;
  std::vector<absl::string_view> tokens;
};

// Lines with their tokens, without comments (#) and blank lines.
std::vector<Line> Tokenize(const std::string& bytes) {
  std::vector<Line> lines;
  int number = 0;
  for (absl::string_view text : absl::StrSplit(bytes, '\n')) {
    ++number;
    const std::size_t hash = text.find('#');
    if (hash != absl::string_view::npos) text = text.substr(0, hash);
    Line line{number, absl::StrSplit(text, absl::ByAnyChar(" \t\r\f\v"), absl::SkipEmpty())};
    if (!line.tokens.empty()) lines.push_back(std::move(line));
  }
  return lines;
}

// "" when `token` is a finite number, else what is wrong with it.
std::string CheckCoordinate(absl::string_view token) {
  double value = 0;
  if (!absl::SimpleAtod(token, &value)) {
    return absl::StrCat("'", token, "' is not a number");
  }
  if (!std::isfinite(value)) return absl::StrCat("'", token, "' is not a finite number");
  return "";
}

std::string DiagnoseOff(const std::vector<Line>& lines) {
  std::size_t i = 0;
  if (lines.empty()) return "file has no content";
  absl::string_view header = lines[0].tokens[0];
  if (header.size() >= 3 && header.substr(header.size() - 3) == "OFF") {
    if (lines[0].tokens.size() > 1) {
      // Counts on the header line: treat the rest of the line as the counts line.
    } else {
      ++i;
    }
  } else {
    return absl::StrCat("line ", lines[0].number, ": expected the OFF header, found '", header,
                        "'");
  }
  if (i >= lines.size()) return "file ends before the vertex and face counts";
  const Line& counts = lines[i];
  const std::size_t first = i == 0 ? 1 : 0;
  std::int64_t nv = 0, nf = 0;
  if (counts.tokens.size() < first + 2 || !absl::SimpleAtoi(counts.tokens[first], &nv) ||
      !absl::SimpleAtoi(counts.tokens[first + 1], &nf)) {
    return absl::StrCat("line ", counts.number, ": expected the vertex, face and edge counts");
  }
  if (nv < 0 || nf < 0) {
    return absl::StrCat("line ", counts.number, ": header announces ", nv, " vertices and ", nf,
                        " faces; counts cannot be negative");
  }
  ++i;
  for (std::int64_t v = 0; v < nv; ++v, ++i) {
    if (i >= lines.size()) {
      return absl::StrCat("file ends after ", v, " of ", nv, " vertices (truncated?)");
    }
    const Line& line = lines[i];
    if (line.tokens.size() < 3) {
      return absl::StrCat("line ", line.number, ": vertex ", v, " has ", line.tokens.size(),
                          " coordinates, expected 3");
    }
    for (int k = 0; k < 3; ++k) {
      if (std::string why = CheckCoordinate(line.tokens[k]); !why.empty()) {
        return absl::StrCat("line ", line.number, ": vertex ", v, ": ", why);
      }
    }
  }
  for (std::int64_t f = 0; f < nf; ++f, ++i) {
    if (i >= lines.size()) {
      return absl::StrCat("file ends after ", f, " of ", nf, " faces (truncated?)");
    }
    const Line& line = lines[i];
    std::int64_t corners = 0;
    if (!absl::SimpleAtoi(line.tokens[0], &corners) || corners < 1) {
      return absl::StrCat("line ", line.number, ": face ", f, ": '", line.tokens[0],
                          "' is not a corner count");
    }
    if (static_cast<std::int64_t>(line.tokens.size()) < corners + 1) {
      return absl::StrCat("line ", line.number, ": face ", f, " announces ", corners,
                          " corners but lists ", line.tokens.size() - 1);
    }
    for (std::int64_t k = 1; k <= corners; ++k) {
      std::int64_t index = 0;
      if (!absl::SimpleAtoi(line.tokens[static_cast<std::size_t>(k)], &index)) {
        return absl::StrCat("line ", line.number, ": face ", f, ": '",
                            line.tokens[static_cast<std::size_t>(k)], "' is not a vertex index");
      }
      if (index < 0 || index >= nv) {
        return absl::StrCat("line ", line.number, ": face ", f, " refers to vertex ", index,
                            ", but the file has ", nv, " vertices (indices are 0-based)");
      }
    }
  }
  return "";
}

std::string DiagnoseObj(const std::vector<Line>& lines) {
  std::int64_t vertices = 0;
  std::int64_t faces = 0;
  bool any_known = false;
  for (const Line& line : lines) {
    const absl::string_view key = line.tokens[0];
    if (key == "v") {
      any_known = true;
      if (line.tokens.size() < 4) {
        return absl::StrCat("line ", line.number, ": vertex has ", line.tokens.size() - 1,
                            " coordinates, expected 3");
      }
      for (std::size_t k = 1; k <= 3; ++k) {
        if (std::string why = CheckCoordinate(line.tokens[k]); !why.empty()) {
          return absl::StrCat("line ", line.number, ": vertex ", vertices, ": ", why);
        }
      }
      ++vertices;
    } else if (key == "f") {
      any_known = true;
      for (std::size_t k = 1; k < line.tokens.size(); ++k) {
        const absl::string_view corner = line.tokens[k].substr(0, line.tokens[k].find('/'));
        std::int64_t index = 0;
        if (!absl::SimpleAtoi(corner, &index) || index == 0) {
          return absl::StrCat("line ", line.number, ": '", line.tokens[k],
                              "' is not a vertex reference");
        }
        const std::int64_t resolved = index > 0 ? index : vertices + 1 + index;
        if (resolved < 1 || resolved > vertices) {
          return absl::StrCat("line ", line.number, ": face ", faces, " refers to vertex ", index,
                              ", but only ", vertices,
                              " vertices precede it (indices are 1-based)");
        }
      }
      ++faces;
    } else if (key == "vn" || key == "vt" || key == "vp" || key == "o" || key == "g" ||
               key == "s" || key == "l" || key == "mtllib" || key == "usemtl") {
      any_known = true;
    } else {
      return absl::StrCat("line ", line.number, ": '", key, "' is not an OBJ statement");
    }
  }
  if (!any_known) return "no OBJ statements found";
  return "";
}

}  // namespace

std::string CheckOffCounts(const std::string& bytes) {
  // Walks the file a line at a time, as CGAL's scanner does: header keyword, counts, one line
  // per vertex, one per face. Nothing is stored.
  std::size_t pos = 0;
  int number = 0;
  std::vector<absl::string_view> tokens;
  auto next_line = [&]() -> bool {  // next non-blank line's tokens, comments removed
    while (pos < bytes.size()) {
      std::size_t end = bytes.find('\n', pos);
      if (end == std::string::npos) end = bytes.size();
      absl::string_view line(bytes.data() + pos, end - pos);
      pos = end + 1;
      ++number;
      const std::size_t hash = line.find('#');
      if (hash != absl::string_view::npos) line = line.substr(0, hash);
      tokens = absl::StrSplit(line, absl::ByAnyChar(" \t\r\f\v"), absl::SkipEmpty());
      if (!tokens.empty()) return true;
    }
    return false;
  };
  if (!next_line()) return "";
  for (absl::string_view token : tokens) {
    if (token == "BINARY") return "binary OFF is not supported; use ASCII OFF, PLY or STL";
  }
  std::size_t first = 1;  // counts may follow the keyword on its own line
  if (tokens.size() < 3) {
    if (!next_line()) return "";
    first = 0;
  }
  std::int64_t vertices = 0, faces = 0;
  if (tokens.size() < first + 2 || !absl::SimpleAtoi(tokens[first], &vertices) ||
      !absl::SimpleAtoi(tokens[first + 1], &faces)) {
    return "";  // not counts: CGAL's reader refuses the file and the diagnosis says why
  }
  if (vertices < 0 || faces < 0) {
    return absl::StrCat("line ", number, ": header announces ", vertices, " vertices and ", faces,
                        " faces; counts cannot be negative");
  }
  // CGAL sizes its arrays from these counts before reading: bound them by the file. The
  // shortest text a vertex can take is "0 0 0\n" (6 bytes), a face "3 0 1 2\n" (8).
  const std::int64_t rest = static_cast<std::int64_t>(bytes.size() - std::min(pos, bytes.size()));
  constexpr std::int64_t kLimit = std::int64_t{1} << 40;
  if (vertices > kLimit || faces > kLimit || 6 * vertices + 8 * faces - 1 > rest) {
    return absl::StrCat("header announces ", vertices, " vertices and ", faces,
                        " faces, more than the remaining ", rest, " bytes can hold (truncated?)");
  }
  for (std::int64_t v = 0; v < vertices; ++v) {
    if (!next_line()) return "";  // truncated: the reader and the diagnosis handle it
  }
  // CGAL also sizes each face from its corner count before reading the corners.
  for (std::int64_t f = 0; f < faces; ++f) {
    if (!next_line()) return "";
    std::int64_t corners = 0;
    if (!absl::SimpleAtoi(tokens[0], &corners)) return "";
    if (corners < 0 || corners > static_cast<std::int64_t>(tokens.size()) - 1) {
      return absl::StrCat("line ", number, ": face ", f, " announces ", corners,
                          " corners but lists ", tokens.size() - 1);
    }
  }
  return "";
}

namespace {

// Bytes of a PLY scalar type, 0 if unknown.
int PlyTypeSize(absl::string_view type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

struct PlyProperty {
  int size = 0;        // scalar size, or list item size
  int count_size = 0;  // list count size; 0 for a scalar
  bool count_signed = false;
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
};

// Reads a binary list count of `size` bytes.
std::int64_t ReadCount(const char* p, int size, bool is_signed, bool big_endian) {
  std::uint64_t value = 0;
  for (int i = 0; i < size; ++i) {
    const auto byte = static_cast<unsigned char>(p[big_endian ? i : size - 1 - i]);
    value = (value << 8) | byte;
  }
  if (is_signed && size < 8 && (value >> (8 * size - 1)) != 0) {
    return static_cast<std::int64_t>(value) - (std::int64_t{1} << (8 * size));
  }
  return static_cast<std::int64_t>(value);
}

// CGAL sizes every list from its count before reading the items: check that each count fits
// in what is left of the file. Only needed for counts wider than 16 bits.
std::string CheckPlyLists(const std::string& bytes, std::size_t pos, const std::string& format,
                          const std::vector<PlyElement>& elements) {
  const bool ascii = format == "ascii";
  const bool big_endian = format == "binary_big_endian";
  for (const PlyElement& element : elements) {
    for (std::int64_t i = 0; i < element.count; ++i) {
      for (const PlyProperty& property : element.properties) {
        if (pos >= bytes.size()) return "";  // truncated: the reader says so
        const std::int64_t rest = static_cast<std::int64_t>(bytes.size() - pos);
        std::int64_t items = 1;
        if (ascii) {
          const std::size_t start = bytes.find_first_not_of(" \t\r\n", pos);
          if (start == std::string::npos) return "";
          std::size_t end = bytes.find_first_of(" \t\r\n", start);
          if (end == std::string::npos) end = bytes.size();
          pos = end;
          if (property.count_size == 0) continue;
          if (!absl::SimpleAtoi(absl::string_view(bytes.data() + start, end - start), &items)) {
            return "";
          }
          if (items < 0 || items > rest / 2) {
            return absl::StrCat(element.name, " ", i, ": a list of ", items,
                                " items is longer than the rest of the file");
          }
          for (std::int64_t k = 0; k < items; ++k) {
            const std::size_t s = bytes.find_first_not_of(" \t\r\n", pos);
            if (s == std::string::npos) return "";
            pos = bytes.find_first_of(" \t\r\n", s);
            if (pos == std::string::npos) pos = bytes.size();
          }
        } else {
          if (property.count_size == 0) {
            pos += static_cast<std::size_t>(property.size);
            continue;
          }
          if (rest < property.count_size) return "";
          items =
              ReadCount(bytes.data() + pos, property.count_size, property.count_signed, big_endian);
          if (items < 0 || items > (rest - property.count_size) / property.size) {
            return absl::StrCat(element.name, " ", i, ": a list of ", items,
                                " items is longer than the rest of the file");
          }
          pos += static_cast<std::size_t>(property.count_size + items * property.size);
        }
      }
    }
  }
  return "";
}

}  // namespace

std::string CheckPlyHeader(const std::string& bytes) {
  std::size_t pos = 0;
  std::string format;
  std::vector<PlyElement> elements;
  bool wide_lists = false;
  for (int number = 1;; ++number) {
    if (pos >= bytes.size()) return "header has no end_header line (truncated?)";
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    absl::string_view line(bytes.data() + pos, end - pos);
    pos = end + 1;
    const std::vector<absl::string_view> tokens =
        absl::StrSplit(line, absl::ByAnyChar(" \t\r"), absl::SkipEmpty());
    const absl::string_view keyword = tokens.empty() ? absl::string_view() : tokens[0];
    auto bad = [&](absl::string_view what) { return absl::StrCat("line ", number, ": ", what); };
    if (number == 1) {
      if (keyword != "ply") return bad("expected 'ply'");
    } else if (keyword == "format") {
      if (tokens.size() != 3 || (tokens[1] != "ascii" && tokens[1] != "binary_little_endian" &&
                                 tokens[1] != "binary_big_endian")) {
        return bad("unknown format");
      }
      format = std::string(tokens[1]);
    } else if (keyword == "element") {
      std::int64_t count = 0;
      if (tokens.size() != 3 || !absl::SimpleAtoi(tokens[2], &count) || count < 0) {
        return bad("malformed element line");
      }
      elements.push_back(PlyElement{std::string(tokens[1]), count, {}});
    } else if (keyword == "property") {
      // CGAL 5.5 crashes on a property before any element.
      if (elements.empty()) return bad("property before any element");
      PlyProperty property;
      if (tokens.size() == 3) {
        property.size = PlyTypeSize(tokens[1]);
      } else if (tokens.size() == 5 && tokens[1] == "list") {
        property.count_size = PlyTypeSize(tokens[2]);
        property.count_signed = tokens[2][0] != 'u';
        property.size = PlyTypeSize(tokens[3]);
        if (property.count_size == 0) return bad("unknown list count type");
        wide_lists = wide_lists || property.count_size > 2;
      } else {
        return bad("malformed property line");
      }
      if (property.size == 0) return bad("unknown property type");
      elements.back().properties.push_back(property);
    } else if (keyword == "end_header") {
      if (format.empty()) return "header has no format line";
      if (elements.empty()) return "header declares no element";
      return wide_lists ? CheckPlyLists(bytes, pos, format, elements) : "";
    } else if (keyword != "comment" && keyword != "obj_info") {
      return bad(absl::StrCat("'", keyword, "' is not a PLY header keyword"));
    }
  }
}

std::string DiagnoseMeshText(const std::string& bytes, const std::string& format) {
  if (format != "off" && format != "obj") return "";
  if (bytes.find('\0') != std::string::npos) return "file contains binary data";
  const std::vector<Line> lines = Tokenize(bytes);
  return format == "off" ? DiagnoseOff(lines) : DiagnoseObj(lines);
}

}  // namespace inscribe::internal
