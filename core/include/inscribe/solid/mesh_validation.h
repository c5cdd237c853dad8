// Checking that a mesh bounds a solid the generator can work on, and fixing what can be fixed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "inscribe/geometry/mesh.h"

namespace inscribe {

enum class Severity {
  kError,    // the mesh cannot be used to generate spheres
  kWarning,  // usable, but results may suffer
  kFixed,    // was wrong and has been repaired in the returned mesh
};

struct MeshIssue {
  Severity severity;
  std::string code;     // stable identifier, e.g. "not_closed"; for scripts and JSON
  std::string message;  // one line a user can act on, with counts and a first example
  std::int64_t count = 0;
};

// Counts found by ValidateMesh. `vertices`, `triangles`, `non_finite_vertices` and
// `out_of_range_indices` are about the mesh as given; the weld's two counts say what welding
// changed; every count after them (and every index an issue names) is about the welded mesh,
// before the orientation and hole fixes, except where a field says otherwise. Without a weld
// (nothing coincident, or ValidateOptions::weld_vertices off) the welded mesh is the mesh as
// given.
struct MeshReport {
  std::int64_t vertices = 0;
  std::int64_t triangles = 0;
  std::int64_t non_finite_vertices = 0;   // a coordinate is NaN or infinite
  std::int64_t out_of_range_indices = 0;  // triangle corners naming no vertex
  // ValidateOptions::weld_vertices: the vertices merged into an earlier one (the welded mesh
  // has vertices - welded_vertices), and the triangles removed because welding left them with
  // a repeated corner (the welded mesh has triangles - weld_collapsed_triangles).
  std::int64_t welded_vertices = 0;
  std::int64_t weld_collapsed_triangles = 0;
  // The weld's tolerance when it was > 0 and merged vertices (moving them up to it), else 0.
  double weld_moved_within = 0.0;
  std::int64_t degenerate_triangles = 0;   // repeated corner or zero area (exact predicate)
  std::int64_t duplicate_triangles = 0;    // same three corners as an earlier triangle
  std::int64_t unreferenced_vertices = 0;  // in no triangle (harmless)
  std::int64_t border_edges = 0;           // edges in exactly one triangle: not closed
  std::int64_t non_manifold_edges = 0;     // edges in more than two triangles
  std::int64_t non_manifold_vertices = 0;  // vertices whose triangles form several fans
  std::int64_t inconsistent_edges = 0;     // edges whose two triangles disagree on orientation
  std::int64_t components = 0;             // edge-connected components of triangles
  std::int64_t flipped_triangles = 0;      // triangles whose orientation the fix reversed
  // Closed shells enclosing almost no volume for their size (the orientation fix's sign and
  // the pseudonormal are not trusted near them; the solid then gets the exact inside test).
  std::int64_t flat_shells = 0;
  bool self_intersections_checked = false;
  std::int64_t self_intersecting_pairs = 0;  // pairs of triangles that cross (exact predicates)
  // MeshRepair::kSafe and above: triangles removed because they repeat an earlier one's
  // corners in the same order (exact duplicates), and pairs of triangles removed because they
  // have the same corners in opposite orders (a wall between two bodies stored once for
  // each: removing both leaves the union of the bodies, the same solid).
  std::int64_t duplicate_triangles_removed = 0;
  std::int64_t double_walls_removed = 0;
  // MeshRepair::kSafe and above, on a mesh with border edges: the tolerance the crack weld
  // used (derived from the mesh's size and edge lengths, CrackWeldTolerance) and the border
  // vertices it merged into a nearby border vertex (0 when it merged none or was undone
  // because it did not close any border edge or made an edge non-manifold).
  double crack_weld_tolerance = 0.0;
  std::int64_t crack_vertices_welded = 0;
  // Hole filling (MeshRepair::kFill, or kAuto on an open mesh): the border loops closed (all
  // of them or none) and the triangles that took, beyond the welded mesh's, in the returned
  // mesh.
  std::int64_t holes_filled = 0;
  std::int64_t hole_triangles_added = 0;
  // The watertight wrap (MeshRepair::kWrap, or kAuto when nothing milder made the mesh
  // usable): the returned mesh is CGAL's 3D alpha wrap of the triangles as given (after the
  // safe fixes), which encloses every one of them (checked with exact predicates: no input
  // triangle meets the wrap's surface and every input vertex is inside it). The counts before
  // `wrapped` describe the input; components, flipped_triangles, flat_shells, the
  // self-intersection figures, volume and bbox describe the wrap.
  bool wrapped = false;
  double wrap_alpha = 0.0;                // mesh units
  double wrap_offset = 0.0;               // mesh units
  std::int64_t wrap_input_triangles = 0;  // the triangles wrapped
  std::int64_t wrap_triangles = 0;        // the wrap's
  // An upper bound on how far any point of the wrap's surface is from the nearest input
  // triangle (mesh units): every point of the wrapped solid lies inside what the input
  // triangles enclose or within the alpha-wide pockets the wrap bridged, and every point of
  // its surface within this distance of the input. About the offset; proven, not sampled.
  double wrap_reach = 0.0;

