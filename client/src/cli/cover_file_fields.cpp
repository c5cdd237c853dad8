#include "cover_file_fields.h"

#include <cstdint>
#include <type_traits>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inscribe::cli {
namespace {

// The value named `name` as a T (an int64 stat also reads as a double), or INVALID_ARGUMENT.
template <typename T>
absl::StatusOr<T> Stat(const NamedValues& stats, const char* name) {
  for (const auto& [key, value] : stats) {
    if (key != name) continue;
    if (const T* held = std::get_if<T>(&value)) return *held;
    if constexpr (std::is_same_v<T, double>) {
      if (const std::int64_t* whole = std::get_if<std::int64_t>(&value)) {
        return static_cast<double>(*whole);
      }
    }
    return absl::InvalidArgumentError(absl::StrCat("stats.", name, " has the wrong type"));
  }
  return absl::InvalidArgumentError(absl::StrCat("a cover file needs stats.", name));
}

}  // namespace

NamedValues CoverCertificateStats(const CoverCertificate& c) {
  return {{"delta", c.delta},
          {"certified", c.certified},
          {"certificate_resolution", c.resolution},
          {"certificate_cells", c.cells},
          {"cells_in_sphere", c.cells_in_sphere},
          {"cells_outside", c.cells_outside},
          {"failed_cells", c.failed_cells},
          {"certify_seconds", c.seconds}};
}

std::string RecordedKind(const SphereFile& file) {
  for (const auto& [key, value] : file.params) {
    if (key != kKindParam) continue;
    if (const std::string* kind = std::get_if<std::string>(&value)) return *kind;
  }
  return "";
}

absl::StatusOr<std::optional<CoverCertificate>> RecordedCoverCertificate(const SphereFile& file) {
  if (RecordedKind(file) != SphereSetKindName(SphereSetKind::kCover)) return std::nullopt;
  CoverCertificate c;
  absl::StatusOr<bool> certified = Stat<bool>(file.stats, "certified");
  absl::StatusOr<double> delta = Stat<double>(file.stats, "delta");
  absl::StatusOr<double> resolution = Stat<double>(file.stats, "certificate_resolution");
  absl::StatusOr<std::int64_t> cells = Stat<std::int64_t>(file.stats, "certificate_cells");
  absl::StatusOr<std::int64_t> in_sphere = Stat<std::int64_t>(file.stats, "cells_in_sphere");
  absl::StatusOr<std::int64_t> outside = Stat<std::int64_t>(file.stats, "cells_outside");
  absl::StatusOr<std::int64_t> failed = Stat<std::int64_t>(file.stats, "failed_cells");
  for (const absl::Status& s :
       {certified.status(), delta.status(), resolution.status(), cells.status(), in_sphere.status(),
        outside.status(), failed.status()}) {
    if (!s.ok()) return s;
  }
  c.certified = *certified;
  c.delta = *delta;
  c.resolution = *resolution;
  c.cells = *cells;
  c.cells_in_sphere = *in_sphere;
  c.cells_outside = *outside;
  c.failed_cells = *failed;
  c.protrusions = file.protrusions;
  return c;
}

std::string CoverVerdict(const CoverCertificate& c) {
  if (c.certified) return "certified: every point of the solid is in a sphere";
  if (c.uncovered_point) {
    const Vector3& p = *c.uncovered_point;
    return absl::StrFormat(
        "NOT certified: the point (%.10g %.10g %.10g), %.6g deep in the solid, is %.6g from the "
        "nearest sphere",
        p.x(), p.y(), p.z(), c.uncovered_depth, c.uncovered_gap);
  }
  return absl::StrFormat(
      "NOT certified: %d cells of side %.6g near the boundary are in no single sphere (no "
      "uncovered point found; a finer resolution may settle them)",
      c.failed_cells, c.resolution);
}

}  // namespace inscribe::cli
