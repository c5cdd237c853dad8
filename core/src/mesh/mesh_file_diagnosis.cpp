#include "mesh/mesh_file_diagnosis.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
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

namespace {

// Reads ASCII OFF the way CGAL 5.5's File_header_OFF and File_scanner_OFF do, character for
// character, so that the counts checked are the counts CGAL allocates from: the header's
// integers are read with `>>` across line breaks (after the keyword, comment lines first), and
// every vertex and face is the rest of a line after blanks and comment lines, whatever the
// line structure; a count line may thus continue with the first vertex.
class OffScanner {
 public:
  explicit OffScanner(const std::string& bytes) : bytes_(bytes) {}

  bool at_end() const { return pos_ >= bytes_.size(); }
  std::size_t pos() const { return pos_; }
  // 1-based line number of the current position. O(pos): count lines for messages only, not
  // per record (that made reading a 75k-face file take a minute).
  std::int64_t line() const { return LineAt(pos_); }
  std::int64_t LineAt(std::size_t pos) const {
    return 1 +
           std::count(bytes_.begin(),
                      bytes_.begin() + static_cast<std::ptrdiff_t>(std::min(pos, bytes_.size())),
                      '\n');
  }

  // skip_comment_OFF: blanks, and lines whose first non-blank is '#'.
  void SkipComments() {
    while (!at_end()) {
      if (std::isspace(static_cast<unsigned char>(bytes_[pos_]))) {
        ++pos_;
      } else if (bytes_[pos_] == '#') {
        const std::size_t eol = bytes_.find('\n', pos_);
        pos_ = eol == std::string::npos ? bytes_.size() : eol + 1;
      } else {
        break;
      }
    }
  }