  // Enclosed volume of the returned mesh, after every fix (mesh units cubed). The
  // self-intersection figures are about the returned mesh too.
  double volume = 0.0;
  BoundingBox bbox;

  std::vector<MeshIssue> issues;

  // True when the returned mesh has no border: as given, once its holes were filled, or as
  // wrapped.
  bool closed() const {
    return triangles > 0 && (border_edges == 0 || holes_filled > 0 || wrapped);
  }
  // True when no issue is an error: the mesh bounds a solid the generator can use.
  bool usable() const;
  // True when the returned mesh's solid is not the given one's: vertices welded within a
  // tolerance > 0 (a crack weld too), triangles welding removed, holes filled, a wrap. Hashes,
  // spheres and certificates are then about the repaired mesh only. Orientation fixes, welds
  // of identical positions and removed duplicates and double walls change no point of the
  // solid.
  bool geometry_repaired() const {
    return weld_moved_within > 0.0 || weld_collapsed_triangles > 0 || holes_filled > 0 || wrapped;
  }
  // Those repairs in one line ("welded 3 vertices within 0.02 ...; filled 1 hole ..."), or ""
  // when geometry_repaired() is false.
  std::string repairs() const;
  // The warnings and fixes to show whoever uses the mesh (every entry point prints or returns
  // them): every issue that is not an error, except a weld of identical positions that removed
  // no triangle (lossless, and what every per-face exporter needs).
  std::vector<MeshIssue> notices() const;
  // The first error as a one-line reason, or "" when usable.
  std::string first_error() const;
};

// How much validation may change a mesh to make it usable, mildest first. Every level does
// what the levels before it do.
enum class MeshRepair {
  // Lossless for the surface: vertices at identical positions welded, orientation made
  // consistent and outward. Anything else wrong refuses the mesh.
  kNone,
  // Also lossless for the solid, or moving vertices by at most a tolerance far below the
  // mesh's size: exact duplicate triangles removed, walls stored twice (same corners, opposite
  // orders) removed, and cracks welded: border vertices merged into a border vertex within
  // CrackWeldTolerance, kept only when that closes border edges and makes no edge
  // non-manifold. The default.
  kSafe,
  // Also closes holes (ValidateOptions' hole-filling notes); no vertex moves.
  kFill,
  // The safe fixes, then CGAL's 3D alpha wrap of all the triangles: a closed, oriented
  // 2-manifold without self-intersections that encloses every input triangle, within about
  // `offset` of them outside and bridging gaps narrower than about `alpha`. Any triangle soup
  // with a triangle becomes usable (a lone sheet becomes a thin slab).
  kWrap,
  // kSafe; if the mesh is still unusable, hole filling; if it is still unusable, the wrap.
  kAuto,
};

// "none", "safe", "fill", "wrap", "auto": the names the CLI, the wire and Python use.
const char* MeshRepairName(MeshRepair repair);
// The level a name gives, or INVALID_ARGUMENT listing the names.
absl::StatusOr<MeshRepair> ParseMeshRepair(const std::string& name);

// The crack weld's tolerance for a mesh with bounding box `bbox` and these triangles: 1e-4 of
// the box's diagonal, at most a quarter of the median length of the mesh's non-border edges
// (so that no edge of a real feature collapses), never below 1e-9 of the diagonal.
double CrackWeldTolerance(const Mesh& mesh);

// The wrap's default parameters for a mesh whose bounding box has diagonal `diagonal`:
// alpha = diagonal / kWrapAlphaDivisor, offset = alpha / kWrapOffsetDivisor. The offset sits
// at CGAL's faster end (its examples use alpha / 30: 1.5x closer, about 1.4x the time).
inline constexpr int kWrapAlphaDivisor = 50;
inline constexpr int kWrapOffsetDivisor = 20;
double DefaultWrapAlpha(double diagonal);
double DefaultWrapOffset(double alpha);

// What a caller asks of the repair: every entry point (CLI, service, Python, robots) carries
// this one struct to ValidateMesh.
struct RepairOptions {
  // How much the mesh may be changed to make it usable (MeshRepair).
  MeshRepair level = MeshRepair::kSafe;
  // A weld of every vertex within this distance of an earlier kept one (mesh units; see
  // ValidateOptions::weld_vertices), before everything else; 0: identical positions only.
  double weld_tolerance = 0.0;
  // The wrap's alpha and offset (mesh units; 0: DefaultWrapAlpha / DefaultWrapOffset).
  // Negative or non-finite: the error "invalid_wrap_parameters". An alpha below 1e-4 of the
  // diagonal is refused too (the wrap's cost grows as 1/alpha^2: "wrap_alpha_too_small").
  double wrap_alpha = 0.0;
  double wrap_offset = 0.0;
};

struct ValidateOptions {
  RepairOptions repair;
  // Merge coincident vertices first: exporters (MeshLab's OBJ, STL by its nature) repeat each
  // vertex once per face, which leaves every edge a border. With repair.weld_tolerance 0 only
  // vertices with identical coordinates are merged; with a weld tolerance > 0 (mesh units) a
  // vertex within that distance of an earlier kept vertex is merged into the first such one,
  // in index order (deterministic; clusters span at most twice the tolerance). Triangles left
  // with a repeated corner are removed. Coincident vertices of separate shells or sheets stay
  // apart: a merge is made only where the triangles around the vertex form one fan, so a
  // mesh that was usable stays so. Kept vertices keep their order and coordinates. Reported
  // as the fixed issue "welded_vertices". Cost O(#V log #V + #T log #T).
  bool weld_vertices = true;
  // Self-intersection testing costs O(#T log #T) with exact predicates; it is skipped (and
  // reported as unchecked) for meshes that are not closed 2-manifolds. A solid whose mesh was
  // not checked, or intersects itself, gets the exact inside test (InsideTestFor).
  bool check_self_intersections = true;
  // Make orientation consistent within each component and point every normal away from the
  // solid: a shell enclosed by an even number of others outward, by an odd number (a cavity)
  // inward, for any number of components (exact winding numbers). The solid is then where the
  // mesh's winding number is not zero (InsideTest).
  bool fix_orientation = true;
  // Hole filling closes every hole (border loop) with triangles between its own border vertices (no
  // vertex is added; CGAL's triangulate_hole: the constrained Delaunay triangulation of a
  // near-planar loop, else the triangulation with the smallest largest dihedral angle, then the
  // smallest area), after orientation is made consistent and before the closedness check. All holes
  // are filled or none: nothing is when the mesh is not edge-manifold, a vertex is on the
  // border twice, a loop exceeds the caps below (or, when not near planar, 1,000 edges or a
  // fixed work budget shared by all loops) or CGAL finds no triangulation for it; the mesh
  // then stays "not closed", and that error says why. Off by default so that a user's solid
  // is never changed silently; needs fix_orientation unless the orientation is consistent.
  // Done for MeshRepair::kFill, and for kAuto when the safe fixes leave the mesh unusable.
  // Caps on hole filling's work, in border edges: per loop and in all.
  std::int64_t max_hole_edges = 10'000;
  std::int64_t max_total_hole_edges = 100'000;
};

struct ValidatedMesh {
  // The input, welded when options.weld_vertices found coincident vertices, less the
  // duplicates and double walls the safe fixes removed, with orientation fixed when
  // options.fix_orientation and, when hole filling closed them, the patches' triangles
  // appended (same vertices); or, when the report says `wrapped`, the wrap.
  Mesh mesh;
  MeshReport report;
};

// Validates `mesh` and returns it (possibly welded, re-oriented, with its holes filled) with
// the report. A negative or non-finite options.repair.weld_tolerance is the error
// "invalid_weld_tolerance". Never fails: every problem becomes an issue in the report, including
// out-of-range indices and NaN coordinates. Cost O(#T log #T), plus hole filling's when asked
// for: O(n log n) for a near-planar loop of n edges, up to O(n^2) for another (at most 1,000
// edges), all loops' searches together within a fixed budget (under 3 s on hostile input).
ValidatedMesh ValidateMesh(Mesh mesh, const ValidateOptions& options = {});

// ValidateMesh, then INVALID_ARGUMENT carrying the first error when the mesh is not usable.
absl::StatusOr<ValidatedMesh> PrepareMesh(Mesh mesh, const ValidateOptions& options = {});

const char* SeverityName(Severity severity);

}  // namespace inscribe
