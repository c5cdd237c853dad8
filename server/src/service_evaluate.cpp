// Evaluate: the quality of a sphere set (cached by key, or sent inline) against a stored mesh
// (paper Section IV-B measures), on the pool.
#include <algorithm>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "admission.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "named_spheres.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// Boundary samples Evaluate takes at most: ~100 ms per million samples and 1,000 spheres on
// one core, so this bounds a call to seconds, not hours.
constexpr std::int64_t kMaxEvaluateSamples = 10'000'000;

}  // namespace

grpc::ServerUnaryReactor* InscribeService::Evaluate(grpc::CallbackServerContext* context,
                                                    const v1::EvaluateRequest* request,
                                                    v1::EvaluateResponse* response) {
  absl::Status precheck = CheckSpheresRequest(*request, limits_.max_spheres);
  if (precheck.ok() && request->samples() > kMaxEvaluateSamples) {
    precheck = absl::InvalidArgumentError(absl::StrCat(
        "samples is ", request->samples(), "; at most ", kMaxEvaluateSamples, " are taken"));
  }
  absl::StatusOr<QualityOptions> quality = wire::QualityOptionsFromProto(*request);
  if (precheck.ok()) precheck = quality.status();
  // Samples and an inline set are in the request; a cached set's size is reserved on the pool.
  const std::int64_t samples = quality.ok() ? quality->surface_samples : 0;
  const std::int64_t inline_spheres = request->sphere_set().radii_size();
  return RunUnary(
      context, "Evaluate", 0, precheck,
      std::min(samples, kMaxEvaluateSamples) * MemoryCosts::kPerSample +
          inline_spheres * MemoryCosts::kPerSphere + MemoryCosts::kSmallCall,
      absl::StrCat("Evaluate with ", samples, " samples and ", inline_spheres, " inline spheres"),
      [this, request, response, options = quality.value_or(QualityOptions())]() -> absl::Status {
        absl::StatusOr<NamedSpheres> named =
            ResolveSpheres(*request, *store_, *admission_, "Evaluate");
        if (!named.ok()) return named.status();
        absl::StatusOr<QualityReport> report =
            EvaluateSpheres(named->mesh->solid.oracle, named->spheres(), options);
        if (!report.ok()) return report.status();
        wire::QualityReportToProto(*report, response->mutable_quality());
        return absl::OkStatus();
      });
}

}  // namespace inscribe::server
