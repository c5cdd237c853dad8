// The RPCs on sphere sets by key: PutSphereSet (a set made elsewhere, stored under a content
// key), GetSphereSet and GetHierarchy (a cached set, and its hierarchy built on first use).
#include <memory>
#include <optional>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {

grpc::ServerUnaryReactor* InscribeService::PutSphereSet(grpc::CallbackServerContext* context,
                                                        const v1::PutSphereSetRequest* request,
                                                        v1::PutSphereSetResponse* response) {
  absl::Status precheck;
  if (request->spheres().radii_size() > limits_.max_spheres) {
    precheck = absl::ResourceExhaustedError(
        absl::StrCat("spheres has ", request->spheres().radii_size(),
                     " spheres; this server's limit (--max-spheres) is ", limits_.max_spheres));
  } else if (!request->mesh_sha256().empty()) {
    precheck = CheckKey(request->mesh_sha256(), "mesh_sha256");
  }
  // No union volume here: the core set and its stored copy, a quarter of kPerSphere.
  const std::int64_t spheres = request->spheres().radii_size();
  return RunUnary(context, "PutSphereSet", 0, precheck, spheres * MemoryCosts::kPerSphere / 4,
                  absl::StrCat("PutSphereSet of ", spheres, " spheres"),
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<SphereSet> set = wire::SphereSetFromProto(request->spheres());
                    if (!set.ok()) return set.status();
                    std::optional<CoverCertificate> certificate;
                    if (request->has_certificate()) {
                      absl::StatusOr<CoverCertificate> given =
                          wire::CoverCertificateFromProto(request->certificate());
                      if (!given.ok()) return given.status();
                      certificate = *std::move(given);
                    }
                    bool already = false;
                    absl::StatusOr<std::shared_ptr<const SphereSetEntry>> entry =
                        store_->PutSphereSet(*std::move(set), request->mesh_sha256(), &already, "",
                                             certificate);
                    if (!entry.ok()) return entry.status();
                    response->set_sphere_set_key((*entry)->result.sphere_set_key());
                    response->set_already_stored(already);
                    return absl::OkStatus();
                  });
}

grpc::ServerUnaryReactor* InscribeService::GetSphereSet(grpc::CallbackServerContext* context,
                                                        const v1::GetSphereSetRequest* request,
                                                        v1::GetSphereSetResponse* response) {
  return RunUnary(context, "GetSphereSet", 0, CheckKey(request->sphere_set_key(), "sphere_set_key"),
                  MemoryCosts::kSmallCall, "GetSphereSet",
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<std::shared_ptr<const SphereSetEntry>> entry =
                        store_->GetSphereSet(request->sphere_set_key());
                    if (!entry.ok()) return entry.status();
                    *response->mutable_spheres() = (*entry)->result.spheres();
                    response->set_mesh_sha256((*entry)->result.mesh_sha256());
                    return absl::OkStatus();
                  });
}

grpc::ServerUnaryReactor* InscribeService::GetHierarchy(grpc::CallbackServerContext* context,
                                                        const v1::GetHierarchyRequest* request,
                                                        v1::GetHierarchyResponse* response) {
  return RunUnary(context, "GetHierarchy", 0, CheckKey(request->sphere_set_key(), "sphere_set_key"),
                  MemoryCosts::kSmallCall, "GetHierarchy",
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<std::shared_ptr<const SphereHierarchy>> h = store_->GetHierarchy(
                        request->sphere_set_key(), wire::VolumeFromProto(request->volume()));
                    if (!h.ok()) return h.status();
                    response->set_hierarchy((*h)->Serialize());
                    return absl::OkStatus();
                  });
}

}  // namespace inscribe::server
