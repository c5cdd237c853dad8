#include "inscribe/solid/mesh_validation.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "mesh/hole_filling.h"
#include "mesh/mesh_topology.h"
#include "mesh/vertex_welding.h"
#include "solid/mesh_orientation.h"
#include "solid/mesh_repair.h"
#include "solid/self_intersections.h"
#include "tbb/task_group.h"

namespace inscribe {
namespace {

using internal::AddIssue;
using internal::DisjointSets;
using internal::EdgeGroups;
using internal::EdgeUse;
using internal::GroupEdges;
using internal::Plural;

// Checks that every coordinate is finite and every index names a vertex. Returns false when
// the mesh cannot be examined further.
bool CheckIndicesAndCoordinates(const Mesh& mesh, MeshReport& report) {
  std::int64_t first_bad_vertex = -1;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    if (!mesh.vertices.row(v).allFinite()) {
      if (report.non_finite_vertices++ == 0) first_bad_vertex = v;
    }
  }
  if (report.non_finite_vertices > 0) {
    const auto row = mesh.vertices.row(first_bad_vertex);
    AddIssue(report, Severity::kError, "non_finite_coordinates",
             absl::StrFormat("%s non-finite (NaN or infinite) coordinates (first: vertex %d = "
                             "(%g, %g, %g))",
                             Plural(report.non_finite_vertices, "vertex has", "vertices have"),
                             first_bad_vertex, row(0), row(1), row(2)),
             report.non_finite_vertices);
  }
  std::int64_t first_triangle = -1, first_corner = -1, first_value = 0;
  const auto nv = mesh.num_vertices();
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = mesh.triangles(t, k);
      if (v < 0 || v >= nv) {
        if (report.out_of_range_indices++ == 0) {
          first_triangle = t;
          first_corner = k;
          first_value = v;
        }
      }
    }
  }
  if (report.out_of_range_indices > 0) {
    AddIssue(report, Severity::kError, "index_out_of_range",
             absl::StrCat(Plural(report.out_of_range_indices, "triangle corner refers",
                                 "triangle corners refer"),
                          " to no vertex (first: triangle ", first_triangle, " corner ",
                          first_corner, " = ", first_value, "; valid indices are 0..", nv - 1, ")"),
             report.out_of_range_indices);
  }
  if (mesh.num_triangles() == 0) {
    AddIssue(report, Severity::kError, "no_triangles", "mesh has no triangles", 0);
  }
  return report.non_finite_vertices == 0 && report.out_of_range_indices == 0 &&
         mesh.num_triangles() > 0;
}

