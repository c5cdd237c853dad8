// Sphere-set files: format names, dispatch, the checks every writer shares, and the file
// system side (reading whole files, atomic replacement). The formats themselves live in
// sphere_formats_json.cpp (JSON), sphere_formats_text.cpp (.sph, CSV) and
// sphere_formats_view.cpp (OBJ, YAML).
#include "inscribe/balls/sphere_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <system_error>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "balls/sphere_formats.h"
#include "inscribe/base/atomic_file.h"

namespace inscribe {
namespace internal {

bool ParseDouble(absl::string_view token, double* value, std::string* why) {
  absl::string_view digits = token;
  if (digits.size() > 1 && digits[0] == '+' && digits[1] != '-' && digits[1] != '+') {
    digits.remove_prefix(1);
  }
  const char* end = digits.data() + digits.size();
  const std::from_chars_result result = std::from_chars(digits.data(), end, *value);
  if (result.ec == std::errc::result_out_of_range) {
    *why = absl::StrCat(QuoteToken(token), " is out of the range of a double");
    return false;
  }
  if (result.ec != std::errc() || result.ptr != end) {
    *why = token.empty() ? std::string("empty field")
                         : absl::StrCat(QuoteToken(token), " is not a number");
    return false;
  }
  return true;
}

std::string QuoteToken(absl::string_view token) {
  constexpr std::size_t kMaxBytes = 24;
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMaxBytes; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\' && c != '\'') {
      out.push_back(static_cast<char>(c));
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out.push_back(kHex[c >> 4]);
      out.push_back(kHex[c & 15]);
    }
  }
  if (token.size() > kMaxBytes) out += "...";
  out += "'";
  return out;
}

absl::Status CheckMeshSha256(absl::string_view hash) {
  if (hash.empty()) return absl::OkStatus();
  constexpr absl::string_view kPrefix = "sha256:";
  bool ok = hash.size() == kPrefix.size() + 64 && hash.substr(0, kPrefix.size()) == kPrefix;
  for (std::size_t i = kPrefix.size(); ok && i < hash.size(); ++i) {
    const char c = hash[i];
    ok = (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
  }
  if (!ok) {
    return absl::InvalidArgumentError(
        absl::StrCat("mesh_sha256 ", QuoteToken(hash),
                     " is not \"sha256:\" followed by 64 lowercase hex digits"));
  }
  return absl::OkStatus();
}

absl::Status CheckSphereSetForWrite(const SphereFile& file) {
  const SphereSet& set = file.set;
  for (std::size_t i = 0; i < set.spheres.size(); ++i) {
    if (absl::Status status = CheckSphere(set.spheres[i], i); !status.ok()) return status;
  }
  if (set.has_contacts() && set.contacts.size() != set.spheres.size()) {
    return absl::InvalidArgumentError(absl::StrCat(set.contacts.size(), " contacts for ",
                                                   set.spheres.size(),
                                                   " spheres (need one per sphere, or none)"));
  }
  for (std::size_t i = 0; i < set.contacts.size(); ++i) {
    const SurfaceContact& contact = set.contacts[i];
    if (contact.triangle < 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("contact ", i, ": triangle ", contact.triangle, " is negative"));
    }
    if (!contact.barycentric.allFinite()) {
      return absl::InvalidArgumentError(
          absl::StrCat("contact ", i, ": barycentric weights are not finite"));
    }
  }
  if (!file.protrusions.empty() && file.protrusions.size() != set.spheres.size()) {
    return absl::InvalidArgumentError(absl::StrCat(file.protrusions.size(), " protrusions for ",
                                                   set.spheres.size(),
                                                   " spheres (need one per sphere, or none)"));
  }
  for (std::size_t i = 0; i < file.protrusions.size(); ++i) {
    if (!std::isfinite(file.protrusions[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("protrusion ", i, ": ", file.protrusions[i], " is not finite"));
    }
  }
  return CheckMeshSha256(file.mesh_sha256);
}

absl::string_view StripCommentAndBlanks(absl::string_view line) {
  line = line.substr(0, line.find('#'));
  const std::size_t first = line.find_first_not_of(" \t");
  if (first == absl::string_view::npos) return {};
  const std::size_t last = line.find_last_not_of(" \t");
  return line.substr(first, last - first + 1);
}

}  // namespace internal

