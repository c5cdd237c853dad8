// The InscribeService RPCs on sphere sets made elsewhere or moved: PutSphereSet,
// UpdateDeformation (paper Section V), Evaluate (Section IV-B measures) and CertifyCover. O(1)
// checks on the gRPC thread, the rest on the pool through ResultStore.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "inscribe/balls/sphere_quality.h"
#include "inscribe/cover/cover_certificate.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// Boundary samples Evaluate takes at most: ~100 ms per million samples and 1,000 spheres on
// one core, so this bounds a call to seconds, not hours.
constexpr std::int64_t kMaxEvaluateSamples = 10'000'000;

// The mesh a call is about: the request's, else the one the set names. INVALID_ARGUMENT when
// neither names one, or when they differ (contacts index one mesh's triangles).
absl::StatusOr<std::string> MeshKeyFor(const std::string& requested, const SphereSetEntry& set,
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

// Copies packed xyz triples into #V x 3 vertices. INVALID_ARGUMENT for a length that is not
// 3 * expected (naming both) or a non-finite coordinate (naming the vertex).
absl::StatusOr<Vertices> DeformedVertices(const v1::UpdateDeformationRequest& request,
                                          std::int64_t expected) {
  const int n = request.vertices_size();
  if (n != 3 * expected) {
    return absl::InvalidArgumentError(absl::StrCat("vertices has ", n, " numbers; the mesh has ",
                                                   expected, " vertices, so 3 x ", expected, " = ",
                                                   3 * expected, " are needed"));
  }
  Vertices vertices(expected, 3);
  for (int i = 0; i < n; ++i) {
    const double x = request.vertices(i);
    if (!std::isfinite(x)) {
      return absl::InvalidArgumentError(
          absl::StrCat("vertices: vertex ", i / 3, " has a non-finite coordinate"));
    }
    vertices(i / 3, i % 3) = x;
  }
  return vertices;
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
                                            MemoryBudget& memory, absl::string_view call) {
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
    absl::StatusOr<MemoryBudget::Reservation> more = memory.Reserve(
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

}  // namespace

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

grpc::ServerUnaryReactor* InscribeService::UpdateDeformation(
    grpc::CallbackServerContext* context, const v1::UpdateDeformationRequest* request,
    v1::UpdateDeformationResponse* response) {
  absl::Status precheck = CheckKey(request->sphere_set_key(), "sphere_set_key");
  if (precheck.ok() && request->vertices_size() / 3 > limits_.MaxDeformVertices()) {
    precheck = absl::ResourceExhaustedError(
        absl::StrCat("vertices has ", request->vertices_size() / 3,
                     " vertices; no stored mesh has more than 3 x --max-triangles = ",
                     limits_.MaxDeformVertices()));
  }
  if (precheck.ok() && !(std::isfinite(request->xi()) && request->xi() >= 0.0)) {
    precheck = absl::InvalidArgumentError(
        absl::StrCat("xi must be finite and >= 0 (0 = the default), got ", request->xi()));
  }
  const std::int64_t vertex_count = request->vertices_size() / 3;
  return RunUnary(
      context, "UpdateDeformation", 0, precheck,
      vertex_count * MemoryCosts::kPerDeformVertex + MemoryCosts::kSmallCall,
      absl::StrCat("UpdateDeformation of ", vertex_count, " vertices"),
      [this, request, response]() -> absl::Status {
        absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set =
            store_->GetSphereSet(request->sphere_set_key());
        if (!set.ok()) return set.status();
        // The set's size is known only now: its moved copy, and the union volume for bounds.
        const std::int64_t spheres = static_cast<std::int64_t>((*set)->set.spheres.size());
        absl::StatusOr<MemoryBudget::Reservation> more = memory_->Reserve(
            spheres * (request->bounds() ? MemoryCosts::kPerSphere : MemoryCosts::kPerSphere / 4),
            absl::StrCat("UpdateDeformation of ", spheres, " spheres"));
        if (!more.ok()) return more.status();
        absl::StatusOr<std::string> mesh_key =
            MeshKeyFor(request->mesh_sha256(), **set, request->sphere_set_key());
        if (!mesh_key.ok()) return mesh_key.status();
        absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> mesh = store_->GetMesh(*mesh_key);
        if (!mesh.ok()) return mesh.status();
        absl::StatusOr<Vertices> vertices =
            DeformedVertices(*request, (*mesh)->mesh().num_vertices());
        if (!vertices.ok()) return vertices.status();

        DeformationOptions options;
        options.xi = request->xi();
        options.strict = request->strict();
        options.direction = request->interpolated_normal() ? ContactDirection::kInterpolatedNormal
                                                           : ContactDirection::kCarriedFrame;
        // As the stored mesh's own oracle, unless the caller asks for the exact test.
        options.oracle.inside_test = request->ray_parity() ? InsideTest::kExactWinding
                                                           : InsideTestFor((*mesh)->solid.report);
        absl::StatusOr<std::shared_ptr<const DeformerEntry>> entry =
            store_->GetDeformer(*mesh_key, request->sphere_set_key(), options);
        if (!entry.ok()) return entry.status();

        absl::StatusOr<DeformedSpheres> moved;
        absl::StatusOr<DeformationErrorBounds> bounds;
        {
          // One update at a time per deformer: Update refits its oracle in place, and the
          // bounds read that oracle.
          std::lock_guard<std::mutex> lock((*entry)->mutex);
          moved = (*entry)->deformer.Update(*vertices);
          if (!moved.ok()) return moved.status();
          if (request->bounds()) {
            bounds =
                BoundDeformationError((*entry)->deformer.oracle(), moved->set.spheres, moved->xi);
            if (!bounds.ok()) return bounds.status();
          }
          response->set_reference_spheres(
              static_cast<std::int64_t>((*entry)->deformer.reference_spheres().size()));
        }
        wire::DeformedSpheresToProto(*moved, response);
        const std::string deformed_key =
            FormatSha256(MeshSha256(Mesh{*std::move(vertices), (*entry)->triangles}));
        response->set_deformed_mesh_sha256(deformed_key);
        if (request->bounds()) wire::DeformationBoundsToProto(*bounds, response);
        if (request->store()) {
          // Named by no mesh (the deformed one is not stored); its key routes like the
          // reference set's, so a routing client's Distance on it finds it here.
          absl::StatusOr<std::shared_ptr<const SphereSetEntry>> stored =
              store_->PutSphereSet(std::move(moved->set), "", nullptr, request->sphere_set_key());
          if (!stored.ok()) return stored.status();
          response->set_sphere_set_key((*stored)->result.sphere_set_key());
        }
        return absl::OkStatus();
      });
}

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
            ResolveSpheres(*request, *store_, *memory_, "Evaluate");
        if (!named.ok()) return named.status();
        absl::StatusOr<QualityReport> report =
            EvaluateSpheres(named->mesh->solid.oracle, named->spheres(), options);
        if (!report.ok()) return report.status();
        wire::QualityReportToProto(*report, response->mutable_quality());
        return absl::OkStatus();
      });
}

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
                        ResolveSpheres(*request, *store_, *memory_, "CertifyCover");
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
