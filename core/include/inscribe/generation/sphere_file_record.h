// What a sphere file records of the set it holds, written once for every entry point (the
// CLI's generate, Python's generate and SphereSet.save, anything that reads a cover file back):
// the params and stats of a generation, the set's kind, and a cover's certificate.
#pragma once

#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe {

// The param naming the set's kind: SphereSetKindName ("internal", "dilated", "cover").
inline constexpr char kKindParam[] = "kind";

// The sphere file of a generation: `result`'s set, `mesh_sha256` (the validated mesh's), and
//   params: kind, voxel_size (the one used), object_angle, epsilon (medial runs), the medial
//     settings (samples, screen_samples, pair_angle_margin, corner_screen, subdivide_boundary),
//     max_spheres and selection (a budget), dilation_growth (dilated), max_protrusion and
//     cover_resolution (covers), mesh_repairs (when `mesh`'s geometry was repaired:
//     MeshReport::repairs, what validation changed of the user's solid), and for a wrapped
//     mesh mesh_wrap_alpha and mesh_wrap_offset;
//   stats: seconds (the generation's, GeneratedSphereSet::generation_seconds), search_runs
//     (medial runs), pool_size and covered_fraction (optimised), the quality figures
//     (QualityFigures; when evaluated), visited_voxels and closest_point_queries (medial runs),
//     the dilation's figures (DilationFigures) and a cover's (CoverFigures); for a wrapped mesh
//     mesh_wrap_reach, and for a cover of a mesh whose repair moved its surface (a wrap, a weld
//     within a tolerance) delta_input (CoverDeltaOverInput), for an internal set of one
//     protrusion_input (InternalProtrusionOverInput).
// Lengths in mesh units, angles in radians. A cover's protrusions go with it.
SphereFile GenerationSphereFile(const SphereSetParameters& parameters,
                                const GeneratedSphereSet& result, const std::string& mesh_sha256,
                                const MeshReport& mesh);

// How far a certified cover of the repaired mesh reaches beyond the triangles of the mesh as
// given, when the repair moved the surface by a known bound: every point of the union lies in
// the repaired solid or within delta + that bound of the input triangles. The bound is the
// wrap's reach (a wrapped mesh) or the weld tolerance (vertices welded within one, which moves
// each point of the surface by at most it). Rounded up. nullopt when neither applies (nothing
// moved: delta itself holds; or holes were filled, whose patch has no bound to the input).
std::optional<double> CoverDeltaOverInput(double delta, const MeshReport& mesh);

// How far an internal set of the repaired mesh may reach outside the input's surface, under the
// same conditions: the wrap's reach or the weld tolerance. For a wrap the bound is proved as
// follows: the set lies inside the wrap, every point of the wrap's surface lies within
// wrap_reach of an input triangle, so a point of the set farther than wrap_reach from every
// input triangle cannot reach the wrap's outside without passing that close to one: it is
// enclosed by the input (in its material, or in a cavity or an alpha-narrow gap the wrap
// filled). Every other point lies within the bound of an input triangle. nullopt as for
// CoverDeltaOverInput.
std::optional<double> InternalProtrusionOverInput(const MeshReport& mesh);

// volume_mesh, volume_union, nerr, nerr_is_exact, protrusion_max, coverage,
// boundary_to_union_hausdorff, surface_samples, fat.
NamedValues QualityFigures(const QualityReport& quality);
// v_points, edge_points, grown, max_growth, dilation_seconds.
NamedValues DilationFigures(const DilationResult& dilation);
// CoverCertificateStats, then grown_spheres, cover_candidates, repair_rounds, and
// unused_reason when the cover has fewer spheres than its budget (GeneratedCover).
NamedValues CoverFigures(const GeneratedCover& cover);

// The certificate's figures as stats: delta and certificate_resolution (mesh units),
// certified, certificate_cells, cells_in_sphere, cells_outside, failed_cells, certify_seconds,
// and what it proved: certified_mesh_sha256 and certified_spheres_sha256.
NamedValues CoverCertificateStats(const CoverCertificate& certificate);

// The kind `file` records (its kKindParam), or "" when it records none (peer formats, files
// written before kinds were recorded).
std::string RecordedKind(const SphereFile& file);

// The certificate a cover file records: kind "cover", the stats CoverCertificateStats writes
// and the file's protrusions (when it has them). nullopt for a file of another kind or of none;
// INVALID_ARGUMENT naming the stat when a cover file lacks one of them or gives it another type
// (the two hashes may be missing: the certificate then names nothing).
absl::StatusOr<std::optional<CoverCertificate>> RecordedCoverCertificate(const SphereFile& file);

// The rule for taking a cover file's certificate, which every reader of covers follows: the
// recorded certificate, when it names the file's spheres and, when `mesh_sha256` is not empty,
// that mesh (CheckCoverCertificateBinding; empty: the mesh is not known there) and certifies
// them. nullopt when the file records none. FAILED_PRECONDITION "PATH: why" when it records one
// that does not name them (the spheres were edited, the file was written for another mesh or
// by an older inscribe) or does not certify them: the caller certifies the spheres again when
// it has their mesh, and refuses the file otherwise. INVALID_ARGUMENT "PATH: ..." as
// RecordedCoverCertificate's. Cost O(#spheres).
absl::StatusOr<std::optional<CoverCertificate>> UsableCoverCertificate(
    const SphereFile& file, const std::string& path, absl::string_view mesh_sha256);

}  // namespace inscribe
