// The repair ladder's steps, private to core: ValidateMesh (mesh_validation.cpp) runs them;
// mesh_repair.cpp holds them. Each adds what it did to the report as MeshIssues.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::internal {

inline void AddIssue(MeshReport& report, Severity severity, std::string code, std::string message,
                     std::int64_t count) {
  report.issues.push_back(MeshIssue{severity, std::move(code), std::move(message), count});
}

inline std::string Plural(std::int64_t n, const char* singular, const char* plural) {
  return absl::StrCat(n, " ", n == 1 ? singular : plural);
}

// Appends to the errors a repair can fix the levels above `tried` that would fix them, with
// what they cost.
void AppendRemedies(MeshReport& report, MeshRepair tried);

// MeshRepair::kSafe: exact duplicate triangles and walls stored twice (see mesh_repair.cpp).
void RemoveDuplicatesAndDoubleWalls(Mesh& mesh, MeshReport& report);

// MeshRepair::kSafe on a mesh with border edges: border vertices welded within
// CrackWeldTolerance, kept only when it closes border edges and makes no edge non-manifold.
void WeldCracks(Mesh& mesh, MeshReport& report);

// The wrap's alpha and offset for `soup` (RepairOptions' when given, else the defaults from
// its bounding box's diagonal), and that diagonal.
struct WrapParameters {
  double alpha = 0.0;
  double offset = 0.0;
  double diagonal = 0.0;
};
WrapParameters WrapParametersFor(const Mesh& soup, const RepairOptions& repair);

// CGAL's alpha wrap of `soup` with `parameters` (AlphaWrap), or why it cannot be made. The
// part of WrapSoup that needs nothing of the validation, so that --repair wrap can run it
// beside the rest of the input's validation.
absl::StatusOr<Mesh> ComputeWrap(const Mesh& soup, const WrapParameters& parameters);

// The wrap of `soup` (the mesh `input` came from, once welded) replaces input's mesh; the
// report keeps input's counts, turns its errors into warnings ("before the wrap: ...") and
// takes the wrap's shape figures. An error "wrap_failed" when the wrap cannot be made or used,
// or does not provably enclose the soup (CheckWrapEncloses). `computed`: ComputeWrap(soup, its
// WrapParametersFor) when already made, else made here.
ValidatedMesh WrapSoup(ValidatedMesh input, const Mesh& soup, const ValidateOptions& options,
                       std::optional<absl::StatusOr<Mesh>> computed = std::nullopt);

}  // namespace inscribe::internal
