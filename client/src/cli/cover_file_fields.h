// A cover's certificate as the command line writes and reads it, in one place: the params and
// stats of a sphere file (generate writes them, distance reads them back to use a file as a
// cover) and the verdict's wording (evaluate --certify, distance).
#pragma once

#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_io.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/generation/sphere_set_generation.h"

namespace inscribe::cli {

// The param naming the set's kind: SphereSetKindName ("internal", "dilated", "cover").
inline constexpr char kKindParam[] = "kind";

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

// The rule for taking a cover file's certificate, which every command that reads covers
// follows: the recorded certificate, when it names the file's spheres and, when `mesh_sha256`
// is not empty, that mesh (CheckCoverCertificateBinding; empty: the mesh is not known here)
// and certifies them. nullopt when the file records none. FAILED_PRECONDITION "PATH: why" when
// it records one that does not name them (the spheres were edited, the file was written for
// another mesh or by an older inscribe) or does not certify them: the caller certifies the
// spheres again when it has their mesh, and refuses the file otherwise. INVALID_ARGUMENT
// "PATH: ..." as RecordedCoverCertificate's. Cost O(#spheres).
absl::StatusOr<std::optional<CoverCertificate>> UsableCoverCertificate(
    const SphereFile& file, const std::string& path, absl::string_view mesh_sha256);

// The verdict in words: "certified: ...", or "NOT certified: " and the point of the solid in no
// sphere (its depth and gap), or the unsettled cells when no such point was found.
std::string CoverVerdict(const CoverCertificate& certificate);

}  // namespace inscribe::cli
