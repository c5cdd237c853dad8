// The RPCs that take a mesh: InspectMesh (validation, a report) and PutMesh (validated and
// stored under its content hash). Each checks the mesh's shape and size on the gRPC thread and
// validates it on the pool.
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/wire/convert.h"
#include "mesh_sizes.h"
#include "result_store.h"
#include "service_checks.h"

namespace inscribe::server {
namespace {

// The body of InspectMesh, run on the pool. Only expected failures are returned; the mesh's
// own problems are issues in the report, not errors.
absl::Status RunInspectMesh(const v1::InspectMeshRequest& request,
                            v1::InspectMeshResponse* response) {
  absl::StatusOr<Mesh> mesh = wire::MeshFromProto(request.mesh());
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<RepairOptions> repair = wire::RepairOptionsFromProto(request);
  if (!repair.ok()) return repair.status();
  ValidateOptions options;
  options.check_self_intersections = !request.skip_self_intersections();
  options.repair = *repair;
  const ValidatedMesh validated = ValidateMesh(*std::move(mesh), options);
  const MeshReport& report = validated.report;
  // As the CLI does: a hash over NaNs or dangling indices would key nothing usable.
  if (report.non_finite_vertices == 0 && report.out_of_range_indices == 0) {
    response->set_mesh_sha256(FormatSha256(MeshSha256(validated.mesh)));
  }
  wire::MeshReportToProto(report, response->mutable_report());
  return absl::OkStatus();
}

}  // namespace

grpc::ServerUnaryReactor* InscribeService::InspectMesh(grpc::CallbackServerContext* context,
                                                       const v1::InspectMeshRequest* request,
                                                       v1::InspectMeshResponse* response) {
  return RunUnary(
      context, "InspectMesh", wire::TriangleCount(request->mesh()), CheckMesh(request->mesh()),
      MeshWorkBytes(request->mesh()),
      absl::StrCat("InspectMesh of ", wire::TriangleCount(request->mesh()), " triangles"),
      [request, response] { return RunInspectMesh(*request, response); });
}

grpc::ServerUnaryReactor* InscribeService::PutMesh(grpc::CallbackServerContext* context,
                                                   const v1::PutMeshRequest* request,
                                                   v1::PutMeshResponse* response) {
  return RunUnary(context, "PutMesh", wire::TriangleCount(request->mesh()),
                  CheckMesh(request->mesh()), MeshWorkBytes(request->mesh()),
                  absl::StrCat("PutMesh of ", wire::TriangleCount(request->mesh()), " triangles"),
                  [this, request, response]() -> absl::Status {
                    absl::StatusOr<Mesh> mesh = wire::MeshFromProto(request->mesh());
                    if (!mesh.ok()) return mesh.status();
                    bool already = false;
                    absl::StatusOr<RepairOptions> asked = wire::RepairOptionsFromProto(*request);
                    if (!asked.ok()) return asked.status();
                    ValidateOptions repair;
                    repair.repair = *asked;
                    absl::StatusOr<std::shared_ptr<const StoredMeshEntry>> stored =
                        store_->PutMesh(*std::move(mesh), repair, &already);
                    if (!stored.ok()) return stored.status();
                    mesh_sizes_->Record((*stored)->key, MeshSize::Of((*stored)->mesh()));
                    response->set_mesh_sha256((*stored)->key);
                    wire::MeshReportToProto((*stored)->solid.report, response->mutable_report());
                    response->set_already_stored(already);
                    return absl::OkStatus();
                  });
}

}  // namespace inscribe::server
