// What the Client tests share: a gmock Connection and DistanceStreamConnection, well-formed
// answers of every RPC written field by field, and retries fast enough for tests.
#pragma once

#include <gmock/gmock.h>

#include <chrono>
#include <functional>
#include <memory>

#include "inscribe/client/client.h"
#include "inscribe/client/connection.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/wire/convert.h"
#include "support/synthetic_meshes.h"

namespace inscribe::client {

class MockConnection : public Connection {
 public:
  MOCK_METHOD(absl::StatusOr<v1::InspectMeshResponse>, InspectMesh,
              (const v1::InspectMeshRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::PutMeshResponse>, PutMesh,
              (const v1::PutMeshRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::GenerateResult>, Generate,
              (const v1::GenerateRequest& request, Deadline deadline,
               const std::function<void(double fraction)>& on_progress),
              (override));
  MOCK_METHOD(absl::StatusOr<v1::PutSphereSetResponse>, PutSphereSet,
              (const v1::PutSphereSetRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::GetSphereSetResponse>, GetSphereSet,
              (const v1::GetSphereSetRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::GetHierarchyResponse>, GetHierarchy,
              (const v1::GetHierarchyRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::UpdateDeformationResponse>, UpdateDeformation,
              (const v1::UpdateDeformationRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::DistanceResponse>, Distance,
              (const v1::DistanceRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::EvaluateResponse>, Evaluate,
              (const v1::EvaluateRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::CertifyCoverResponse>, CertifyCover,
              (const v1::CertifyCoverRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<v1::CacheStatsResponse>, CacheStats,
              (const v1::CacheStatsRequest& request, Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<std::unique_ptr<DistanceStreamConnection>>, OpenDistanceStream,
              (Deadline deadline), (override));
  MOCK_METHOD(absl::StatusOr<std::unique_ptr<SceneStreamConnection>>, OpenSceneStream,
              (Deadline deadline), (override));
};

// What a server answers for the unit cube.
inline v1::InspectMeshResponse CubeResponse() {
  v1::InspectMeshResponse response;
  response.set_mesh_sha256("sha256:cube");
  wire::MeshReportToProto(ValidateMesh(testing::UnitCube()).report, response.mutable_report());
  return response;
}

// Two spheres, written field by field: centres (0, 0, 0) and (1, 2, 3), radii 0.5 and 0.25.
inline v1::SphereSet TwoSpheres() {
  v1::SphereSet set;
  for (double v : {0.0, 0.0, 0.0, 1.0, 2.0, 3.0}) set.add_centers(v);
  set.add_radii(0.5);
  set.add_radii(0.25);
  return set;
}

// Well-formed answers of each RPC.
inline v1::PutMeshResponse PutMeshOk() {
  v1::PutMeshResponse response;
  response.set_mesh_sha256("sha256:cube");
  *response.mutable_report() = CubeResponse().report();
  return response;
}
inline v1::GenerateResult GenerateOk() {
  v1::GenerateResult result;
  result.set_sphere_set_key("spheres/v1/two");
  result.set_mesh_sha256("sha256:cube");
  *result.mutable_spheres() = TwoSpheres();
  result.set_voxel_size(0.125);
  result.set_seconds(1.5);
  result.mutable_quality()->set_spheres(2);
  result.mutable_quality()->set_volume_union(0.75);
  result.set_cache("computed");
  return result;
}
inline v1::PutSphereSetResponse PutSphereSetOk() {
  v1::PutSphereSetResponse response;
  response.set_sphere_set_key("spheres/v1/two");
  return response;
}
inline v1::GetSphereSetResponse GetSphereSetOk() {
  v1::GetSphereSetResponse response;
  *response.mutable_spheres() = TwoSpheres();
  response.set_mesh_sha256("sha256:cube");
  return response;
}
inline v1::GetHierarchyResponse HierarchyOk(HierarchyVolume volume) {
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(
      {Sphere{Vector3(0, 0, 0), 0.5}, Sphere{Vector3(1, 2, 3), 0.25}}, volume);
  v1::GetHierarchyResponse response;
  response.set_hierarchy(h->Serialize());
  return response;
}
inline v1::UpdateDeformationResponse DeformationOk() {
  v1::UpdateDeformationResponse response;
  *response.mutable_spheres() = TwoSpheres();
  response.add_reference_index(0);
  response.add_reference_index(3);
  return response;
}
// `n` results: distance i, spheres (i, i + 1), witnesses (i, 0, 0) and (i, 1, 0).
inline v1::DistanceResults Results(int n) {
  v1::DistanceResults results;
  for (int i = 0; i < n; ++i) {
    results.add_distances(i);
    results.add_spheres_a(i);
    results.add_spheres_b(i + 1);
    for (double v : {double(i), 0.0, 0.0}) results.add_points_a(v);
    for (double v : {double(i), 1.0, 0.0}) results.add_points_b(v);
    results.add_closer(i % 2 == 1);
  }
  return results;
}
inline v1::DistanceResponse DistanceOk(int n) {
  v1::DistanceResponse response;
  *response.mutable_results() = Results(n);
  response.set_seconds(0.5);
  return response;
}
inline v1::EvaluateResponse EvaluateOk() {
  v1::EvaluateResponse response;
  response.mutable_quality()->set_spheres(2);
  response.mutable_quality()->set_nerr(0.125);
  return response;
}

// Backoff short enough for tests; the attempts are what is being checked.
inline ClientOptions FastRetries() {
  ClientOptions options;
  options.retry.initial_backoff = std::chrono::milliseconds(1);
  options.retry.max_backoff = std::chrono::milliseconds(4);
  return options;
}

class MockDistanceStream : public DistanceStreamConnection {
 public:
  MOCK_METHOD(absl::StatusOr<v1::DistanceFrameResult>, RoundTrip,
              (const v1::DistanceFrame& frame, Deadline deadline), (override));
  MOCK_METHOD(absl::Status, Finish, (), (override));
  // Called by the destructor: the session let go of the call (which cancels it).
  MOCK_METHOD(void, Destroyed, ());
  ~MockDistanceStream() override { Destroyed(); }
};

class MockSceneStream : public SceneStreamConnection {
 public:
  MOCK_METHOD(absl::StatusOr<v1::SceneReply>, RoundTrip,
              (const v1::SceneMessage& message, Deadline deadline), (override));
  MOCK_METHOD(absl::Status, Finish, (), (override));
  // Called by the destructor: the session let go of the call (which cancels it).
  MOCK_METHOD(void, Destroyed, ());
  ~MockSceneStream() override { Destroyed(); }
};

}  // namespace inscribe::client