void CheckDegenerateAndDuplicate(const Mesh& mesh, MeshReport& report) {
  std::int64_t repeated = 0, first_repeated = -1;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t) && repeated++ == 0) first_repeated = t;
  }
  std::int64_t first_collinear = -1;
  const std::int64_t collinear = internal::CountCollinearTriangles(mesh, &first_collinear);
  report.degenerate_triangles = repeated + collinear;
  if (report.degenerate_triangles > 0) {
    const std::int64_t first =
        first_repeated >= 0 && (first_collinear < 0 || first_repeated < first_collinear)
            ? first_repeated
            : first_collinear;
    AddIssue(report, Severity::kWarning, "degenerate_triangles",
             absl::StrCat(Plural(report.degenerate_triangles, "triangle has", "triangles have"),
                          " zero area (", repeated, " repeat a corner, ", collinear,
                          " have collinear corners; first: triangle ", first,
                          "); they are kept but contribute no surface"),
             report.degenerate_triangles);
  }

  std::vector<std::array<std::int32_t, 4>> keys;  // sorted corners + triangle
  keys.reserve(static_cast<std::size_t>(mesh.num_triangles()));
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    std::array<std::int32_t, 3> c = {mesh.triangles(t, 0), mesh.triangles(t, 1),
                                     mesh.triangles(t, 2)};
    std::sort(c.begin(), c.end());
    keys.push_back({c[0], c[1], c[2], static_cast<std::int32_t>(t)});
  }
  std::sort(keys.begin(), keys.end());
  std::int64_t first_duplicate = -1;
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (keys[i][0] == keys[i - 1][0] && keys[i][1] == keys[i - 1][1] &&
        keys[i][2] == keys[i - 1][2]) {
      if (report.duplicate_triangles++ == 0 || keys[i][3] < first_duplicate) {
        first_duplicate = keys[i][3];
      }
    }
  }
  if (report.duplicate_triangles > 0) {
    AddIssue(
        report, Severity::kWarning, "duplicate_triangles",
        absl::StrCat(Plural(report.duplicate_triangles, "triangle repeats", "triangles repeat"),
                     " the corners of an earlier one (first: triangle ", first_duplicate, ")"),
        report.duplicate_triangles);
  }

  std::vector<char> used(static_cast<std::size_t>(mesh.num_vertices()), 0);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    for (int k = 0; k < 3; ++k) used[static_cast<std::size_t>(mesh.triangles(t, k))] = 1;
  }
  report.unreferenced_vertices = std::count(used.begin(), used.end(), 0);
  if (report.unreferenced_vertices > 0) {
    AddIssue(report, Severity::kWarning, "unreferenced_vertices",
             absl::StrCat(Plural(report.unreferenced_vertices, "vertex is", "vertices are"),
                          " in no triangle (ignored)"),
             report.unreferenced_vertices);
  }
}

void CheckEdges(const Mesh& mesh, const std::vector<EdgeUse>& uses, const EdgeGroups& groups,
                MeshReport& report) {
  const EdgeUse* first_border = nullptr;
  const EdgeUse* first_non_manifold = nullptr;
  std::size_t first_non_manifold_count = 0;
  const EdgeUse* first_inconsistent = nullptr;
  for (const auto& [begin, end] : groups.ranges) {
    const std::size_t n = end - begin;
    if (n == 1) {
      if (report.border_edges++ == 0) first_border = &uses[begin];
    } else if (n > 2) {
      if (report.non_manifold_edges++ == 0) {
        first_non_manifold = &uses[begin];
        first_non_manifold_count = n;
      }
    } else if (uses[begin].forward == uses[begin + 1].forward) {
      if (report.inconsistent_edges++ == 0) first_inconsistent = &uses[begin];
    }
  }
  if (report.border_edges > 0) {
    AddIssue(report, Severity::kError, "not_closed",
             absl::StrCat(
                 "mesh is not closed: ", Plural(report.border_edges, "border edge", "border edges"),
                 " (edges in only one triangle; first: vertices ", first_border->lo, "-",
                 first_border->hi, " in triangle ", first_border->triangle, ")",
                 // Every edge a border: no two triangles share a vertex, as when an exporter
                 // repeats each vertex per face at positions that differ in the last digits.
                 report.border_edges == static_cast<std::int64_t>(groups.ranges.size()) &&
                         mesh.num_triangles() > 1
                     ? "; no two triangles share an edge: if the file repeats each vertex per "
                       "face at slightly different positions, --repair safe welds those within "
                       "1e-4 of the size, --weld-tolerance D any within D"
                     : ""),
             report.border_edges);
  }
  if (report.non_manifold_edges > 0) {
    AddIssue(
        report, Severity::kError, "non_manifold_edges",
        absl::StrCat("mesh is not edge-manifold: ",
                     Plural(report.non_manifold_edges, "edge is", "edges are"),
                     " shared by more than two triangles (first: vertices ", first_non_manifold->lo,
                     "-", first_non_manifold->hi, ", in ", first_non_manifold_count, " triangles)"),
        report.non_manifold_edges);
  }
  // Inconsistent orientation is reported by the orientation step, which knows if it is fixed.
  (void)first_inconsistent;
}

