// The repair ladder's steps (MeshRepair): the safe fixes (duplicates, double walls, cracks),
// the remedies a refusal names, the wrap; and the ladder's names and defaults. ValidateMesh
// (mesh_validation.cpp) runs them in order.
#include "solid/mesh_repair.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "mesh/mesh_topology.h"
#include "mesh/vertex_welding.h"
#include "solid/mesh_wrap.h"
#include "tbb/parallel_invoke.h"

namespace inscribe {
namespace internal {

// Appends to the errors a repair can fix the levels above `tried` that would fix them, with
// what they cost.
void AppendRemedies(MeshReport& report, MeshRepair tried) {
  const std::string wrap = absl::StrCat(
      "--repair wrap wraps any mesh in a watertight surface (about alpha/", kWrapOffsetDivisor,
      " outside it; a second or two per 100k triangles), --repair auto tries each level in "
      "turn");
  for (MeshIssue& issue : report.issues) {
    if (issue.severity != Severity::kError) continue;
    std::string remedy;
    if (issue.code == "not_closed") {
      if (tried == MeshRepair::kNone) {
        remedy = "--repair safe welds cracks narrower than 1e-4 of the size, ";
      }
      if (tried != MeshRepair::kFill && tried != MeshRepair::kAuto) {
        absl::StrAppend(&remedy, "--repair fill closes holes (no vertex moves), ");
      }
      absl::StrAppend(&remedy, wrap);
    } else if (issue.code == "non_manifold_edges") {
      if (tried == MeshRepair::kNone) {
        remedy = "--repair safe removes duplicate triangles and walls stored twice, ";
      }
      absl::StrAppend(&remedy, wrap);
    } else if (issue.code == "not_orientable" || issue.code == "no_volume" ||
               issue.code == "inconsistent_orientation") {
      remedy = wrap;
    }
    if (!remedy.empty() && issue.message.find("--repair wrap") == std::string::npos) {
      absl::StrAppend(&issue.message, "; ", remedy);
    }
  }
}

// MeshRepair::kSafe: removes triangles that repeat an earlier one's corners in the same cyclic
// order, then deals with each pair of triangles with the same corners in opposite orders: when
// each of its edges is in four or more triangles, a wall stored once for each of the two
// bodies it separates, both go (the bodies' union is left); otherwise a face listed twice, the
// later copy goes (the orientation fix then turns the kept one as its neighbours need). Kept
// triangles keep their order.
void RemoveDuplicatesAndDoubleWalls(Mesh& mesh, MeshReport& report) {
  // How many triangles use each edge, looked up by (lo, hi).
  const std::vector<EdgeUse> uses = internal::SortedEdgeUses(mesh);
  const EdgeGroups groups = GroupEdges(uses);
  auto edge_uses = [&](std::int32_t a, std::int32_t b) -> std::size_t {
    const std::int32_t lo = std::min(a, b), hi = std::max(a, b);
    const auto it =
        std::lower_bound(groups.ranges.begin(), groups.ranges.end(), std::make_pair(lo, hi),
                         [&](const std::pair<std::size_t, std::size_t>& r,
                             const std::pair<std::int32_t, std::int32_t>& e) {
                           return std::make_pair(uses[r.first].lo, uses[r.first].hi) < e;
                         });
    return it == groups.ranges.end() ? 0 : it->second - it->first;
  };
  // Key: the corners rotated so that the smallest comes first (same cyclic order, same key),
  // and the parity of the order (+1: rising after the smallest corner, -1: falling).
  struct Key {
    std::array<std::int32_t, 3> sorted;
    int parity;
    std::int32_t triangle;
  };
  std::vector<Key> keys;
  keys.reserve(static_cast<std::size_t>(mesh.num_triangles()));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    std::array<std::int32_t, 3> c = {mesh.triangles(t, 0), mesh.triangles(t, 1),
                                     mesh.triangles(t, 2)};
    const int smallest = static_cast<int>(std::min_element(c.begin(), c.end()) - c.begin());
    std::rotate(c.begin(), c.begin() + smallest, c.end());
    const int parity = c[1] < c[2] ? 1 : -1;
    std::array<std::int32_t, 3> sorted = c;
    std::sort(sorted.begin(), sorted.end());
    keys.push_back(Key{sorted, parity, static_cast<std::int32_t>(t)});
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return std::tie(a.sorted, a.triangle) < std::tie(b.sorted, b.triangle);
  });
  std::vector<char> removed(static_cast<std::size_t>(mesh.num_triangles()), 0);
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i + 1;
    while (j < keys.size() && keys[j].sorted == keys[i].sorted) ++j;
    if (j - i > 1) {
      // Within one set of corners: keep the first of each orientation, then cancel one
      // rising against one falling.
      std::vector<std::int32_t> rising, falling;
      for (std::size_t k = i; k < j; ++k) {
        (keys[k].parity > 0 ? rising : falling).push_back(keys[k].triangle);
      }
      for (std::size_t k = 1; k < rising.size(); ++k) removed[rising[k]] = 1;
      for (std::size_t k = 1; k < falling.size(); ++k) removed[falling[k]] = 1;
      report.duplicate_triangles_removed +=
          static_cast<std::int64_t>(rising.size() + falling.size()) - (rising.empty() ? 0 : 1) -
          (falling.empty() ? 0 : 1);
      if (!rising.empty() && !falling.empty()) {
        const std::array<std::int32_t, 3>& c = keys[i].sorted;
        const bool wall =
            edge_uses(c[0], c[1]) >= 4 && edge_uses(c[1], c[2]) >= 4 && edge_uses(c[0], c[2]) >= 4;
        if (wall) {
          removed[rising[0]] = removed[falling[0]] = 1;
          ++report.double_walls_removed;
        } else {
          removed[std::max(rising[0], falling[0])] = 1;
          ++report.duplicate_triangles_removed;
        }
      }
    }
    i = j;
  }
  if (report.duplicate_triangles_removed == 0 && report.double_walls_removed == 0) return;
  Triangles kept(mesh.num_triangles(), 3);
  Eigen::Index row = 0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!removed[static_cast<std::size_t>(t)]) kept.row(row++) = mesh.triangles.row(t);
  }
  kept.conservativeResize(row, 3);
  mesh.triangles = std::move(kept);
  if (report.duplicate_triangles_removed > 0) {
    AddIssue(report, Severity::kFixed, "duplicate_triangles_removed",
             absl::StrCat("removed ",
                          Plural(report.duplicate_triangles_removed, "triangle that repeats",
                                 "triangles that repeat"),
                          " an earlier one's corners"),
             report.duplicate_triangles_removed);
  }
  if (report.double_walls_removed > 0) {
    AddIssue(
        report, Severity::kFixed, "double_walls_removed",
        absl::StrCat("removed ",
                     Plural(report.double_walls_removed, "wall stored twice", "walls stored twice"),
                     " (the same triangle in both orientations, as where two bodies touch): "
                     "the solid is the bodies' union"),
        report.double_walls_removed);
  }
}

