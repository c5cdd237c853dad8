// The sphere set and the mesh a call names: a set cached by key or sent inline, against a
// stored mesh (Evaluate, CertifyCover), and the mesh a cached set is moved on
// (UpdateDeformation). Private to the server.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "admission.h"
#include "inscribe/geometry/sphere.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {

// The mesh a call is about: the request's, else the one the set names. INVALID_ARGUMENT when
// neither names one, or when they differ (contacts index one mesh's triangles).
inline absl::StatusOr<std::string> MeshKeyFor(const std::string& requested,
                                              const SphereSetEntry& set,
                                              const std::string& set_key) {
  const std::string& own = set.result.mesh_sha256();
  if (requested.empty()) {
    if (own.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("mesh_sha256 is required: sphere set ",
                                                     set_key, " was uploaded without a mesh"));
    }
    return own;
  }
  if (absl::Status s = CheckKey(requested, "mesh_sha256"); !s.ok()) return s;
  if (!own.empty() && own != requested) {
    return absl::InvalidArgumentError(
        absl::StrCat("sphere set ", set_key, " was made for mesh ", own, ", not ", requested));
  }
  return requested;
}

// The O(1) checks of a call on "a set, cached by key or sent inline, against a mesh"
// (Evaluate, CertifyCover): an inline set within --max-spheres and a mesh key, or a set key.
template <class Request>
absl::Status CheckSpheresRequest(const Request& request, std::int64_t max_spheres) {
  if (request.has_sphere_set()) {
    if (request.sphere_set().radii_size() > max_spheres) {
      return absl::ResourceExhaustedError(
          absl::StrCat("sphere_set has ", request.sphere_set().radii_size(),
                       " spheres; this server's limit (--max-spheres) is ", max_spheres));
    }
    return CheckKey(request.mesh_sha256(), "mesh_sha256");
  }
  return CheckKey(request.sphere_set_key(), "sphere_set_key (or an inline sphere_set)");
}

// The spheres and the mesh such a call names, on the pool: an inline set and the request's
// mesh, or a cached set (its memory reserved while this lives) and the mesh it names.
struct NamedSpheres {
  std::shared_ptr<const StoredMeshEntry> mesh;
  std::shared_ptr<const SphereSetEntry> cached;
  SphereSet inline_set;
  MemoryBudget::Reservation reservation;

  const std::vector<Sphere>& spheres() const {
    return cached ? cached->set.spheres : inline_set.spheres;
  }
};

template <class Request>
absl::StatusOr<NamedSpheres> ResolveSpheres(const Request& request, ResultStore& store,
                                            Admission& admission, absl::string_view call) {
  NamedSpheres out;
  std::string mesh_key = request.mesh_sha256();
  if (request.has_sphere_set()) {
    absl::StatusOr<SphereSet> set = wire::SphereSetFromProto(request.sphere_set(), "sphere_set");
    if (!set.ok()) return set.status();
    out.inline_set = *std::move(set);
  } else {
    absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set =
        store.GetSphereSet(request.sphere_set_key());
    if (!set.ok()) return set.status();
    out.cached = *std::move(set);
    absl::StatusOr<MemoryBudget::Reservation> more = admission.Reserve(
        static_cast<std::int64_t>(out.cached->set.spheres.size()) * MemoryCosts::kPerSphere,
        absl::StrCat(call, " of ", out.cached->set.spheres.size(), " cached spheres"));
    if (!more.ok()) return more.status();
    out.reservation = *std::move(more);
    absl::StatusOr<std::string> key =
        MeshKeyFor(request.mesh_sha256(), *out.cached, request.sphere_set_key());
    if (!key.ok()) return key.status();
    mesh_key = *std::move(key);
  }
  absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = store.GetMesh(mesh_key);
  if (!mesh.ok()) return mesh.status();
  out.mesh = *std::move(mesh);
  return out;
}

}  // namespace inscribe::server