void CheckVertexManifold(const Mesh& mesh, const std::vector<EdgeUse>& uses,
                         const EdgeGroups& groups, MeshReport& report) {
  // Corners 3t + k of one vertex belong to one fan when linked through manifold edges.
  DisjointSets corners(static_cast<std::size_t>(mesh.num_triangles()) * 3);
  auto corner_of = [&](std::int32_t t, std::int32_t v) -> std::size_t {
    for (int k = 0; k < 3; ++k) {
      if (mesh.triangles(t, k) == v) return static_cast<std::size_t>(t) * 3 + k;
    }
    return static_cast<std::size_t>(t) * 3;  // unreachable for a use of this edge
  };
  for (const auto& [begin, end] : groups.ranges) {
    if (end - begin != 2) continue;
    const EdgeUse& a = uses[begin];
    const EdgeUse& b = uses[begin + 1];
    corners.Union(corner_of(a.triangle, a.lo), corner_of(b.triangle, a.lo));
    corners.Union(corner_of(a.triangle, a.hi), corner_of(b.triangle, a.hi));
  }
  // Each vertex's first fan; a corner in another fan makes the vertex non-manifold.
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> fan_of(static_cast<std::size_t>(mesh.num_vertices()), kNone);
  std::vector<char> several(static_cast<std::size_t>(mesh.num_vertices()), 0);
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(mesh.triangles(t, k));
      const std::size_t fan = corners.Find(static_cast<std::size_t>(t) * 3 + k);
      if (fan_of[v] == kNone) fan_of[v] = fan;
      if (fan_of[v] != fan) several[v] = 1;
    }
  }
  std::int64_t first = -1;
  for (std::size_t v = 0; v < several.size(); ++v) {
    if (several[v] && report.non_manifold_vertices++ == 0) first = static_cast<std::int64_t>(v);
  }
  if (report.non_manifold_vertices > 0) {
    AddIssue(report, Severity::kWarning, "non_manifold_vertices",
             absl::StrCat(Plural(report.non_manifold_vertices, "vertex joins", "vertices join"),
                          " several separate fans of triangles (first: vertex ", first,
                          "); the solid is classified with the exact inside test"),
             report.non_manifold_vertices);
  }
}

// Edge-connected components of the triangles with distinct corners. Returns component id per
// triangle (-1 for skipped triangles) and fills report.components.
std::vector<std::int32_t> LabelComponents(const Mesh& mesh, const std::vector<EdgeUse>& uses,
                                          const EdgeGroups& groups, MeshReport& report) {
  DisjointSets sets(static_cast<std::size_t>(mesh.num_triangles()));
  for (const auto& [begin, end] : groups.ranges) {
    for (std::size_t i = begin + 1; i < end; ++i) {
      sets.Union(static_cast<std::size_t>(uses[begin].triangle),
                 static_cast<std::size_t>(uses[i].triangle));
    }
  }
  std::vector<std::int32_t> label(static_cast<std::size_t>(mesh.num_triangles()), -1);
  std::vector<std::int32_t> root_label(static_cast<std::size_t>(mesh.num_triangles()), -1);
  std::int32_t next = 0;
  for (Eigen::Index t = 0; t < mesh.triangles.rows(); ++t) {
    if (!internal::HasDistinctCorners(mesh, t)) continue;
    const std::size_t root = sets.Find(static_cast<std::size_t>(t));
    if (root_label[root] < 0) root_label[root] = next++;
    label[static_cast<std::size_t>(t)] = root_label[root];
  }
  report.components = next;
  return label;
}

