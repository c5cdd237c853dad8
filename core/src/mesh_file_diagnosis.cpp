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
  // Tokens of the header: the keyword, then the vertex and face counts; comments skipped.
  std::vector<absl::string_view> tokens;
  std::size_t pos = 0;
  while (pos < bytes.size() && tokens.size() < 3) {
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string::npos) end = bytes.size();
    absl::string_view line(bytes.data() + pos, end - pos);
    pos = end + 1;
    const std::size_t hash = line.find('#');
    if (hash != absl::string_view::npos) line = line.substr(0, hash);
    for (absl::string_view token :
         absl::StrSplit(line, absl::ByAnyChar(" \t\r\f\v"), absl::SkipEmpty())) {
      if (token == "BINARY") return "";  // counts are binary; CGAL reads them itself
      if (tokens.size() < 3) tokens.push_back(token);
    }
  }
  if (tokens.size() < 3) return "";  // too short to announce anything: the reader will say
  std::int64_t vertices = 0, faces = 0;
  if (!absl::SimpleAtoi(tokens[1], &vertices) || !absl::SimpleAtoi(tokens[2], &faces)) return "";
  if (vertices < 0 || faces < 0) {
    return absl::StrCat("header announces ", vertices, " vertices and ", faces,
                        " faces; counts cannot be negative");
  }
  // The shortest text a vertex can take is "0 0 0\n" (6 bytes), a face "3 0 1 2\n" (8).
  const std::int64_t rest = pos >= bytes.size() ? 0 : static_cast<std::int64_t>(bytes.size() - pos);
  constexpr std::int64_t kLimit = std::int64_t{1} << 40;
  if (vertices > kLimit || faces > kLimit || 6 * vertices + 8 * faces - 1 > rest) {
    return absl::StrCat("header announces ", vertices, " vertices and ", faces,
                        " faces, more than the remaining ", rest, " bytes can hold (truncated?)");
  }
  return "";
}

std::string DiagnoseMeshText(const std::string& bytes, const std::string& format) {
  if (bytes.find('\0') != std::string::npos) return "file contains binary data";
  const std::vector<Line> lines = Tokenize(bytes);
  if (format == "off") return DiagnoseOff(lines);
  if (format == "obj") return DiagnoseObj(lines);
  return "";
}

}  // namespace inscribe::internal