  // The header keyword: a first character, then letters and digits; like CGAL, the character
  // that ends it is consumed too.
  absl::string_view Keyword() {
    const std::size_t begin = pos_;
    if (!at_end()) ++pos_;
    while (!at_end() && std::isalnum(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    const absl::string_view keyword(bytes_.data() + begin, pos_ - begin);
    if (!at_end()) ++pos_;
    return keyword;
  }

  // `in >> int`: blanks, an optional sign, digits. False when there are none or the value
  // does not fit an int (the stream fails then, and CGAL gives up before allocating).
  bool Int(std::int64_t* value) {
    while (!at_end() && std::isspace(static_cast<unsigned char>(bytes_[pos_]))) ++pos_;
    std::size_t end = pos_;
    const bool negative = end < bytes_.size() && bytes_[end] == '-';
    if (end < bytes_.size() && (bytes_[end] == '-' || bytes_[end] == '+')) ++end;
    const std::size_t digits = end;
    while (end < bytes_.size() && bytes_[end] == '0') ++end;  // "0008" is 8
    const std::size_t significant = end;
    while (end < bytes_.size() && std::isdigit(static_cast<unsigned char>(bytes_[end]))) ++end;
    if (end == digits || end - significant > 10) return false;
    std::int64_t magnitude = 0;
    if (end > significant &&
        !absl::SimpleAtoi(absl::string_view(bytes_.data() + significant, end - significant),
                          &magnitude)) {
      return false;
    }
    pos_ = end;
    *value = negative ? -magnitude : magnitude;
    return *value >= std::numeric_limits<int>::min() && *value <= std::numeric_limits<int>::max();
  }

  // One vertex or face: comments skipped, then the rest of the line up to any '#'.
  absl::string_view Record() {
    SkipComments();
    std::size_t eol = bytes_.find('\n', pos_);
    if (eol == std::string::npos) eol = bytes_.size();
    absl::string_view record(bytes_.data() + pos_, eol - pos_);
    pos_ = eol + 1;
    if (const std::size_t hash = record.find('#'); hash != absl::string_view::npos) {
      record = record.substr(0, hash);
    }
    return record;
  }

 private:
  const std::string& bytes_;
  std::size_t pos_ = 0;
};

}  // namespace

std::vector<double> CgalRecordNumbers(absl::string_view record) {
  // Fast path: whitespace and plain digit runs of at most 15 digits, which `>> double` reads
  // as the exact integers (a face record is nearly always this); else the stream itself.
  std::vector<double> numbers;
  bool plain = true;
  for (std::size_t i = 0; i < record.size() && plain;) {
    const auto at = [&record](std::size_t k) { return static_cast<unsigned char>(record[k]); };
    if (absl::ascii_isspace(at(i))) {
      ++i;
      continue;
    }
    std::int64_t value = 0;
    std::size_t digits = 0;
    for (; i < record.size() && absl::ascii_isdigit(at(i)) && digits < 16; ++i, ++digits) {
      value = value * 10 + (record[i] - '0');
    }
    plain = digits > 0 && digits <= 15 && (i == record.size() || absl::ascii_isspace(at(i)));
    numbers.push_back(static_cast<double>(value));
  }
  if (plain) return numbers;
  numbers.clear();
  std::istringstream in{std::string(record)};
  double value = 0;
  while (in >> value) numbers.push_back(value);
  return numbers;
}

std::string CheckOffCounts(const std::string& bytes) {
  // Nothing is stored; cost O(file).
  OffScanner scan(bytes);
  scan.SkipComments();
  if (scan.at_end()) return "";
  const absl::string_view keyword = scan.Keyword();
  const bool off = absl::EndsWith(keyword, "OFF");
  if (!off && !absl::EndsWith(keyword, "SKEL")) return "";  // CGAL refuses the file
  // nOFF / nSKEL: the dimension comes first, then the counts.
  const bool dimensional =
      keyword.size() >= (off ? 4u : 5u) && keyword[keyword.size() - (off ? 4 : 5)] == 'n';
  scan.SkipComments();
  if (absl::StartsWith(absl::string_view(bytes).substr(scan.pos()), "BINARY")) {
    return "binary OFF is not supported; use ASCII OFF, PLY or STL";
  }
  const std::int64_t header_line = scan.line();
  std::int64_t dimension = 0, vertices = 0, faces = 0, edges = 0;
  if ((dimensional && !scan.Int(&dimension)) || !scan.Int(&vertices) || !scan.Int(&faces) ||
      (off && !scan.Int(&edges))) {
    if (vertices < 0 || faces < 0) {
      // CGAL refuses these, but the count says more than its "wrong format".
    } else {
      return "";  // not counts: CGAL's reader refuses the file and the diagnosis says why
    }
  }
  if (vertices < 0 || faces < 0) {
    return absl::StrCat("line ", header_line, ": header announces ", vertices, " vertices and ",
                        faces, " faces; counts cannot be negative");
  }
  // CGAL sizes its arrays from these counts before reading: bound them by the file. The
  // shortest text a vertex can take is "0 0 0\n" (6 bytes), a face "3 0 1 2\n" (8).
  const std::int64_t rest =
      static_cast<std::int64_t>(bytes.size() - std::min(scan.pos(), bytes.size()));
  if (6 * vertices + 8 * faces - 1 > rest) {
    return absl::StrCat("header announces ", vertices, " vertices and ", faces,
                        " faces, more than the remaining ", rest, " bytes can hold (truncated?)");
  }
  for (std::int64_t v = 0; v < vertices; ++v) {
    scan.SkipComments();
    if (scan.at_end()) return "";  // truncated: the reader and the diagnosis handle it
    scan.Record();
  }
  // CGAL also sizes each face from its corner count (the record's first number, cast to
  // size_t) before reading the corners, which must follow in the same record.
  for (std::int64_t f = 0; f < faces; ++f) {
    scan.SkipComments();
    if (scan.at_end()) return "";
    const std::size_t record_start = scan.pos();
    const std::vector<double> numbers = CgalRecordNumbers(scan.Record());
    if (numbers.empty()) return "";  // CGAL stops on a face without numbers
    const double corners = numbers[0];
    const auto listed = static_cast<std::int64_t>(numbers.size()) - 1;
    if (!(corners >= 0.0 && corners < static_cast<double>(numbers.size()))) {
      const std::string announced = std::abs(corners) < 1e18 && corners == std::floor(corners)
                                        ? absl::StrCat(static_cast<std::int64_t>(corners))
                                        : absl::StrCat(corners);
      return absl::StrCat("line ", scan.LineAt(record_start), ": face ", f, " announces ",
                          announced, " corners but lists ", listed);
    }
    // CGAL casts each corner to size_t: undefined for a negative or huge number (UBSan's
    // finding under fuzz_mesh). Indices past the vertices are reported after reading.
    const auto count = static_cast<std::size_t>(corners);
    for (std::size_t k = 1; k <= count; ++k) {
      if (!(numbers[k] >= 0.0 && numbers[k] < 9.2e18)) {
        return absl::StrCat("line ", scan.LineAt(record_start), ": face ", f, " refers to vertex ",
                            numbers[k], ", but the file has ", vertices,
                            " vertices (indices are 0-based)");
      }
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
        // CGAL 5.5 reads a vertex coordinate as double or float and calls through a null
        // pointer for any other type (UBSan under fuzz_mesh).
        const bool coordinate = tokens[2] == "x" || tokens[2] == "y" || tokens[2] == "z";
        if (coordinate && elements.back().name == "vertex" && tokens[1] != "float" &&
            tokens[1] != "double" && tokens[1] != "float32" && tokens[1] != "float64") {
          return bad(absl::StrCat("vertex coordinate ", tokens[2], " has type ", tokens[1],
                                  "; expected float or double"));
        }
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