// Reports the triangles that the orientation fixes reversed: flip[t] for each triangle t of the
// mesh as given; component[t] < 0 marks triangles without three distinct corners.
void ReportFlips(const std::vector<char>& flip, const std::vector<std::int32_t>& component,
                 MeshReport& report) {
  report.flipped_triangles = std::count(flip.begin(), flip.end(), 1);
  if (report.flipped_triangles > 0) {
    const bool all =
        report.flipped_triangles ==
        std::count_if(component.begin(), component.end(), [](std::int32_t c) { return c >= 0; });
    std::string what =
        report.inconsistent_edges > 0
            ? absl::StrCat("orientation was inconsistent (",
                           Plural(report.inconsistent_edges, "edge", "edges"), ")")
            : std::string(all ? "mesh was inside out" : "some shells faced the wrong way");
    AddIssue(
        report, Severity::kFixed, "orientation_fixed",
        absl::StrCat(what, "; reversed ", Plural(report.flipped_triangles, "triangle", "triangles"),
                     " so that normals point out of the solid"),
        report.flipped_triangles);
  }
}

void CheckOrientation(Mesh& mesh, const std::vector<EdgeUse>& uses, const EdgeGroups& groups,
                      const ValidateOptions& options, MeshReport& report) {
  const std::vector<std::int32_t> component = LabelComponents(mesh, uses, groups, report);
  const bool two_manifold_edges = report.border_edges == 0 && report.non_manifold_edges == 0;
  if (!options.fix_orientation || !two_manifold_edges) {
    if (report.inconsistent_edges > 0) {
      AddIssue(report, two_manifold_edges ? Severity::kError : Severity::kWarning,
               "inconsistent_orientation",
               absl::StrCat(Plural(report.inconsistent_edges, "edge joins", "edges join"),
                            " triangles of opposite orientation (not fixed)"),
               report.inconsistent_edges);
    }
    return;
  }
  std::vector<char> flip;
  std::int64_t bad_triangle = -1;
  if (!internal::MakeOrientationConsistent(mesh, uses, groups, component, report.components, flip,
                                           &bad_triangle)) {
    AddIssue(report, Severity::kError, "not_orientable",
             absl::StrCat("mesh is not orientable (a Moebius-like component contains triangle ",
                          bad_triangle, ")"),
             1);
    return;
  }
  report.flat_shells = internal::OrientComponentsOutward(mesh, component, report.components, flip);
  ReportFlips(flip, component, report);
}

// Appends why the holes stay open to the "not closed" error, the one line users see.
void NoteHolesNotFilled(MeshReport& report, const std::string& why) {
  for (MeshIssue& issue : report.issues) {
    if (issue.code == "not_closed") absl::StrAppend(&issue.message, "; ", why);
  }
}

