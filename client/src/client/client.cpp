#include "inscribe/client/client.h"

#include <algorithm>
#include <functional>
#include <random>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "inscribe/wire/convert.h"

namespace inscribe::client {
namespace {

// Wait before attempt `attempt + 1` (attempt counts from 1): exponential, capped, jittered.
std::chrono::milliseconds Backoff(const RetryPolicy& policy, int attempt) {
  double ms = static_cast<double>(policy.initial_backoff.count());
  for (int i = 1; i < attempt; ++i) ms *= policy.multiplier;
  ms = std::min(ms, static_cast<double>(policy.max_backoff.count()));
  thread_local std::mt19937 random_bits{std::random_device{}()};
  ms *= std::uniform_real_distribution<double>(0.5, 1.0)(random_bits);
  return std::chrono::milliseconds(static_cast<std::int64_t>(ms));
}

// The retry and failover loop (see connection.h): runs `attempt` until it succeeds, fails with
// a code other than UNAVAILABLE, the attempts run out, or the next wait would end past
// `deadline`. An UNAVAILABLE carrying kRetryElsewherePayload (another replica can take the
// call) is retried at once. For idempotent calls only. Every attempt gets the same (overall)
// deadline.
absl::Status RetryIdempotent(const RetryPolicy& policy, Deadline deadline,
                             const std::function<absl::Status(Deadline)>& attempt) {
  const int max_attempts = std::max(1, policy.max_attempts);
  for (int n = 1;; ++n) {
    absl::Status status = attempt(deadline);
    if (status.code() != absl::StatusCode::kUnavailable) return status;
    const bool elsewhere = status.GetPayload(kRetryElsewherePayload).has_value();
    status.ErasePayload(kRetryElsewherePayload);
    const std::chrono::milliseconds wait =
        elsewhere ? std::chrono::milliseconds(0) : Backoff(policy, n);
    if (n == max_attempts || std::chrono::system_clock::now() + wait >= deadline) {
      if (n == 1) return status;
      return absl::UnavailableError(
          absl::StrCat(status.message(), " (gave up after ", n, " attempts)"));
    }
    std::this_thread::sleep_for(wait);
  }
}

// RetryIdempotent for an attempt that returns a response: the last attempt's response, or the
// final error (with RetryIdempotent's "gave up" note).
template <typename Attempt>
auto Retried(const RetryPolicy& policy, Deadline deadline, const Attempt& attempt)
    -> decltype(attempt(deadline)) {
  decltype(attempt(deadline)) response = absl::UnknownError("never attempted");
  const absl::Status status = RetryIdempotent(policy, deadline, [&](Deadline d) {
    response = attempt(d);
    return response.status();
  });
  if (!status.ok()) return status;
  return response;
}

Deadline DeadlineAfter(const std::optional<std::chrono::milliseconds>& timeout,
                       const ClientOptions& options) {
  return std::chrono::system_clock::now() + timeout.value_or(options.default_timeout);
}

// A response the server should never send (a bug or a version mismatch, not the caller's
// fault): INTERNAL, naming the RPC and what is wrong with it.
absl::Status Malformed(absl::string_view rpc, absl::string_view problem) {
  return absl::InternalError(absl::StrCat("malformed ", rpc, " response: ", problem));
}

absl::StatusOr<PutMeshResult> PutMeshUntil(Connection& connection, const RetryPolicy& retry,
                                           const v1::PutMeshRequest& request, Deadline deadline) {
  absl::StatusOr<v1::PutMeshResponse> response =
      Retried(retry, deadline, [&](Deadline d) { return connection.PutMesh(request, d); });
  if (!response.ok()) return response.status();
  absl::StatusOr<MeshReport> report = wire::MeshReportFromProto(response->report());
  if (!report.ok()) return Malformed("PutMesh", report.status().message());
  return PutMeshResult{std::move(*response->mutable_mesh_sha256()), *std::move(report),
                       response->already_stored()};
}

absl::StatusOr<PutSphereSetResult> PutSphereSetUntil(Connection& connection,
                                                     const RetryPolicy& retry,
                                                     const v1::PutSphereSetRequest& request,
                                                     Deadline deadline) {
  absl::StatusOr<v1::PutSphereSetResponse> response =
      Retried(retry, deadline, [&](Deadline d) { return connection.PutSphereSet(request, d); });
  if (!response.ok()) return response.status();
  return PutSphereSetResult{std::move(*response->mutable_sphere_set_key()),
                            response->already_stored()};
}

v1::GenerateRequest GenerateRequestFor(const std::string& mesh_sha256,
                                       const GenerateSettings& settings,
                                       const GenerateOptions& options) {
  v1::GenerateRequest request;
  wire::GenerateRequestToProto(mesh_sha256, settings.parameters, settings.repair.level, &request);
  request.set_progress_interval(options.progress_interval);
  return request;
}

absl::StatusOr<GenerateResult> GenerateUntil(Connection& connection, const RetryPolicy& retry,
                                             const v1::GenerateRequest& request,
                                             const std::function<void(double)>& on_progress,
                                             Deadline deadline) {
  absl::StatusOr<v1::GenerateResult> response = Retried(
      retry, deadline, [&](Deadline d) { return connection.Generate(request, d, on_progress); });
  if (!response.ok()) return response.status();
  absl::StatusOr<GeneratedSphereSet> generated = wire::GeneratedSphereSetFromProto(*response);
  if (!generated.ok()) return Malformed("Generate", generated.status().message());
  GenerateResult result;
  static_cast<GeneratedSphereSet&>(result) = *std::move(generated);
  result.sphere_set_key = std::move(*response->mutable_sphere_set_key());
  result.mesh_sha256 = std::move(*response->mutable_mesh_sha256());
  result.cache = std::move(*response->mutable_cache());
  return result;
}

v1::PutMeshRequest PutMeshRequestFor(const Mesh& mesh, const RepairOptions& repair) {
  v1::PutMeshRequest request;
  wire::MeshToProto(mesh, request.mutable_mesh());
  wire::RepairOptionsToProto(repair, &request);
  return request;
}

// Generate for the mesh that `put` stored as `mesh_sha256`. When the server has dropped it
// since (NOT_FOUND: evicted, or restarted without its disk tier), `put` uploads it again, once,
// and Generate asks again; a second NOT_FOUND is the server's answer.
absl::StatusOr<GenerateResult> GenerateUploadingAgain(
    Connection& connection, const RetryPolicy& retry, const v1::PutMeshRequest& put,
    const std::string& mesh_sha256, const GenerateSettings& settings,
    const GenerateOptions& options, Deadline deadline) {
  v1::GenerateRequest request = GenerateRequestFor(mesh_sha256, settings, options);
  absl::StatusOr<GenerateResult> generated =
      GenerateUntil(connection, retry, request, options.on_progress, deadline);
  if (generated.status().code() != absl::StatusCode::kNotFound) return generated;
  absl::StatusOr<PutMeshResult> stored = PutMeshUntil(connection, retry, put, deadline);
  if (!stored.ok()) return stored.status();
  request.set_mesh_sha256(stored->mesh_sha256);
  return GenerateUntil(connection, retry, request, options.on_progress, deadline);
}

absl::StatusOr<QualityReport> EvaluateUntil(Connection& connection, const RetryPolicy& retry,
                                            v1::EvaluateRequest& request,
                                            const EvaluateSettings& settings, Deadline deadline) {
  wire::QualityOptionsToProto(settings, &request);
  absl::StatusOr<v1::EvaluateResponse> response =
      Retried(retry, deadline, [&](Deadline d) { return connection.Evaluate(request, d); });
  if (!response.ok()) return response.status();
  if (!response->has_quality()) return Malformed("Evaluate", "no quality report");
  return wire::QualityReportFromProto(response->quality());
}

absl::StatusOr<CoverCertificate> CertifyUntil(Connection& connection, const RetryPolicy& retry,
                                              v1::CertifyCoverRequest& request,
                                              const CoverCertifyOptions& settings,
                                              Deadline deadline) {
  request.set_resolution(settings.resolution);
  absl::StatusOr<v1::CertifyCoverResponse> response =
      Retried(retry, deadline, [&](Deadline d) { return connection.CertifyCover(request, d); });
  if (!response.ok()) return response.status();
  if (!response->has_certificate()) return Malformed("CertifyCover", "no certificate");
  absl::StatusOr<CoverCertificate> certificate =
      wire::CoverCertificateFromProto(response->certificate());
  if (!certificate.ok()) return Malformed("CertifyCover", certificate.status().message());
  return certificate;
}

}  // namespace

Client::Client(std::shared_ptr<Connection> connection, ClientOptions options)
    : connection_(std::move(connection)), options_(std::move(options)) {}

absl::StatusOr<InspectMeshResult> Client::InspectMesh(const Mesh& mesh,
                                                      const InspectMeshOptions& options) const {
  v1::InspectMeshRequest request;
  wire::MeshToProto(mesh, request.mutable_mesh());
  request.set_skip_self_intersections(options.skip_self_intersections);
  wire::RepairOptionsToProto(options.repair, &request);
  absl::StatusOr<v1::InspectMeshResponse> response =
      Retried(options_.retry, DeadlineAfter(options.timeout, options_),
              [&](Deadline d) { return connection_->InspectMesh(request, d); });
  if (!response.ok()) return response.status();
  absl::StatusOr<MeshReport> report = wire::MeshReportFromProto(response->report());
  if (!report.ok()) return Malformed("InspectMesh", report.status().message());
  return InspectMeshResult{std::move(*response->mutable_mesh_sha256()), *std::move(report)};
}

absl::StatusOr<PutMeshResult> Client::PutMesh(const Mesh& mesh,
                                              const PutMeshOptions& options) const {
  return PutMeshUntil(*connection_, options_.retry, PutMeshRequestFor(mesh, options.repair),
                      DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<GenerateResult> Client::Generate(const std::string& mesh_sha256,
                                                const GenerateSettings& settings,
                                                const GenerateOptions& options) const {
  // Checked before sending: the wire cannot carry some bad values (a voxel size of 0 reads as
  // unset), and core's message is the one to give.
  if (absl::Status checked = CheckSphereSetParameters(settings.parameters); !checked.ok()) {
    return checked;
  }
  return GenerateUntil(*connection_, options_.retry,
                       GenerateRequestFor(mesh_sha256, settings, options), options.on_progress,
                       DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<GenerateResult> Client::Generate(const Mesh& mesh, const GenerateSettings& settings,
                                                const GenerateOptions& options) const {
  if (absl::Status checked = CheckSphereSetParameters(settings.parameters); !checked.ok()) {
    return checked;
  }
  // One deadline for the uploads and generations together; the mesh is converted once.
  const Deadline deadline = DeadlineAfter(options.timeout, options_);
  const v1::PutMeshRequest put = PutMeshRequestFor(mesh, settings.repair);
  absl::StatusOr<PutMeshResult> stored = PutMeshUntil(*connection_, options_.retry, put, deadline);
  if (!stored.ok()) return stored.status();
  return GenerateUploadingAgain(*connection_, options_.retry, put, stored->mesh_sha256, settings,
                                options, deadline);
}

absl::StatusOr<GenerateResult> Client::Generate(const std::string& mesh_sha256, const Mesh& mesh,
                                                const GenerateSettings& settings,
                                                const GenerateOptions& options) const {
  if (absl::Status checked = CheckSphereSetParameters(settings.parameters); !checked.ok()) {
    return checked;
  }
  return GenerateUploadingAgain(*connection_, options_.retry,
                                PutMeshRequestFor(mesh, settings.repair), mesh_sha256, settings,
                                options, DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<PutSphereSetResult> Client::PutSphereSet(const SphereSet& spheres,
                                                        const std::string& mesh_sha256,
                                                        const CallOptions& options) const {
  v1::PutSphereSetRequest request;
  wire::SphereSetToProto(spheres, request.mutable_spheres());
  request.set_mesh_sha256(mesh_sha256);
  return PutSphereSetUntil(*connection_, options_.retry, request,
                           DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<PutSphereSetResult> Client::PutCertifiedCover(const SphereSet& spheres,
                                                             const CoverCertificate& certificate,
                                                             const CallOptions& options) const {
  v1::PutSphereSetRequest request;
  wire::SphereSetToProto(spheres, request.mutable_spheres());
  wire::CoverCertificateToProto(certificate, request.mutable_certificate());
  return PutSphereSetUntil(*connection_, options_.retry, request,
                           DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<StoredSphereSet> Client::GetSphereSet(const std::string& sphere_set_key,
                                                     const CallOptions& options) const {
  v1::GetSphereSetRequest request;
  request.set_sphere_set_key(sphere_set_key);
  absl::StatusOr<v1::GetSphereSetResponse> response =
      Retried(options_.retry, DeadlineAfter(options.timeout, options_),
              [&](Deadline d) { return connection_->GetSphereSet(request, d); });
  if (!response.ok()) return response.status();
  absl::StatusOr<SphereSet> spheres = wire::SphereSetFromProto(response->spheres());
  if (!spheres.ok()) return Malformed("GetSphereSet", spheres.status().message());
  return StoredSphereSet{*std::move(spheres), std::move(*response->mutable_mesh_sha256())};
}

absl::StatusOr<SphereHierarchy> Client::GetHierarchy(const std::string& sphere_set_key,
                                                     HierarchyVolume volume,
                                                     const CallOptions& options) const {
  v1::GetHierarchyRequest request;
  request.set_sphere_set_key(sphere_set_key);
  request.set_volume(wire::VolumeToProto(volume));
  absl::StatusOr<v1::GetHierarchyResponse> response =
      Retried(options_.retry, DeadlineAfter(options.timeout, options_),
              [&](Deadline d) { return connection_->GetHierarchy(request, d); });
  if (!response.ok()) return response.status();
  absl::StatusOr<SphereHierarchy> hierarchy = SphereHierarchy::Deserialize(response->hierarchy());
  if (!hierarchy.ok()) {
    return Malformed("GetHierarchy", absl::StrCat("hierarchy: ", hierarchy.status().message()));
  }
  if (hierarchy->volume() != volume) {
    return Malformed("GetHierarchy",
                     absl::StrCat("hierarchy: asked for ", HierarchyVolumeName(volume), ", got ",
                                  HierarchyVolumeName(hierarchy->volume())));
  }
  return hierarchy;
}

absl::StatusOr<DeformationResult> Client::UpdateDeformation(const std::string& mesh_sha256,
                                                            const std::string& sphere_set_key,
                                                            const Vertices& deformed_vertices,
                                                            const DeformationSettings& settings,
                                                            const CallOptions& options) const {
  v1::UpdateDeformationRequest request;
  request.set_mesh_sha256(mesh_sha256);
  request.set_sphere_set_key(sphere_set_key);
  // Row-major #V x 3: the storage is already the wire's x0, y0, z0, x1, ...
  request.mutable_vertices()->Add(deformed_vertices.data(),
                                  deformed_vertices.data() + deformed_vertices.size());
  wire::DeformationSettingsToProto(settings, &request);
  absl::StatusOr<v1::UpdateDeformationResponse> response =
      Retried(options_.retry, DeadlineAfter(options.timeout, options_),
              [&](Deadline d) { return connection_->UpdateDeformation(request, d); });
  if (!response.ok()) return response.status();

  absl::StatusOr<DeformedSpheres> moved = wire::DeformedSpheresFromProto(*response);
  if (!moved.ok()) return Malformed("UpdateDeformation", moved.status().message());
  DeformationResult result;
  static_cast<DeformedSpheres&>(result) = *std::move(moved);
  result.reference_spheres = response->reference_spheres();
  result.deformed_mesh_sha256 = std::move(*response->mutable_deformed_mesh_sha256());
  result.sphere_set_key = std::move(*response->mutable_sphere_set_key());
  // The wire has no presence bit for the bounds: they are there when they were asked for.
  if (settings.bounds) result.bounds = wire::DeformationBoundsFromProto(*response);
  return result;
}

absl::StatusOr<DistanceBatchResult> Client::Distance(const std::string& sphere_set_a,
                                                     const std::string& sphere_set_b,
                                                     const std::vector<RigidPose>& poses_a,
                                                     const std::vector<RigidPose>& poses_b,
                                                     const DistanceOptions& options) const {
  v1::DistanceRequest request;
  request.set_sphere_set_a(sphere_set_a);
  request.set_sphere_set_b(sphere_set_b);
  request.set_volume(wire::VolumeToProto(options.volume));
  wire::PosesToProto(poses_a, request.mutable_poses_a());
  wire::PosesToProto(poses_b, request.mutable_poses_b());
  wire::ToleranceToProto(options.tolerance, request.mutable_tolerance());
  request.set_brute_force(options.brute_force);
  request.set_cover_a(options.cover_a);
  request.set_cover_b(options.cover_b);
  absl::StatusOr<v1::DistanceResponse> response =
      Retried(options_.retry, DeadlineAfter(options.timeout, options_),
              [&](Deadline d) { return connection_->Distance(request, d); });
  if (!response.ok()) return response.status();
  absl::StatusOr<std::vector<DistanceResult>> results =
      wire::DistanceResultsFromProto(response->results());
  if (!results.ok()) return Malformed("Distance", results.status().message());
  if (results->size() != poses_b.size()) {
    return Malformed("Distance", absl::StrCat("results has ", results->size(), " entries for ",
                                              poses_b.size(), " pose pairs"));
  }
  DistanceBatchResult batch;
  if (!options.cover_a.empty()) {
    absl::StatusOr<std::vector<CertifiedDistanceResult>> certified =
        wire::CertifiedDistanceResultsFromProto(response->results());
    if (!certified.ok()) return Malformed("Distance", certified.status().message());
    batch.certified = *std::move(certified);
  }
  batch.results = *std::move(results);
  batch.server_seconds = response->seconds();
  batch.hierarchy_seconds = response->hierarchy_seconds();
  batch.threads = response->threads();
  batch.volume_tests = response->volume_tests();
  batch.sphere_tests = response->sphere_tests();
  return batch;
}

absl::StatusOr<QualityReport> Client::Evaluate(const std::string& mesh_sha256,
                                               const std::string& sphere_set_key,
                                               const EvaluateSettings& settings,
                                               const CallOptions& options) const {
  v1::EvaluateRequest request;
  request.set_mesh_sha256(mesh_sha256);
  request.set_sphere_set_key(sphere_set_key);
  return EvaluateUntil(*connection_, options_.retry, request, settings,
                       DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<QualityReport> Client::Evaluate(const std::string& mesh_sha256,
                                               const SphereSet& spheres,
                                               const EvaluateSettings& settings,
                                               const CallOptions& options) const {
  v1::EvaluateRequest request;
  request.set_mesh_sha256(mesh_sha256);
  wire::SphereSetToProto(spheres, request.mutable_sphere_set());
  return EvaluateUntil(*connection_, options_.retry, request, settings,
                       DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<CoverCertificate> Client::CertifyCover(const std::string& mesh_sha256,
                                                      const std::string& sphere_set_key,
                                                      const CoverCertifyOptions& settings,
                                                      const CallOptions& options) const {
  v1::CertifyCoverRequest request;
  request.set_mesh_sha256(mesh_sha256);
  request.set_sphere_set_key(sphere_set_key);
  return CertifyUntil(*connection_, options_.retry, request, settings,
                      DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<CoverCertificate> Client::CertifyCover(const std::string& mesh_sha256,
                                                      const SphereSet& spheres,
                                                      const CoverCertifyOptions& settings,
                                                      const CallOptions& options) const {
  v1::CertifyCoverRequest request;
  request.set_mesh_sha256(mesh_sha256);
  wire::SphereSetToProto(spheres, request.mutable_sphere_set());
  return CertifyUntil(*connection_, options_.retry, request, settings,
                      DeadlineAfter(options.timeout, options_));
}

absl::StatusOr<ServerCacheStats> Client::CacheStats(const CallOptions& options) const {
  const v1::CacheStatsRequest request;
  absl::StatusOr<v1::CacheStatsResponse> response =
      Retried(options_.retry, DeadlineAfter(options.timeout, options_),
              [&](Deadline d) { return connection_->CacheStats(request, d); });
  if (!response.ok()) return response.status();
  return wire::CacheStatsFromProto(*response);
}

absl::StatusOr<DistanceSession> Client::OpenDistanceSession(
    const DistanceSessionOptions& options) const {
  const Deadline deadline = options.session_timeout
                                ? std::chrono::system_clock::now() + *options.session_timeout
                                : Deadline::max();
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(deadline);
  if (!stream.ok()) return stream.status();
  return DistanceSession(*std::move(stream), options);
}

absl::StatusOr<SceneSession> Client::OpenSceneSession(
    const std::vector<SceneSessionObject>& objects, const SceneSessionOptions& options) const {
  const Deadline deadline = options.session_timeout
                                ? std::chrono::system_clock::now() + *options.session_timeout
                                : Deadline::max();
  absl::StatusOr<std::unique_ptr<SceneStreamConnection>> stream =
      connection_->OpenSceneStream(deadline);
  if (!stream.ok()) return stream.status();
  SceneSession session(*std::move(stream), options);
  if (absl::Status s = session.Create(objects); !s.ok()) return s;
  return session;
}

}  // namespace inscribe::client
