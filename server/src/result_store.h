// The service's typed view of its ResultCache: stored meshes, generated sphere sets and their
// hierarchies, each under a content key, each decoded once and shared. Private to the server.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "absl/status/statusor.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/certified_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/geometry/mesh.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/server/result_cache.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/solid/solid.h"
#include "inscribe/v1/service.pb.h"

namespace inscribe::server {

// A validated mesh ready for queries: the cache object under "sha256:<hex>".
struct StoredMeshEntry {
  std::string key;  // "sha256:<64 hex>"
  Solid solid;      // orientation fixed, holes filled when asked

  const Mesh& mesh() const { return solid.mesh(); }
};

// A generated sphere set: the cache object under "spheres/v1/<hex>". `result` is what Generate
// returns (its `cache` field empty). An uploaded set has its spheres, mesh and key there, and
// kind cover with the certificate it was uploaded with, if any. A cover's certificate names
// the set's spheres and mesh (CheckCoverCertificateBinding, checked whenever it is decoded).
struct SphereSetEntry {
  v1::GenerateResult result;
  SphereSet set;
};

// One solid of a certified distance query: its internal set's and its cover's hierarchies
// (held, so `object` stays valid) and the cover's certified delta.
struct CertifiedObjectEntry {
  CertifiedObjectEntry(std::shared_ptr<const SphereHierarchy> internal_set,
                       std::shared_ptr<const SphereHierarchy> cover_set, double cover_delta)
      : internal(std::move(internal_set)),
        cover(std::move(cover_set)),
        object{internal.get(), cover.get(), cover_delta} {}

  const std::shared_ptr<const SphereHierarchy> internal, cover;
  const CertifiedObject object;
};

// A SphereDeformer kept between UpdateDeformation calls on one (mesh, set, options): the
// cache object under "deformer/v1/<hex>", in memory only (it holds a refit oracle). Update
// mutates the deformer, so callers take `mutex` for the update and every read of `deformer`
// that follows it (its oracle is the last frame's).
struct DeformerEntry {
  DeformerEntry(std::string mesh, Triangles mesh_triangles, SphereDeformer made)
      : mesh_key(std::move(mesh)),
        triangles(std::move(mesh_triangles)),
        deformer(std::move(made)) {}

  const std::string mesh_key;
  const Triangles triangles;  // the stored mesh's, for hashing deformed frames
  mutable std::mutex mutex;
  mutable SphereDeformer deformer;  // guarded by mutex
};

// Limits the store enforces while computing (the service checks the cheap ones first).
struct StoreLimits {
  std::int64_t max_voxels = 20'000'000;
  std::int64_t max_spheres = 1'000'000;
};

class ResultStore {
 public:
  ResultStore(ResultCache* cache, const StoreLimits& limits);

  // Validates `mesh` with `options` (its repairs: welding, hole filling) and stores it under
  // the hash of the validated mesh. UnusableMeshError (the report's first error) when it is
  // unusable, before any hashing or cache lookup. *already_stored: the key was held before.
  absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> PutMesh(Mesh mesh,
                                                                 const ValidateOptions& options,
                                                                 bool* already_stored);
  // NOT_FOUND for a key the cache does not hold (in memory or on disk).
  absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> GetMesh(const std::string& key);

  // The sphere set for (mesh, parameters): cached, or generated (GenerateSphereSet) with
  // `control` (progress and cancellation). `repair`: how the mesh was stored repaired (part
  // of the key). RESOURCE_EXHAUSTED over the --max-spheres limit, NOT_FOUND for an unknown
  // mesh, GenerateSphereSet's errors.
  absl::StatusOr<std::pair<std::shared_ptr<const SphereSetEntry>, CacheSource>> Generate(
      const std::string& mesh_key, const SphereSetParameters& parameters, MeshRepair repair,
      const GenerationControl& control);
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> GetSphereSet(const std::string& key);

  // Stores an uploaded set under "spheres/v1/<64 hex>": the first 16 hex digits of the mesh
  // key (else of `derived_from`, the key of the set this one was computed from, so that a
  // routing client finds it on the replica that made it), then the SHA-256 of mesh key and
  // numbers; a full SHA-256 when neither names a mesh. `mesh_key` may be empty; when given the
  // mesh must be stored (NOT_FOUND) and contacts must name its triangles (INVALID_ARGUMENT).
  // *already_stored: the key was held before.
  // With a `certificate` (which must be certified and bound to the set: name its spheres,
  // and `mesh_key` when given, with one protrusion per sphere; INVALID_ARGUMENT naming the
  // mismatch otherwise) the set is stored as a cover holding it, under a key that includes it.
  absl::StatusOr<std::shared_ptr<const SphereSetEntry>> PutSphereSet(
      SphereSet set, const std::string& mesh_key, bool* already_stored,
      const std::string& derived_from = "",
      const std::optional<CoverCertificate>& certificate = std::nullopt);

  // The certificate of cached set `set_key` against stored mesh `mesh_key` with `options`
  // (CertifyCover; the failed cells are not kept), computed once, then cached under
  // CoverCertificateKey (one read back that does not name the set's spheres and the mesh is
  // proved again). NOT_FOUND for unknown keys; CertifyCover's errors.
  absl::StatusOr<std::shared_ptr<const CoverCertificate>> CertifySphereSet(
      const std::string& set_key, const std::string& mesh_key, const CoverCertifyOptions& options,
      const GenerationControl& control = {});

  // The rule for using a set as a cover, in one place: the certificate the set was generated
  // or uploaded with, else CertifySphereSet against the mesh the set names at core's default
  // options. FAILED_PRECONDITION naming the key when there is none (no certificate, no mesh)
  // or it does not certify the set (naming the point of the solid in no sphere).
  absl::StatusOr<CoverCertificate> CoverCertificateOf(const std::string& set_key);

  // One solid of a certified query: internal set `internal_key` (refused, FAILED_PRECONDITION,
  // when Generate made it a cover or dilated: it must lie inside the solid) and cover
  // `cover_key` (CoverCertificateOf), their hierarchies of `volume`. INVALID_ARGUMENT when the
  // two name different meshes, or the cover's certificate another mesh than the internal set.
  absl::StatusOr<std::shared_ptr<const CertifiedObjectEntry>> GetCertifiedObject(
      const std::string& internal_key, const std::string& cover_key, HierarchyVolume volume);

  // The deformer of (mesh, set, options), created on first use (an oracle build). FAILED_
  // PRECONDITION for a set without contacts or whose contacts do not fit the mesh.
  absl::StatusOr<std::shared_ptr<const DeformerEntry>> GetDeformer(
      const std::string& mesh_key, const std::string& set_key, const DeformationOptions& options);

  // The hierarchy of a cached sphere set, built on first use.
  absl::StatusOr<std::shared_ptr<const SphereHierarchy>> GetHierarchy(const std::string& key,
                                                                      HierarchyVolume volume);

  ResultCache& cache() { return *cache_; }

 private:
  ResultCache* const cache_;
  const StoreLimits limits_;
};

}  // namespace inscribe::server
