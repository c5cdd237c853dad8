// The cache and routing key scheme, in one place: how the server names what it stores, and how
// a routing client finds the replica holding it. Every key derived from a mesh starts with the
// mesh hash's first kRouteDigits hex digits, so a mesh and all its results live on one replica.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/generation/sphere_set_generation.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/solid/mesh_validation.h"

namespace inscribe::wire {

// Hex digits of a mesh key that route it and every key derived from it.
inline constexpr std::size_t kRouteDigits = 16;

// The first kRouteDigits hex digits of a mesh key ("sha256:<hex>") or of a sphere-set key
// ("spheres/v1/<hex>"), or "" for any other key. O(1).
std::string RoutePrefix(absl::string_view key);

// What routes `key` between replicas: RoutePrefix(key), or the whole key when that is "".
// Equal for a mesh and everything computed from it.
std::string RouteKey(absl::string_view key);

// The replica order for `route_key` under rendezvous hashing: indices into `names` (the
// replicas' names, e.g. "host:port"), best first. Every client (C++ or Python) given the same
// names routes a key the same way; adding or removing a replica moves only the keys it owned.
// One SHA-256 per name.
std::vector<int> RendezvousOrder(absl::string_view route_key,
                                 const std::vector<std::string>& names);

// What routes a set uploaded without a mesh: the first kRouteDigits hex digits of the SHA-256
// of its serialised numbers (the server's key for it is another hash). O(size).
std::string ContentRouteKey(absl::string_view spheres_bytes);

// "spheres/v1/<64 hex>" of a generated set: RoutePrefix(mesh_key), then SHA-256 digits of a
// fixed text of the algorithm version, the mesh key and every parameter (defaults resolved,
// numbers with 17 significant digits). `repair`: how the mesh was repaired when stored.
std::string GeneratedSphereSetKey(const std::string& mesh_key,
                                  const SphereSetParameters& parameters, MeshRepair repair);

// "spheres/v1/<64 hex>" of an uploaded set: the route prefix of `mesh_key`, else of
// `derived_from` (the key of the set it was computed from), else none (a full SHA-256), then
// the SHA-256 of the mesh key, `spheres_bytes` (the set's serialised numbers) and, when not
// empty, `certificate_bytes` (the serialised certificate it was uploaded with; sets uploaded
// without one keep the keys they had before certificates were uploaded).
std::string UploadedSphereSetKey(const std::string& mesh_key, const std::string& derived_from,
                                 absl::string_view spheres_bytes,
                                 absl::string_view certificate_bytes = "");

// "certificate/v1/<64 hex>": the cover certificate of set `set_key` against mesh `mesh_key`
// with `options` (its resolution; the failed cells kept change no verdict). Routes with the
// set.
std::string CoverCertificateKey(const std::string& set_key, const std::string& mesh_key,
                                const CoverCertifyOptions& options);

// "deformer/v1/<64 hex>": the deformer of (mesh, set, options).
std::string DeformerKey(const std::string& mesh_key, const std::string& set_key,
                        const DeformationOptions& options);

// "hierarchy/v1/<volume>/<set key>".
std::string HierarchyKey(const std::string& set_key, HierarchyVolume volume);

// "hierarchy/v1/<volume>/upper/<64 hex>": the hierarchy over the spheres behind the upper bound
// of a certified distance with internal set `internal_key` and cover `cover_key`
// (UpperBoundSpheres). Routes with neither set (it is made where it is asked for).
std::string UpperBoundHierarchyKey(const std::string& internal_key, const std::string& cover_key,
                                   HierarchyVolume volume);

// Whether `key` names a mesh ("sha256:"), or a sphere set ("spheres/"). O(1).
bool IsMeshKey(absl::string_view key);
bool IsSphereSetKey(absl::string_view key);

}  // namespace inscribe::wire
