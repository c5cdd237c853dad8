// CertifyCover: proves that a sphere set (cached by key, or sent inline) contains the solid of
// a stored mesh (core's CertifyCover); a cached set's certificate is cached with it, where
// Distance finds it (ResultStore::CoverCertificateOf).
#include <memory>

#include "absl/strings/str_cat.h"
#include "admission.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "named_spheres.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {

grpc::ServerUnaryReactor* InscribeService::CertifyCover(grpc::CallbackServerContext* context,
                                                        const v1::CertifyCoverRequest* request,
                                                        v1::CertifyCoverResponse* response) {
  absl::Status precheck = CheckSpheresRequest(*request, limits_.max_spheres);
  absl::StatusOr<CoverCertifyOptions> options = wire::CoverCertifyOptionsFromProto(*request);
  if (precheck.ok()) precheck = options.status();
  // The octree holds one candidate list per level on each thread; the spheres dominate.
  const std::int64_t inline_spheres = request->sphere_set().radii_size();
  return RunUnary(context, "CertifyCover", 0, precheck,
                  inline_spheres * MemoryCosts::kPerSphere * 4 + MemoryCosts::kSmallCall,
                  absl::StrCat("CertifyCover of ", inline_spheres, " inline spheres"),
                  [this, request, response,
                   options = options.value_or(CoverCertifyOptions())]() -> absl::Status {
                    absl::StatusOr<NamedSpheres> named =
                        ResolveSpheres(*request, *store_, *admission_, "CertifyCover");
                    if (!named.ok()) return named.status();
                    if (named->cached) {
                      // Cached with the set, where Distance finds it (CoverCertificateOf).
                      absl::StatusOr<std::shared_ptr<const CoverCertificate>> certificate =
                          store_->CertifySphereSet(request->sphere_set_key(), named->mesh->key,
                                                   options);
                      if (!certificate.ok()) return certificate.status();
                      wire::CoverCertificateToProto(**certificate, response->mutable_certificate());
                      return absl::OkStatus();
                    }
                    absl::StatusOr<CoverCertificate> certificate =
                        inscribe::CertifyCover(named->mesh->solid, named->spheres(), options);
                    if (!certificate.ok()) return certificate.status();
                    wire::CoverCertificateToProto(*certificate, response->mutable_certificate());
                    return absl::OkStatus();
                  });
}

}  // namespace inscribe::server