// Hole filling (MeshRepair::kFill, kAuto) on a mesh with border edges: makes orientation consistent
// on a copy, closes every hole of the copy (internal::FillHoles), then orients the closed copy
// outward and returns it in `mesh`. When any hole cannot be closed, `mesh` is left as given,
// checked as without fill_holes, and the "not closed" error says why. Cost O(#T log #T) plus
// CGAL's.
void FillHolesAndOrient(Mesh& mesh, const std::vector<EdgeUse>& uses, const EdgeGroups& groups,
                        const ValidateOptions& options, MeshReport& report) {
  auto keep_open = [&](const std::string& why) {
    CheckOrientation(mesh, uses, groups, options, report);
    NoteHolesNotFilled(report, why);
  };
  if (report.non_manifold_edges > 0) {
    return keep_open("holes were not filled: the mesh is not edge-manifold");
  }
  if (report.inconsistent_edges > 0 && !options.fix_orientation) {
    return keep_open("holes were not filled: orientation is inconsistent and is not to be fixed");
  }
  const std::vector<std::int32_t> component = LabelComponents(mesh, uses, groups, report);
  Mesh closed = mesh;
  std::vector<char> flip(static_cast<std::size_t>(mesh.num_triangles()), 0);
  std::int64_t bad_triangle = -1;
  if (options.fix_orientation &&
      !internal::MakeOrientationConsistent(closed, uses, groups, component, report.components, flip,
                                           &bad_triangle)) {
    return keep_open(
        absl::StrCat("holes were not filled: a component is not orientable "
                     "(it contains triangle ",
                     bad_triangle, ")"));
  }
  internal::HoleFillingLimits limits;
  limits.max_hole_edges = options.max_hole_edges;
  limits.max_total_hole_edges = options.max_total_hole_edges;
  const internal::HoleFilling filling = internal::FillHoles(closed, limits);
  if (filling.holes_left_open > 0 || filling.holes == 0) {
    return keep_open(filling.refused || filling.holes == 1
                         ? absl::StrCat("holes were not filled: ", filling.failure)
                         : absl::StrCat("hole filling failed for ", filling.holes_left_open, " of ",
                                        Plural(filling.holes, "loop", "loops"),
                                        filling.holes_filled > 0 ? ", so none was filled" : "",
                                        " (first: ", filling.failure, ")"));
  }
  const Eigen::Index given = closed.triangles.rows();
  closed.triangles.conservativeResize(given + filling.patch.rows(), 3);
  closed.triangles.bottomRows(filling.patch.rows()) = filling.patch;

  // The patch is checked, not trusted: every edge of the closed copy must join exactly two
  // triangles that walk it in opposite directions before the copy replaces the mesh.
  const std::vector<EdgeUse> closed_uses = internal::SortedEdgeUses(closed);
  const EdgeGroups closed_groups = GroupEdges(closed_uses);
  const std::int64_t bad_edges =
      std::count_if(closed_groups.ranges.begin(), closed_groups.ranges.end(),
                    [&closed_uses](const std::pair<std::size_t, std::size_t>& r) {
                      return r.second - r.first != 2 ||
                             closed_uses[r.first].forward == closed_uses[r.first + 1].forward;
                    });
  if (bad_edges > 0) {
    return keep_open(absl::StrCat("holes were not filled: the patches left ",
                                  Plural(bad_edges, "edge", "edges"),
                                  " not shared by two consistently oriented triangles"));
  }
  MeshReport closed_report;
  const std::vector<std::int32_t> closed_component =
      LabelComponents(closed, closed_uses, closed_groups, closed_report);
  flip.resize(static_cast<std::size_t>(closed.num_triangles()), 0);
  if (options.fix_orientation) {
    report.flat_shells =
        internal::OrientComponentsOutward(closed, closed_component, closed_report.components, flip);
  }
  // Only the triangles as given count as flipped; the patch was made facing its neighbours.
  flip.resize(static_cast<std::size_t>(given));
  ReportFlips(flip, component, report);

  report.holes_filled = filling.holes_filled;
  report.hole_triangles_added = filling.patch.rows();
  report.issues.erase(std::remove_if(report.issues.begin(), report.issues.end(),
                                     [](const MeshIssue& i) { return i.code == "not_closed"; }),
                      report.issues.end());
  AddIssue(report, Severity::kFixed, "holes_filled",
           absl::StrCat("filled ", Plural(report.holes_filled, "hole", "holes"), " (",
                        Plural(filling.filled_border_edges, "border edge", "border edges"),
                        ") with ", Plural(report.hole_triangles_added, "triangle", "triangles")),
           report.holes_filled);
  mesh = std::move(closed);
}

