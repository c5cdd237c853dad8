#include "cover_file_fields.h"

#include <cstdint>
#include <type_traits>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"

namespace inscribe::cli {
namespace {

// The value named `name`, or nullptr.
const ScalarValue* Find(const NamedValues& stats, const char* name) {
  for (const auto& [key, value] : stats) {
    if (key == name) return &value;
  }
  return nullptr;
}

// `value`, stat `name`, as a T (an int64 stat also reads as a double), or INVALID_ARGUMENT.
template <typename T>
absl::StatusOr<T> As(const ScalarValue& value, const char* name) {
  if (const T* held = std::get_if<T>(&value)) return *held;
  if constexpr (std::is_same_v<T, double>) {
    if (const std::int64_t* whole = std::get_if<std::int64_t>(&value)) {
      return static_cast<double>(*whole);
    }
  }
  return absl::InvalidArgumentError(absl::StrCat("stats.", name, " has the wrong type"));
}

// The value named `name` as a T, or INVALID_ARGUMENT when it is missing or of another type.
template <typename T>
absl::StatusOr<T> Stat(const NamedValues& stats, const char* name) {
  const ScalarValue* value = Find(stats, name);
  if (value == nullptr) {
    return absl::InvalidArgumentError(absl::StrCat("a cover file needs stats.", name));
  }
  return As<T>(*value, name);
}

// The string named `name`, "" when the file has none (a certificate that names nothing, which
// CheckCoverCertificateBinding refuses), or INVALID_ARGUMENT for another type.
absl::StatusOr<std::string> OptionalString(const NamedValues& stats, const char* name) {
  const ScalarValue* value = Find(stats, name);
  if (value == nullptr) return std::string();
  return As<std::string>(*value, name);
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
          {"certify_seconds", c.seconds},
          {"certified_mesh_sha256", c.mesh_sha256},
          {"certified_spheres_sha256", c.spheres_sha256}};
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
  absl::StatusOr<std::string> mesh = OptionalString(file.stats, "certified_mesh_sha256");
  absl::StatusOr<std::string> spheres = OptionalString(file.stats, "certified_spheres_sha256");
  for (const absl::Status& s :
       {certified.status(), delta.status(), resolution.status(), cells.status(), in_sphere.status(),
        outside.status(), failed.status(), mesh.status(), spheres.status()}) {
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
  c.mesh_sha256 = *std::move(mesh);
  c.spheres_sha256 = *std::move(spheres);
  return c;
}

absl::StatusOr<std::optional<CoverCertificate>> UsableCoverCertificate(
    const SphereFile& file, const std::string& path, absl::string_view mesh_sha256) {
  absl::StatusOr<std::optional<CoverCertificate>> recorded = RecordedCoverCertificate(file);
  if (!recorded.ok()) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", recorded.status().message()));
  }
  if (!recorded->has_value()) return std::nullopt;
  if (absl::Status bound = CheckCoverCertificateBinding(**recorded, file.set.spheres, mesh_sha256);
      !bound.ok()) {
    return absl::FailedPreconditionError(absl::StrCat(path, ": ", bound.message()));
  }
  if (!(*recorded)->certified) {
    return absl::FailedPreconditionError(
        absl::StrCat(path, " records a certificate that does not certify it"));
  }
  return recorded;
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