namespace {

std::int64_t CountBorderEdges(const Mesh& mesh, std::int64_t* non_manifold) {
  const std::vector<EdgeUse> uses = internal::SortedEdgeUses(mesh);
  const EdgeGroups groups = GroupEdges(uses);
  std::int64_t border = 0;
  *non_manifold = 0;
  for (const auto& [begin, end] : groups.ranges) {
    if (end - begin == 1) ++border;
    if (end - begin > 2) ++*non_manifold;
  }
  return border;
}

}  // namespace

// MeshRepair::kSafe on a mesh with border edges: merges border vertices into border vertices
// within CrackWeldTolerance (internal::WeldVertices on the border vertices only), kept only
// when it closes border edges and makes no more edges non-manifold.
void WeldCracks(Mesh& mesh, MeshReport& report) {
  std::int64_t non_manifold_before = 0;
  const std::int64_t border_before = CountBorderEdges(mesh, &non_manifold_before);
  if (border_before == 0) return;
  const double tolerance = CrackWeldTolerance(mesh);
  report.crack_weld_tolerance = tolerance;
  std::vector<char> on_border(static_cast<std::size_t>(mesh.num_vertices()), 0);
  {
    const std::vector<EdgeUse> uses = internal::SortedEdgeUses(mesh);
    const EdgeGroups groups = GroupEdges(uses);
    for (const auto& [begin, end] : groups.ranges) {
      if (end - begin != 1) continue;
      on_border[static_cast<std::size_t>(uses[begin].lo)] = 1;
      on_border[static_cast<std::size_t>(uses[begin].hi)] = 1;
    }
  }
  Mesh welded = mesh;
  const internal::Weld weld = internal::WeldVertices(welded, tolerance, &on_border);
  if (weld.merged_vertices == 0) return;
  std::int64_t non_manifold_after = 0;
  const std::int64_t border_after = CountBorderEdges(welded, &non_manifold_after);
  if (welded.num_triangles() == 0 || border_after >= border_before ||
      non_manifold_after > non_manifold_before) {
    AddIssue(
        report, Severity::kWarning, "cracks_not_welded",
        absl::StrFormat("welding the border's vertices within %g would %s; not done", tolerance,
                        non_manifold_after > non_manifold_before ? "make edges non-manifold"
                                                                 : "close no border edge"),
        0);
    return;
  }
  report.crack_vertices_welded = weld.merged_vertices;
  report.weld_collapsed_triangles += weld.collapsed_triangles;
  report.weld_moved_within = std::max(report.weld_moved_within, tolerance);
  AddIssue(report, Severity::kFixed, "cracks_welded",
           absl::StrFormat("welded %s across cracks within %g (closing %d of %s)",
                           Plural(weld.merged_vertices, "border vertex", "border vertices"),
                           tolerance, border_before - border_after,
                           Plural(border_before, "border edge", "border edges")),
           weld.merged_vertices);
  mesh = std::move(welded);
}

}  // namespace internal