// options.weld_vertices: merges coincident vertices (internal::WeldVertices) and reports it.
// Returns false, with the error "invalid_weld_tolerance", for a tolerance that is negative or
// not finite; the mesh is then not examined further.
bool WeldCoincidentVertices(Mesh& mesh, double tolerance, MeshReport& report) {
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance)) {
    AddIssue(report, Severity::kError, "invalid_weld_tolerance",
             absl::StrFormat("weld tolerance %g is not a finite distance >= 0", tolerance), 0);
    return false;
  }
  const internal::Weld weld = internal::WeldVertices(mesh, tolerance);
  report.welded_vertices = weld.merged_vertices;
  report.weld_collapsed_triangles = weld.collapsed_triangles;
  if (tolerance > 0.0 && weld.merged_vertices > 0) report.weld_moved_within = tolerance;
  if (weld.merged_vertices > 0 || weld.collapsed_triangles > 0) {
    AddIssue(report, Severity::kFixed, "welded_vertices",
             absl::StrCat("welded ", Plural(weld.merged_vertices, "vertex", "vertices"),
                          tolerance > 0.0 ? absl::StrFormat(" within %g", tolerance)
                                          : std::string(" at identical positions"),
                          " into the ", Plural(mesh.num_vertices(), "vertex", "vertices"), " kept",
                          weld.collapsed_triangles > 0
                              ? absl::StrCat("; removed ",
                                             Plural(weld.collapsed_triangles, "triangle that",
                                                    "triangles that"),
                                             " welding left with a repeated corner")
                              : std::string()),
             weld.merged_vertices);
    report.bbox = ComputeBoundingBox(mesh.vertices);
  }
  if (mesh.num_triangles() == 0) {
    AddIssue(report, Severity::kError, "no_triangles",
             "mesh has no triangles left once its coincident vertices were welded", 0);
    return false;
  }
  return true;
}

}  // namespace

const char* SeverityName(Severity severity) {
  switch (severity) {
    case Severity::kError:
      return "error";
    case Severity::kWarning:
      return "warning";
    case Severity::kFixed:
      return "fixed";
  }
  return "unknown";
}

bool MeshReport::usable() const {
  return std::none_of(issues.begin(), issues.end(),
                      [](const MeshIssue& i) { return i.severity == Severity::kError; });
}

std::vector<MeshIssue> MeshReport::notices() const {
  std::vector<MeshIssue> out;
  for (const MeshIssue& issue : issues) {
    if (issue.severity == Severity::kError) continue;
    if (issue.code == "welded_vertices" && weld_moved_within == 0.0 &&
        weld_collapsed_triangles == 0) {
      continue;
    }
    out.push_back(issue);
  }
  return out;
}

std::string MeshReport::repairs() const {
  if (!geometry_repaired()) return "";
  std::string out;
  for (const MeshIssue& issue : issues) {
    if (issue.code == "holes_filled" || issue.code == "welded_vertices" ||
        issue.code == "cracks_welded" || issue.code == "wrapped") {
      absl::StrAppend(&out, out.empty() ? "" : "; ", issue.message);
    }
  }
  return out;
}

std::string MeshReport::first_error() const {
  for (const MeshIssue& issue : issues) {
    if (issue.severity == Severity::kError) return issue.message;
  }
  return "";
}