namespace {

namespace fs = std::filesystem;

std::string LowercaseAscii(absl::string_view s) { return absl::AsciiStrToLower(s); }

absl::Status Prefixed(const absl::Status& status, absl::string_view what) {
  return absl::Status(status.code(), absl::StrCat(what, ": ", status.message()));
}

// The format of a file whose extension says nothing: JSON starts with '{'; YAML's first
// meaningful line is a key ending in ':' (collision_spheres:, robot_cfg:); a .sph file's first
// line is two integers; anything else with a comma on its first meaningful line is CSV.
absl::StatusOr<SphereFileFormat> SniffFormat(absl::string_view bytes) {
  absl::string_view first;
  (void)internal::ForEachLine(bytes, [&](std::size_t, absl::string_view line) {
    first = internal::StripCommentAndBlanks(line);
    // Stop (with any non-OK status) at the first line with content.
    return first.empty() ? absl::OkStatus() : absl::CancelledError();
  });
  if (first.size() >= 3 && first.substr(0, 3) == "\xEF\xBB\xBF") first.remove_prefix(3);
  if (!first.empty() && first[0] == '{') return SphereFileFormat::kJson;
  if (first == "---" || (!first.empty() && first.back() == ':')) return SphereFileFormat::kYaml;
  if (first.find(',') != absl::string_view::npos) return SphereFileFormat::kCsv;
  const bool only_digits_and_blanks =
      !first.empty() && std::all_of(first.begin(), first.end(), [](char c) {
        return (c >= '0' && c <= '9') || c == ' ' || c == '\t';
      });
  const std::size_t gap = first.find_first_of(" \t");
  if (only_digits_and_blanks && gap != absl::string_view::npos &&
      first.find_first_not_of(" \t", gap) != absl::string_view::npos) {
    return SphereFileFormat::kSph;
  }
  return absl::InvalidArgumentError(
      "cannot tell the sphere file format from the extension or the contents (expected json, "
      "yaml, sph or csv)");
}

// Messages without a prefix; the callers add "<format> data" or the path.
absl::StatusOr<SphereFile> ParseReadable(absl::string_view bytes, SphereFileFormat format,
                                         const SphereFileReadOptions& options) {
  switch (format) {
    case SphereFileFormat::kJson:
      return internal::ParseJsonSphereFile(bytes);
    case SphereFileFormat::kSph:
      return internal::ParseSphSphereFile(bytes, options.sph_level);
    case SphereFileFormat::kCsv:
      return internal::ParseCsvSphereFile(bytes);
    case SphereFileFormat::kYaml:
      return internal::ParseYamlSphereFile(bytes, options.yaml_link);
    case SphereFileFormat::kObj:
      break;
  }
  return absl::InvalidArgumentError(
      absl::StrCat(SphereFileFormatName(format), " sphere files are write-only"));
}

}  // namespace

absl::StatusOr<SphereFileFormat> ParseSphereFileFormat(absl::string_view name) {
  const std::string lower = LowercaseAscii(name);
  if (lower == "json") return SphereFileFormat::kJson;
  if (lower == "sph") return SphereFileFormat::kSph;
  if (lower == "csv") return SphereFileFormat::kCsv;
  if (lower == "obj") return SphereFileFormat::kObj;
  if (lower == "yaml" || lower == "yml") return SphereFileFormat::kYaml;
  return absl::InvalidArgumentError(absl::StrCat("unknown sphere file format ",
                                                 internal::QuoteToken(name),
                                                 " (expected json, sph, csv, obj or yaml)"));
}

absl::string_view SphereFileFormatName(SphereFileFormat format) {
  switch (format) {
    case SphereFileFormat::kJson:
      return "json";
    case SphereFileFormat::kSph:
      return "sph";
    case SphereFileFormat::kCsv:
      return "csv";
    case SphereFileFormat::kObj:
      return "obj";
    case SphereFileFormat::kYaml:
      return "yaml";
  }
  return "unknown";
}

absl::StatusOr<SphereFileFormat> SphereFileFormatFromPath(const std::string& path) {
  std::string ext = LowercaseAscii(fs::path(path).extension().string());
  if (!ext.empty()) ext.erase(0, 1);
  absl::StatusOr<SphereFileFormat> format = ParseSphereFileFormat(ext);
  if (!format.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": unknown sphere file extension '", ext.empty() ? "(none)" : ext,
                     "' (expected .json, .sph, .csv, .obj, .yaml or .yml)"));
  }
  return format;
}

bool IsReadableSphereFileFormat(SphereFileFormat format) {
  return format != SphereFileFormat::kObj;
}