const char* MeshRepairName(MeshRepair repair) {
  switch (repair) {
    case MeshRepair::kNone:
      return "none";
    case MeshRepair::kSafe:
      return "safe";
    case MeshRepair::kFill:
      return "fill";
    case MeshRepair::kWrap:
      return "wrap";
    case MeshRepair::kAuto:
      return "auto";
  }
  return "unknown";
}

absl::StatusOr<MeshRepair> ParseMeshRepair(const std::string& name) {
  for (MeshRepair r : {MeshRepair::kNone, MeshRepair::kSafe, MeshRepair::kFill, MeshRepair::kWrap,
                       MeshRepair::kAuto}) {
    if (name == MeshRepairName(r)) return r;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown mesh repair '", name, "': use none, safe, fill, wrap or auto"));
}

double CrackWeldTolerance(const Mesh& mesh) {
  const BoundingBox box = ComputeBoundingBox(mesh.vertices);
  const double diagonal = (box.max - box.min).norm();
  std::vector<double> lengths;
  const std::vector<internal::EdgeUse> uses = internal::SortedEdgeUses(mesh);
  const internal::EdgeGroups groups = internal::GroupEdges(uses);
  lengths.reserve(groups.ranges.size());
  for (const auto& [begin, end] : groups.ranges) {
    if (end - begin < 2) continue;
    lengths.push_back(
        (mesh.vertices.row(uses[begin].lo) - mesh.vertices.row(uses[begin].hi)).norm());
  }
  double tolerance = 1e-4 * diagonal;
  if (!lengths.empty()) {
    auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
    std::nth_element(lengths.begin(), middle, lengths.end());
    tolerance = std::min(tolerance, 0.25 * *middle);
  }
  return std::max(tolerance, 1e-9 * diagonal);
}

double DefaultWrapAlpha(double diagonal) { return diagonal / kWrapAlphaDivisor; }
double DefaultWrapOffset(double alpha) { return alpha / kWrapOffsetDivisor; }

namespace internal {

// The wrap of `soup` (the mesh `input` came from, once welded) replaces input's mesh; the
// report keeps input's counts, turns its errors into warnings ("before the wrap: ...") and
// takes the wrap's shape figures. An error "wrap_failed" when the wrap cannot be made or used,
// or does not provably enclose the soup (CheckWrapEncloses).
WrapParameters WrapParametersFor(const Mesh& soup, const RepairOptions& repair) {
  WrapParameters p;
  const BoundingBox box = ComputeBoundingBox(soup.vertices);
  p.diagonal = (box.max - box.min).norm();
  p.alpha = repair.wrap_alpha > 0.0 ? repair.wrap_alpha : DefaultWrapAlpha(p.diagonal);
  p.offset = repair.wrap_offset > 0.0 ? repair.wrap_offset : DefaultWrapOffset(p.alpha);
  return p;
}

absl::StatusOr<Mesh> ComputeWrap(const Mesh& soup, const WrapParameters& parameters) {
  if (!(parameters.diagonal > 0.0)) {
    return absl::FailedPreconditionError("the mesh's vertices are all at one point");
  }
  return internal::AlphaWrap(soup, parameters.alpha, parameters.offset);
}

ValidatedMesh WrapSoup(ValidatedMesh input, const Mesh& soup, const ValidateOptions& options,
                       std::optional<absl::StatusOr<Mesh>> computed) {
  MeshReport& report = input.report;
  auto fail = [&](const std::string& why) {
    AddIssue(report, Severity::kError, "wrap_failed", absl::StrCat("the wrap failed: ", why), 0);
    return std::move(input);
  };
  const WrapParameters parameters = WrapParametersFor(soup, options.repair);
  const double alpha = parameters.alpha, offset = parameters.offset;
  absl::StatusOr<Mesh> wrap = computed ? *std::move(computed) : ComputeWrap(soup, parameters);
  if (!wrap.ok()) return fail(std::string(wrap.status().message()));
  ValidateOptions plain;
  plain.repair.level = MeshRepair::kNone;
  plain.check_self_intersections = options.check_self_intersections;
  ValidatedMesh wrapped = ValidateMesh(*std::move(wrap), plain);
  if (!wrapped.report.usable()) {
    return fail(
        absl::StrCat("the wrap is not a usable solid (", wrapped.report.first_error(), ")"));
  }
  // The proof of enclosure and the reach bound read the same two meshes: side by side.
  std::string encloses_not;
  double reach = 0.0;
  tbb::parallel_invoke([&] { encloses_not = internal::CheckWrapEncloses(wrapped.mesh, soup); },
                       [&] { reach = internal::WrapReachBound(wrapped.mesh, soup); });
  if (!encloses_not.empty()) {
    return fail(absl::StrCat("it does not enclose the input (", encloses_not,
                             "); a larger --wrap-offset may help"));
  }
  MeshReport out = std::move(report);
  // A patch tried before the wrap is not in the returned mesh.
  out.holes_filled = 0;
  out.hole_triangles_added = 0;
  out.issues.erase(std::remove_if(out.issues.begin(), out.issues.end(),
                                  [](const MeshIssue& i) { return i.code == "holes_filled"; }),
                   out.issues.end());
  for (MeshIssue& issue : out.issues) {
    if (issue.severity != Severity::kError) continue;
    issue.severity = Severity::kWarning;
    issue.message = absl::StrCat("before the wrap: ", issue.message);
  }
  const MeshReport& w = wrapped.report;
  out.components = w.components;
  out.flipped_triangles = w.flipped_triangles;
  out.flat_shells = w.flat_shells;
  out.self_intersections_checked = w.self_intersections_checked;
  out.self_intersecting_pairs = w.self_intersecting_pairs;
  out.volume = w.volume;
  out.bbox = w.bbox;
  out.wrapped = true;
  out.wrap_alpha = alpha;
  out.wrap_offset = offset;
  out.wrap_input_triangles = soup.num_triangles();
  out.wrap_triangles = wrapped.mesh.num_triangles();
  out.wrap_reach = reach;
  out.issues.erase(std::remove_if(out.issues.begin(), out.issues.end(),
                                  [](const MeshIssue& i) {
                                    return i.code == "self_intersections_not_checked" ||
                                           i.code == "self_intersections" ||
                                           i.code == "flat_shells";
                                  }),
                   out.issues.end());
  for (const MeshIssue& issue : w.notices()) {
    out.issues.push_back(issue);
    out.issues.back().message = absl::StrCat("the wrap: ", issue.message);
  }
  AddIssue(out, Severity::kFixed, "wrapped",
           absl::StrFormat("wrapped the %s in a watertight surface of %s (alpha %g, offset %g): "
                           "it encloses every input triangle (checked) and lies within %g of "
                           "them; results are about the wrap",
                           Plural(soup.num_triangles(), "triangle", "triangles"),
                           Plural(out.wrap_triangles, "triangle", "triangles"), alpha, offset,
                           out.wrap_reach),
           out.wrap_triangles);
  std::stable_sort(out.issues.begin(), out.issues.end(),
                   [](const MeshIssue& a, const MeshIssue& b) {
                     return static_cast<int>(a.severity) < static_cast<int>(b.severity);
                   });
  return ValidatedMesh{std::move(wrapped.mesh), std::move(out)};
}

}  // namespace internal
}  // namespace inscribe
