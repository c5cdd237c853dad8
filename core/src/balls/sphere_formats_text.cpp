// Line-oriented sphere files: spheretree's `.sph` and CSV `x,y,z,r`.
//
// .sph, as spheretree's SphereTree::loadSphereTree reads it: a first line "levels degree";
// then, level after level, degree^level lines (1 for the root) of "x y z r" followed by up to
// six more numbers (spheretree writes a fifth column, the occupancy, and optionally an
// auxiliary sphere and error decrease). Unused slots have r <= 0; blank lines are skipped.
// spheretree's own flat-set writer (SphereTree::saveSpheres) produces a two-level tree
// "2 N": a bounding sphere, then the N spheres. A "1 N" file would not do: its readers take
// level 0 as exactly one sphere and would stop there.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "balls/sphere_formats.h"

namespace inscribe::internal {
namespace {

absl::Status LineError(std::size_t line, absl::string_view message) {
  return absl::InvalidArgumentError(absl::StrCat("line ", line, ": ", message));
}

absl::string_view WithoutByteOrderMark(absl::string_view bytes) {
  if (bytes.substr(0, 3) == "\xEF\xBB\xBF") bytes.remove_prefix(3);
  return bytes;
}

absl::string_view TrimBlanks(absl::string_view s) {
  const std::size_t first = s.find_first_not_of(" \t");
  if (first == absl::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t") - first + 1);
}

// Whitespace-separated tokens of `line`, at most `max_tokens` + 1 of them (enough to tell that
// there are too many without storing an arbitrarily long line's worth).
std::vector<absl::string_view> SplitBlanks(absl::string_view line, std::size_t max_tokens) {
  std::vector<absl::string_view> tokens;
  std::size_t at = 0;
  while (tokens.size() <= max_tokens) {
    at = line.find_first_not_of(" \t\v\f", at);
    if (at == absl::string_view::npos) break;
    std::size_t end = line.find_first_of(" \t\v\f", at);
    if (end == absl::string_view::npos) end = line.size();
    tokens.push_back(line.substr(at, end - at));
    at = end;
  }
  return tokens;
}

bool ParseInt64(absl::string_view token, std::int64_t* value) {
  const char* end = token.data() + token.size();
  const std::from_chars_result result = std::from_chars(token.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

std::int64_t SaturatingMultiply(std::int64_t a, std::int64_t b) {
  if (a == 0 || b == 0) return 0;
  if (a > std::numeric_limits<std::int64_t>::max() / b) {
    return std::numeric_limits<std::int64_t>::max();
  }
  return a * b;
}

// Where the reader is in the tree: slot `slot` of `slots` in level `level`.
struct SphCursor {
  std::int64_t levels = 0;
  std::int64_t degree = 0;
  std::int64_t level = 0;
  std::int64_t slot = 0;
  std::int64_t slots = 1;

  bool done() const { return level >= levels; }
  void Advance() {
    if (++slot < slots) return;
    slot = 0;
    ++level;
    slots = SaturatingMultiply(slots, degree);
    // With degree 0 every deeper level is empty: the tree ends here.
    if (slots == 0) level = levels;
  }
};

constexpr std::size_t kSphMaxColumns = 10;

}  // namespace

absl::StatusOr<SphereFile> ParseSphSphereFile(absl::string_view bytes, int level) {
  SphereFile file;
  bool have_header = false;
  SphCursor cursor;
  std::int64_t target = 0;
  std::size_t last_line = 0;
  absl::Status status = ForEachLine(
      WithoutByteOrderMark(bytes), [&](std::size_t line, absl::string_view text) -> absl::Status {
        last_line = line;
        const std::vector<absl::string_view> tokens = SplitBlanks(text, kSphMaxColumns);
        if (tokens.empty()) return absl::OkStatus();
        if (!have_header) {
          have_header = true;
          if (tokens.size() != 2 || !ParseInt64(tokens[0], &cursor.levels) ||
              !ParseInt64(tokens[1], &cursor.degree)) {
            return LineError(line, absl::StrCat("expected the header \"levels degree\" (two "
                                                "integers), found ",
                                                QuoteToken(TrimBlanks(text))));
          }
          if (cursor.levels < 1) {
            return LineError(
                line, absl::StrCat("the tree has ", cursor.levels, " levels; it needs at least 1"));
          }
          if (cursor.degree < 0) {
            return LineError(line,
                             absl::StrCat("branching factor ", cursor.degree, " is negative"));
          }
          target = level < 0 ? cursor.levels - 1 : level;
          if (target >= cursor.levels) {
            return LineError(
                line, absl::StrCat("level ", level, " requested, but the tree has ", cursor.levels,
                                   " levels (0 to ", cursor.levels - 1, ")"));
          }
          return absl::OkStatus();
        }
        if (cursor.done()) {
          return LineError(
              line, absl::StrCat("content after the last level of the tree "
                                 "(header: ",
                                 cursor.levels, " levels, branching factor ", cursor.degree, ")"));
        }
        const std::string where = absl::StrCat("level ", cursor.level, " slot ", cursor.slot, ": ");
        if (tokens.size() < 4 || tokens.size() > kSphMaxColumns) {
          return LineError(line, absl::StrCat(where, "expected 4 to ", kSphMaxColumns,
                                              " numbers (x y z r ...), found ",
                                              tokens.size() > kSphMaxColumns
                                                  ? absl::StrCat("more than ", kSphMaxColumns)
                                                  : absl::StrCat(tokens.size())));
        }
        static constexpr const char* kNames[] = {"x", "y", "z", "r"};
        double values[kSphMaxColumns];
        for (std::size_t k = 0; k < tokens.size(); ++k) {
          std::string why;
          if (!ParseDouble(tokens[k], &values[k], &why)) {
            return LineError(line, absl::StrCat(where, "column ", k + 1, ": ", why));
          }
          if (k < 4 && !std::isfinite(values[k])) {
            return LineError(line, absl::StrCat(where, kNames[k], " ", FormatDouble(values[k]),
                                                " is not finite"));
          }
        }
        if (cursor.level == target && values[3] > 0) {
          Sphere sphere;
          sphere.center = Vector3(values[0], values[1], values[2]);
          sphere.radius = values[3];
          file.set.spheres.push_back(sphere);
        }
        cursor.Advance();
        return absl::OkStatus();
      });
  if (!status.ok()) return status;
  if (!have_header) return absl::InvalidArgumentError("file is empty");
  if (!cursor.done()) {
    return absl::InvalidArgumentError(
        absl::StrCat("file ends after line ", last_line, " in level ", cursor.level, " after ",
                     cursor.slot, " of ", cursor.slots, " slots (header: ", cursor.levels,
                     " levels, branching factor ", cursor.degree, "; truncated?)"));
  }
  return file;
}

std::string FormatSphSphereFile(const SphereFile& file) {
  const std::vector<Sphere>& spheres = file.set.spheres;
  std::string out = absl::StrCat("2 ", spheres.size(), "\n");
  // The root: a sphere around all the others (not the smallest one), centred on the middle of
  // their bounding box, its radius padded by a relative 1e-12 against rounding. An empty set
  // gets an unused root (r = -1).
  if (spheres.empty()) {
    absl::StrAppend(&out, "0 0 0 -1 1\n");
    return out;
  }
  Vector3 lo = spheres[0].center, hi = spheres[0].center;
  for (const Sphere& s : spheres) {
    lo = lo.cwiseMin(s.center - Vector3::Constant(s.radius));
    hi = hi.cwiseMax(s.center + Vector3::Constant(s.radius));
  }
  Vector3 centre = 0.5 * lo + 0.5 * hi;
  double radius = 0;
  for (const Sphere& s : spheres) {
    radius = std::max(radius, (s.center - centre).stableNorm() + s.radius);
  }
  radius *= 1 + 1e-12;
  // Near the top of the double range the bounding sphere may not be representable; the root
  // is then written as an unused slot, which readers accept, and the leaves stay exact.
  if (!centre.allFinite() || !std::isfinite(radius)) {
    centre.setZero();
    radius = -1;
  }
  // The fifth column is spheretree's occupancy, 1 for a used slot; its readers ignore it, but
  // its viewer scripts expect five columns.
  const auto line = [&out](const Vector3& c, double r) {
    absl::StrAppend(&out, FormatDouble(c.x()), " ", FormatDouble(c.y()), " ", FormatDouble(c.z()),
                    " ", FormatDouble(r), " 1\n");
  };
  line(centre, radius);
  for (const Sphere& s : spheres) line(s.center, s.radius);
  return out;
}

absl::StatusOr<SphereFile> ParseCsvSphereFile(absl::string_view bytes) {
  SphereFile file;
  bool first_content = true;
  absl::Status status = ForEachLine(
      WithoutByteOrderMark(bytes), [&](std::size_t line, absl::string_view text) -> absl::Status {
        const absl::string_view content = StripCommentAndBlanks(text);
        if (content.empty()) return absl::OkStatus();
        // Split on commas; four fields are needed, a fifth is reason enough to stop counting.
        absl::string_view fields[5];
        std::size_t count = 0;
        std::size_t at = 0;
        while (true) {
          const std::size_t comma = content.find(',', at);
          if (count < 5) fields[count] = TrimBlanks(content.substr(at, comma - at));
          ++count;
          if (comma == absl::string_view::npos) break;
          at = comma + 1;
        }
        if (first_content) {
          first_content = false;
          const auto is = [&](std::size_t k, absl::string_view name) {
            return absl::AsciiStrToLower(fields[k]) == name;
          };
          if (count == 4 && is(0, "x") && is(1, "y") && is(2, "z") &&
              (is(3, "r") || is(3, "radius"))) {
            return absl::OkStatus();
          }
        }
        if (count != 4) {
          const bool blanks = count == 1 && content.find_first_of(" \t") != std::string::npos;
          return LineError(line, absl::StrCat("expected 4 numbers x,y,z,r, found ", count,
                                              blanks ? " (fields are separated by commas)" : ""));
        }
        static constexpr const char* kNames[] = {"x", "y", "z", "r"};
        double values[4];
        for (std::size_t k = 0; k < 4; ++k) {
          std::string why;
          if (!ParseDouble(fields[k], &values[k], &why)) {
            return LineError(line, absl::StrCat(kNames[k], ": ", why));
          }
        }
        Sphere sphere;
        sphere.center = Vector3(values[0], values[1], values[2]);
        sphere.radius = values[3];
        if (absl::Status check = CheckSphere(sphere, file.set.spheres.size()); !check.ok()) {
          return LineError(line, check.message());
        }
        file.set.spheres.push_back(sphere);
        return absl::OkStatus();
      });
  if (!status.ok()) return status;
  return file;
}

std::string FormatCsvSphereFile(const SphereFile& file, bool header) {
  std::string out = header ? "x,y,z,r\n" : "";
  for (const Sphere& s : file.set.spheres) {
    absl::StrAppend(&out, FormatDouble(s.center.x()), ",", FormatDouble(s.center.y()), ",",
                    FormatDouble(s.center.z()), ",", FormatDouble(s.radius), "\n");
  }
  return out;
}

}  // namespace inscribe::internal