namespace {

// Every step but the wrap. `soup`: the mesh once welded (what a wrap wraps), when the mesh got
// that far (*wrappable is then true, and `soup_ready`, when given, is called then).
ValidatedMesh ValidateSteps(Mesh mesh, const ValidateOptions& options, Mesh* soup, bool* wrappable,
                            const std::function<void()>& soup_ready = {}) {
  *wrappable = false;
  MeshReport report;
  report.vertices = mesh.num_vertices();
  report.triangles = mesh.num_triangles();
  if (!CheckIndicesAndCoordinates(mesh, report)) {
    return ValidatedMesh{std::move(mesh), std::move(report)};
  }
  report.bbox = ComputeBoundingBox(mesh.vertices);
  // Found by fuzz_mesh: a vertex at 1.8e308 made hole filling's projected triangulation
  // overflow to infinity and GMP abort the process inside CGAL, and one at -1e308 gave an
  // infinite volume on a usable mesh. Below the bound, volumes and CGAL's constructions stay
  // finite; nothing else runs on a mesh beyond it.
  if (const std::int64_t huge =
          (mesh.vertices.array().abs() > kMaxMeshCoordinate).rowwise().any().count();
      huge > 0) {
    AddIssue(report, Severity::kError, "coordinates_too_large",
             absl::StrFormat("%s a coordinate beyond +-%g (largest magnitude %g); scale the "
                             "mesh down",
                             Plural(huge, "vertex has", "vertices have"), kMaxMeshCoordinate,
                             mesh.vertices.cwiseAbs().maxCoeff()),
             huge);
    return ValidatedMesh{std::move(mesh), std::move(report)};
  }
  if (options.weld_vertices &&
      !WeldCoincidentVertices(mesh, options.repair.weld_tolerance, report)) {
    return ValidatedMesh{std::move(mesh), std::move(report)};
  }
  if (soup != nullptr) *soup = mesh;
  *wrappable = true;
  if (soup_ready) soup_ready();
  if (options.repair.level != MeshRepair::kNone) {
    internal::RemoveDuplicatesAndDoubleWalls(mesh, report);
    if (mesh.num_triangles() == 0) {
      AddIssue(report, Severity::kError, "no_triangles",
               "mesh has no triangles left once the walls stored twice were removed: a sheet "
               "stored in both orientations bounds no solid; --repair wrap makes a thin solid "
               "around it",
               0);
      return ValidatedMesh{std::move(mesh), std::move(report)};
    }
    internal::WeldCracks(mesh, report);
  }
  const std::int64_t welded_triangles = mesh.num_triangles();
  CheckDegenerateAndDuplicate(mesh, report);
  const std::vector<EdgeUse> uses = internal::SortedEdgeUses(mesh);
  const EdgeGroups groups = GroupEdges(uses);
  CheckEdges(mesh, uses, groups, report);
  CheckVertexManifold(mesh, uses, groups, report);
  const bool fill =
      options.repair.level == MeshRepair::kFill || options.repair.level == MeshRepair::kAuto;
  if (fill && report.border_edges > 0) {
    FillHolesAndOrient(mesh, uses, groups, options, report);
  } else {
    CheckOrientation(mesh, uses, groups, options, report);
  }
  report.volume = SignedVolume(mesh);

  if (report.usable() && !(report.volume > 0.0)) {
    AddIssue(report, Severity::kError, "no_volume",
             absl::StrFormat("mesh encloses no volume (signed volume %g): a sheet or flat part "
                             "bounds no solid",
                             report.volume),
             0);
  }
  if (options.check_self_intersections && report.usable() && report.non_manifold_vertices == 0) {
    if (auto pairs = internal::SelfIntersectingPairs(mesh)) {
      report.self_intersections_checked = true;
      report.self_intersecting_pairs = static_cast<std::int64_t>(pairs->size());
      if (!pairs->empty()) {
        // Hole-filling triangles follow the given ones: a pair involves one when its second
        // (larger) index is past them.
        const std::int64_t patch_pairs =
            report.hole_triangles_added == 0
                ? 0
                : std::count_if(pairs->begin(), pairs->end(),
                                [welded_triangles](const std::pair<std::int32_t, std::int32_t>& p) {
                                  return p.second >= welded_triangles;
                                });
        AddIssue(
            report, Severity::kWarning, "self_intersections",
            absl::StrCat(
                "mesh intersects itself: ", Plural(report.self_intersecting_pairs, "pair", "pairs"),
                " of triangles cross (first: triangles ", pairs->front().first, " and ",
                pairs->front().second,
                patch_pairs > 0
                    ? absl::StrCat("; ", patch_pairs, " involve triangles that fill holes")
                    : std::string(),
                "); the solid is the union of what they bound (winding number not zero), "
                "classified "
                "with the exact inside test"),
            report.self_intersecting_pairs);
      }
    }
  }
  if (report.flat_shells > 0 && report.usable()) {
    AddIssue(report, Severity::kWarning, "flat_shells",
             absl::StrCat(Plural(report.flat_shells, "shell encloses", "shells enclose"),
                          " almost no volume for its size (under 1e-9 of its box's side cubed); "
                          "the exact inside test is used"),
             report.flat_shells);
  }
  if (!report.self_intersections_checked && report.usable()) {
    AddIssue(report, Severity::kWarning, "self_intersections_not_checked",
             report.non_manifold_vertices > 0
                 ? "self-intersections were not checked (some vertices are not manifold); the "
                   "exact inside test is used"
                 : "self-intersections were not checked; the exact inside test is used",
             0);
  }
  std::stable_sort(report.issues.begin(), report.issues.end(),
                   [](const MeshIssue& a, const MeshIssue& b) {
                     return static_cast<int>(a.severity) < static_cast<int>(b.severity);
                   });
  internal::AppendRemedies(report, options.repair.level);
  return ValidatedMesh{std::move(mesh), std::move(report)};
}

}  // namespace

