// Private to sphere_io.cpp and sphere_formats_*.cpp: one parser / formatter per format and the
// small pieces they share. Messages returned here carry no file name; the public entry points
// prefix it.
#pragma once

#include <cstddef>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "base/format_double.h"
#include "inscribe/balls/sphere_io.h"

namespace inscribe::internal {

// Parses all of `token` as a double (an optional leading '+' is accepted; "nan" and "inf" are
// parsed, finiteness is the caller's check). On failure returns false and sets `why`.
bool ParseDouble(absl::string_view token, double* value, std::string* why);

// `token` quoted for an error message: at most 24 bytes, non-printable bytes as \xNN.
std::string QuoteToken(absl::string_view token);

// What every writer requires: CheckSphere for all spheres, contacts empty or one per sphere
// with triangle >= 0 and finite weights, mesh_sha256 empty or well formed.
absl::Status CheckSphereSetForWrite(const SphereFile& file);

// OK when `hash` is empty or "sha256:" followed by 64 lowercase hex digits.
absl::Status CheckMeshSha256(absl::string_view hash);

// Splits `bytes` into lines without their "\n" or "\r\n". Calls `visit(line_number, line)`
// (1-based) for each line until it returns a non-OK status, which is then returned.
template <typename Visit>
absl::Status ForEachLine(absl::string_view bytes, Visit&& visit) {
  std::size_t number = 0;
  while (!bytes.empty()) {
    const std::size_t end = bytes.find('\n');
    absl::string_view line = bytes.substr(0, end);
    bytes = end == absl::string_view::npos ? absl::string_view() : bytes.substr(end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (absl::Status status = visit(++number, line); !status.ok()) return status;
  }
  return absl::OkStatus();
}

// `line` without a trailing "# comment" and surrounding spaces / tabs.
absl::string_view StripCommentAndBlanks(absl::string_view line);

// Per-format parsers and formatters. Formatters assume CheckSphereSetForWrite passed.
absl::StatusOr<SphereFile> ParseJsonSphereFile(absl::string_view bytes);
absl::StatusOr<std::string> FormatJsonSphereFile(const SphereFile& file);

absl::StatusOr<SphereFile> ParseSphSphereFile(absl::string_view bytes, int level);
std::string FormatSphSphereFile(const SphereFile& file);

absl::StatusOr<SphereFile> ParseCsvSphereFile(absl::string_view bytes);
std::string FormatCsvSphereFile(const SphereFile& file, bool header);

std::string FormatObjSphereFile(const SphereFile& file, int subdivision);

// kYaml: one link of a cuRobo collision_spheres block (see SphereFileReadOptions::yaml_link);
// the writer expects a link name FormatCuroboYaml accepts.
absl::StatusOr<SphereFile> ParseYamlSphereFile(absl::string_view bytes, const std::string& link);
std::string FormatYamlSphereFile(const SphereFile& file, const std::string& link_name);

}  // namespace inscribe::internal