absl::StatusOr<std::string> FormatSphereFile(const SphereFile& file, SphereFileFormat format,
                                             const SphereFileWriteOptions& options) {
  if (absl::Status status = internal::CheckSphereSetForWrite(file); !status.ok()) return status;
  switch (format) {
    case SphereFileFormat::kJson:
      return internal::FormatJsonSphereFile(file);
    case SphereFileFormat::kSph:
      return internal::FormatSphSphereFile(file);
    case SphereFileFormat::kCsv:
      return internal::FormatCsvSphereFile(file, options.csv_header);
    case SphereFileFormat::kObj:
      if (options.obj_subdivision < 0 || options.obj_subdivision > 5) {
        return absl::InvalidArgumentError(
            absl::StrCat("obj subdivision level ", options.obj_subdivision, " is outside 0..5"));
      }
      return internal::FormatObjSphereFile(file, options.obj_subdivision);
    case SphereFileFormat::kYaml:
      if (options.yaml_link_name.empty() ||
          !std::all_of(options.yaml_link_name.begin(), options.yaml_link_name.end(), [](char c) {
            return absl::ascii_isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' ||
                   c == '.' || c == '/';
          })) {
        return absl::InvalidArgumentError(
            absl::StrCat("yaml link name ", internal::QuoteToken(options.yaml_link_name),
                         " is not a non-empty run of letters, digits and _ - . /"));
      }
      return internal::FormatYamlSphereFile(file, options.yaml_link_name);
  }
  return absl::InvalidArgumentError("unknown sphere file format");
}

absl::StatusOr<SphereFile> ParseSphereFile(absl::string_view bytes, SphereFileFormat format,
                                           const SphereFileReadOptions& options) {
  absl::StatusOr<SphereFile> file = ParseReadable(bytes, format, options);
  if (!file.ok()) {
    return Prefixed(file.status(), absl::StrCat(SphereFileFormatName(format), " data"));
  }
  return file;
}

absl::StatusOr<SphereFile> ScaledSphereFile(SphereFile file, double scale) {
  if (!(std::isfinite(scale) && scale > 0.0)) {
    return absl::InvalidArgumentError(
        absl::StrCat("the scale must be a finite number > 0, got ", scale));
  }
  for (std::size_t i = 0; i < file.set.spheres.size(); ++i) {
    Sphere& sphere = file.set.spheres[i];
    sphere.center *= scale;
    sphere.radius *= scale;
    if (!sphere.center.allFinite() || !std::isfinite(sphere.radius) || !(sphere.radius > 0.0)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "sphere ", i, " scaled by ", scale, " is ",
          std::isfinite(sphere.radius) && sphere.center.allFinite() ? "of radius 0" : "not finite",
          ": choose a scale within the range of doubles"));
    }
  }
  file.mesh_sha256.clear();
  file.params.clear();
  file.stats.clear();
  file.protrusions.clear();
  return file;
}

absl::StatusOr<SphereFile> ReadSphereFile(const std::string& path,
                                          const SphereFileReadOptions& options) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (ec || !fs::exists(status)) {
    return absl::NotFoundError(absl::StrCat(path, ": no such file"));
  }
  if (fs::is_directory(status)) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": is a directory, not a sphere file"));
  }
  std::optional<SphereFileFormat> format = options.format;
  if (!format.has_value()) {
    absl::StatusOr<SphereFileFormat> by_extension = SphereFileFormatFromPath(path);
    if (by_extension.ok()) format = *by_extension;
  }
  if (format.has_value() && !IsReadableSphereFileFormat(*format)) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": ", SphereFileFormatName(*format), " sphere files are write-only"));
  }
  std::ifstream in(path, std::ios::in | std::ios::binary);
  if (!in) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": cannot open (", std::strerror(errno), ")"));
  }
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return absl::InvalidArgumentError(absl::StrCat(path, ": read error"));
  const std::string bytes = std::move(contents).str();
  if (!format.has_value()) {
    absl::StatusOr<SphereFileFormat> sniffed = SniffFormat(bytes);
    if (!sniffed.ok()) return Prefixed(sniffed.status(), path);
    format = *sniffed;
  }
  absl::StatusOr<SphereFile> file = ParseReadable(bytes, *format, options);
  if (!file.ok()) return Prefixed(file.status(), path);
  return file;
}

absl::Status WriteSphereFile(const std::string& path, const SphereFile& file,
                             const SphereFileWriteOptions& options) {
  std::optional<SphereFileFormat> format = options.format;
  if (!format.has_value()) {
    absl::StatusOr<SphereFileFormat> by_extension = SphereFileFormatFromPath(path);
    if (!by_extension.ok()) return by_extension.status();
    format = *by_extension;
  }
  absl::StatusOr<std::string> bytes = FormatSphereFile(file, *format, options);
  if (!bytes.ok()) return Prefixed(bytes.status(), path);

  return WriteFileAtomically(path, *bytes);
}

}  // namespace inscribe
