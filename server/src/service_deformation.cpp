// UpdateDeformation (paper Section V): a cached set moved onto a deformed frame of its stored
// mesh, by the deformer the store keeps between calls. O(1) checks on the gRPC thread, the rest
// on the pool through ResultStore.
#include <cmath>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "admission.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/medial/sphere_deformation.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/wire/convert.h"
#include "memory_budget.h"
#include "named_spheres.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// Copies packed xyz triples into #V x 3 vertices. INVALID_ARGUMENT for a length that is not
// 3 * expected (naming both); a non-finite coordinate makes the frame an unusable mesh
// (UnusableMeshError, naming the vertex).
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
      return UnusableMeshError(
          absl::StrCat("vertices: vertex ", i / 3, " has a non-finite coordinate"));
    }
    vertices(i / 3, i % 3) = x;
  }
  return vertices;
}

}  // namespace

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
  absl::StatusOr<wire::DeformationSettings> settings = wire::DeformationSettingsFromProto(*request);
  if (precheck.ok() && !settings.ok()) precheck = settings.status();
  const std::int64_t vertex_count = request->vertices_size() / 3;
  return RunUnary(
      context, "UpdateDeformation", 0, precheck,
      vertex_count * MemoryCosts::kPerDeformVertex + MemoryCosts::kSmallCall,
      absl::StrCat("UpdateDeformation of ", vertex_count, " vertices"),
      [this, request, response,
       settings = settings.value_or(wire::DeformationSettings{})]() -> absl::Status {
        absl::StatusOr<std::shared_ptr<const SphereSetEntry>> set =
            store_->GetSphereSet(request->sphere_set_key());
        if (!set.ok()) return set.status();
        // The set's size is known only now: its moved copy, and the union volume for bounds.
        const std::int64_t spheres = static_cast<std::int64_t>((*set)->set.spheres.size());
        absl::StatusOr<MemoryBudget::Reservation> more = admission_->Reserve(
            spheres * (settings.bounds ? MemoryCosts::kPerSphere : MemoryCosts::kPerSphere / 4),
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

        const DeformationOptions& options = settings.options;
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
          if (settings.bounds) {
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
        if (settings.bounds) wire::DeformationBoundsToProto(*bounds, response);
        if (settings.store) {
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

}  // namespace inscribe::server