ValidatedMesh ValidateMesh(Mesh mesh, const ValidateOptions& options) {
  const bool may_wrap =
      options.repair.level == MeshRepair::kWrap || options.repair.level == MeshRepair::kAuto;
  if (may_wrap) {
    MeshReport report;
    report.vertices = mesh.num_vertices();
    report.triangles = mesh.num_triangles();
    for (const double value : {options.repair.wrap_alpha, options.repair.wrap_offset}) {
      if (!(value >= 0.0) || !std::isfinite(value)) {
        AddIssue(report, Severity::kError, "invalid_wrap_parameters",
                 absl::StrFormat("wrap alpha %g and offset %g must be finite distances >= 0 (0: "
                                 "chosen from the mesh's size)",
                                 options.repair.wrap_alpha, options.repair.wrap_offset),
                 0);
        return ValidatedMesh{std::move(mesh), std::move(report)};
      }
    }
  }
  Mesh soup;
  bool wrappable = false;
  // A given alpha below 1e-4 of the diagonal is refused: the wrap's cost grows as 1/alpha^2.
  auto alpha_too_small = [&options](const internal::WrapParameters& p) {
    return options.repair.wrap_alpha > 0.0 && options.repair.wrap_alpha < 1e-4 * p.diagonal;
  };
  // --repair wrap wraps whatever the other steps find, so CGAL's wrap of the soup (most of the
  // time) runs on a second thread beside them; auto waits to see whether it needs one.
  // Declared before the task group: destroyed after it, which waits for the task.
  std::optional<absl::StatusOr<Mesh>> wrap;
  tbb::task_group wrapping;
  auto start_wrap = [&] {
    const internal::WrapParameters p = internal::WrapParametersFor(soup, options.repair);
    if (alpha_too_small(p)) return;
    wrapping.run([&soup, &wrap, p] { wrap = internal::ComputeWrap(soup, p); });
  };
  ValidatedMesh validated = ValidateSteps(
      std::move(mesh), options, may_wrap ? &soup : nullptr, &wrappable,
      options.repair.level == MeshRepair::kWrap ? std::function<void()>(start_wrap) : nullptr);
  wrapping.wait();
  if (!may_wrap || !wrappable ||
      (options.repair.level == MeshRepair::kAuto && validated.report.usable())) {
    return validated;
  }
  if (const internal::WrapParameters p = internal::WrapParametersFor(soup, options.repair);
      alpha_too_small(p)) {
    AddIssue(validated.report, Severity::kError, "wrap_alpha_too_small",
             absl::StrFormat("wrap alpha %g is below 1e-4 of the mesh's diagonal %g (the wrap's "
                             "cost grows as 1/alpha^2); use a larger --wrap-alpha",
                             options.repair.wrap_alpha, p.diagonal),
             0);
    return validated;
  }
  return internal::WrapSoup(std::move(validated), soup, options, std::move(wrap));
}

absl::StatusOr<ValidatedMesh> PrepareMesh(Mesh mesh, const ValidateOptions& options) {
  ValidatedMesh validated = ValidateMesh(std::move(mesh), options);
  if (!validated.report.usable()) {
    return absl::InvalidArgumentError(validated.report.first_error());
  }
  return validated;
}

}  // namespace inscribe
