// Client's requests carry every argument and setting, and answers become core types field by
// field; Generate from a mesh uploads it again when the server lost it. Against a mock
// Connection.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client_test_support.h"

namespace inscribe::client {
namespace {

using ::testing::_;
using ::testing::ElementsAre;
using ::testing::InSequence;
using ::testing::Return;
using ::testing::Truly;

TEST(Client, GenerateSendsEverySettingAndConvertsTheResult) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, Generate(_, _, _))
      .WillOnce([](const v1::GenerateRequest& request, Deadline,
                   const std::function<void(double)>& on_progress) {
        EXPECT_EQ(request.mesh_sha256(), "sha256:cube");
        const v1::GenerateParameters& p = request.parameters();
        EXPECT_EQ(p.voxel_size(), 0.0);
        EXPECT_EQ(p.max_spheres(), 300);
        EXPECT_EQ(p.object_angle(), 0.5);
        EXPECT_EQ(p.epsilon(), 1e-3);
        EXPECT_EQ(p.samples(), 64);
        EXPECT_TRUE(p.subdivide_boundary());
        EXPECT_TRUE(p.dilate());
        EXPECT_EQ(p.dilation_growth(), 0.5);
        EXPECT_EQ(p.repair(), v1::MESH_REPAIR_FILL);
        EXPECT_TRUE(request.skip_quality());
        EXPECT_EQ(request.progress_interval(), 0.25);
        on_progress(0.25);
        on_progress(0.75);
        v1::GenerateResult result = GenerateOk();
        result.clear_quality();
        return result;
      });
  GenerateSettings settings;
  settings.parameters.max_spheres = 300;
  settings.parameters.medial.object_angle = 0.5;
  settings.parameters.medial.epsilon = 1e-3;
  settings.parameters.medial.samples = 64;
  settings.parameters.medial.subdivide_boundary = true;
  settings.parameters.kind = SphereSetKind::kDilated;
  settings.parameters.dilation.growth = 0.5;
  settings.repair.level = MeshRepair::kFill;
  settings.parameters.evaluate = false;
  GenerateOptions options;
  options.progress_interval = 0.25;
  std::vector<double> progress;
  options.on_progress = [&](double fraction) { progress.push_back(fraction); };

  absl::StatusOr<GenerateResult> result =
      Client(connection).Generate("sha256:cube", settings, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_THAT(progress, ElementsAre(0.25, 0.75));
  EXPECT_EQ(result->sphere_set_key, "spheres/v1/two");
  EXPECT_EQ(result->mesh_sha256, "sha256:cube");
  ASSERT_EQ(result->set.size(), 2u);
  EXPECT_EQ(result->set.spheres[1].center, Vector3(1, 2, 3));
  EXPECT_EQ(result->set.spheres[1].radius, 0.25);
  EXPECT_EQ(result->voxel_size, 0.125);
  EXPECT_EQ(result->seconds, 1.5);
  EXPECT_EQ(result->cache, "computed");
  EXPECT_FALSE(result->quality.has_value());
}

TEST(Client, GenerateReturnsTheQualityWhenSent) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, Generate(_, _, _)).WillOnce(Return(GenerateOk()));
  absl::StatusOr<GenerateResult> result = Client(connection).Generate("sha256:cube", {});
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_TRUE(result->quality.has_value());
  EXPECT_EQ(result->quality->spheres, 2);
  EXPECT_EQ(result->quality->volume_union, 0.75);
}

TEST(Client, GenerateFromAMeshUploadsItAgainOnceWhenTheServerLostIt) {
  auto connection = std::make_shared<MockConnection>();
  {
    InSequence order;
    for (int upload = 0; upload < 2; ++upload) {
      EXPECT_CALL(*connection, PutMesh(Truly([](const v1::PutMeshRequest& request) {
                                         return request.repair().level() == v1::MESH_REPAIR_FILL &&
                                                request.mesh().triangles_size() == 36;
                                       }),
                                       _))
          .WillOnce(Return(PutMeshOk()));
      EXPECT_CALL(*connection, Generate(Truly([](const v1::GenerateRequest& request) {
                                          return request.mesh_sha256() == "sha256:cube";
                                        }),
                                        _, _))
          .WillOnce(Return(upload == 0 ? absl::StatusOr<v1::GenerateResult>(
                                             absl::NotFoundError("unknown mesh sha256:cube"))
                                       : GenerateOk()));
    }
  }
  GenerateSettings settings;
  settings.parameters.voxel_size = 0.125;
  settings.repair.level = MeshRepair::kFill;
  absl::StatusOr<GenerateResult> result =
      Client(connection).Generate(testing::UnitCube(), settings);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->sphere_set_key, "spheres/v1/two");
}

TEST(Client, GenerateFromAMeshUploadsAgainOnlyOnce) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, PutMesh(_, _)).Times(2).WillRepeatedly(Return(PutMeshOk()));
  EXPECT_CALL(*connection, Generate(_, _, _))
      .Times(2)
      .WillRepeatedly(Return(absl::NotFoundError("unknown mesh")));
  EXPECT_EQ(Client(connection).Generate(testing::UnitCube(), {}).status(),
            absl::NotFoundError("unknown mesh"));
}

TEST(Client, GenerateFromAMeshDoesNotUploadAgainForOtherErrors) {
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, PutMesh(_, _)).WillOnce(Return(PutMeshOk()));
  EXPECT_CALL(*connection, Generate(_, _, _))
      .WillOnce(Return(absl::InvalidArgumentError("object_angle")));
  EXPECT_EQ(Client(connection).Generate(testing::UnitCube(), {}).status().code(),
            absl::StatusCode::kInvalidArgument);

  // A refused upload stops before Generate.
  auto refusing = std::make_shared<MockConnection>();
  EXPECT_CALL(*refusing, PutMesh(_, _))
      .WillOnce(Return(absl::FailedPreconditionError("not_closed")));
  EXPECT_CALL(*refusing, Generate(_, _, _)).Times(0);
  EXPECT_EQ(Client(refusing).Generate(testing::OpenUnitCube(), {}).status().code(),
            absl::StatusCode::kFailedPrecondition);
}

TEST(Client, GenerateForAStoredMeshUploadsItOnlyWhenTheServerLostIt) {
  auto connection = std::make_shared<MockConnection>();
  {
    InSequence order;
    EXPECT_CALL(*connection, Generate(_, _, _))
        .WillOnce(Return(absl::NotFoundError("unknown mesh sha256:cube")));
    EXPECT_CALL(*connection, PutMesh(Truly([](const v1::PutMeshRequest& request) {
                                       return request.repair().level() == v1::MESH_REPAIR_FILL &&
                                              request.weld_tolerance() == 0.5 &&
                                              request.mesh().triangles_size() == 36;
                                     }),
                                     _))
        .WillOnce(Return(PutMeshOk()));
    EXPECT_CALL(*connection, Generate(Truly([](const v1::GenerateRequest& request) {
                                        return request.mesh_sha256() == "sha256:cube";
                                      }),
                                      _, _))
        .WillOnce(Return(GenerateOk()));
  }
  GenerateSettings settings;
  settings.repair.level = MeshRepair::kFill;
  settings.repair.weld_tolerance = 0.5;
  absl::StatusOr<GenerateResult> result =
      Client(connection).Generate("sha256:cube", testing::UnitCube(), settings);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->sphere_set_key, "spheres/v1/two");

  // Found at once: nothing is uploaded.
  auto found = std::make_shared<MockConnection>();
  EXPECT_CALL(*found, PutMesh(_, _)).Times(0);
  EXPECT_CALL(*found, Generate(_, _, _)).WillOnce(Return(GenerateOk()));
  EXPECT_TRUE(Client(found).Generate("sha256:cube", testing::UnitCube(), {}).ok());

  // Lost again after the second upload: the server's answer.
  auto losing = std::make_shared<MockConnection>();
  EXPECT_CALL(*losing, PutMesh(_, _)).WillOnce(Return(PutMeshOk()));
  EXPECT_CALL(*losing, Generate(_, _, _))
      .Times(2)
      .WillRepeatedly(Return(absl::NotFoundError("unknown mesh")));
  EXPECT_EQ(Client(losing).Generate("sha256:cube", testing::UnitCube(), {}).status(),
            absl::NotFoundError("unknown mesh"));
}

TEST(Client, DistanceSendsPosesVolumeAndToleranceAndConvertsResults) {
  RigidPose a;
  a.translation = Vector3(1, 2, 3);
  RigidPose b0, b1;
  b1.rotation = Eigen::Quaterniond(0, 1, 0, 0);
  b1.translation = Vector3(-1, 0, 4);
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, Distance(_, _))
      .WillOnce([](const v1::DistanceRequest& request, Deadline) {
        EXPECT_EQ(request.sphere_set_a(), "spheres/v1/a");
        EXPECT_EQ(request.sphere_set_b(), "spheres/v1/b");
        EXPECT_EQ(request.volume(), v1::RSS);
        EXPECT_THAT(request.poses_a().values(), ElementsAre(1, 0, 0, 0, 1, 2, 3));
        EXPECT_THAT(request.poses_b().values(),
                    ElementsAre(1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 4));
        EXPECT_EQ(request.tolerance().abs_err(), 0.5);
        EXPECT_EQ(request.tolerance().rel_err(), 0.25);
        EXPECT_TRUE(request.tolerance().has_closer_than());
        EXPECT_EQ(request.tolerance().closer_than(), -0.125);
        return DistanceOk(2);
      })
      .WillOnce([](const v1::DistanceRequest& request, Deadline) {
        EXPECT_EQ(request.volume(), v1::SPHERE);
        EXPECT_FALSE(request.tolerance().has_closer_than());  // a distance query
        return DistanceOk(2);
      });
  Client client(connection);
  DistanceOptions options;
  options.volume = HierarchyVolume::kRss;
  options.tolerance.abs_err = 0.5;
  options.tolerance.rel_err = 0.25;
  options.tolerance.closer_than = -0.125;
  absl::StatusOr<DistanceBatchResult> batch =
      client.Distance("spheres/v1/a", "spheres/v1/b", {a}, {b0, b1}, options);
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_EQ(batch->server_seconds, 0.5);
  ASSERT_EQ(batch->results.size(), 2u);
  const DistanceResult& r = batch->results[1];
  EXPECT_EQ(r.distance, 1.0);
  EXPECT_EQ(r.sphere_a, 1);
  EXPECT_EQ(r.sphere_b, 2);
  EXPECT_EQ(r.point_a, Vector3(1, 0, 0));
  EXPECT_EQ(r.point_b, Vector3(1, 1, 0));
  EXPECT_TRUE(r.closer);
  EXPECT_FALSE(batch->results[0].closer);

  ASSERT_TRUE(client.Distance("spheres/v1/a", "spheres/v1/b", {a}, {b0, b1}).ok());
}

TEST(Client, UpdateDeformationSendsVerticesRowByRowAndReadsTheBounds) {
  Vertices vertices(2, 3);
  vertices << 1, 2, 3, 4, 5, 6;
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, UpdateDeformation(_, _))
      .WillOnce([](const v1::UpdateDeformationRequest& request, Deadline) {
        EXPECT_EQ(request.mesh_sha256(), "sha256:cube");
        EXPECT_EQ(request.sphere_set_key(), "spheres/v1/two");
        EXPECT_THAT(request.vertices(), ElementsAre(1, 2, 3, 4, 5, 6));
        EXPECT_EQ(request.xi(), 0.01);
        EXPECT_TRUE(request.strict() && request.bounds() && request.store() &&
                    request.interpolated_normal());
        v1::UpdateDeformationResponse response = DeformationOk();
        response.set_nerr_lower(0.1);
        response.set_nerr_upper(0.2);
        response.set_nerr_upper_uniform_xi(0.3);
        response.set_bounds_seconds(0.4);
        response.set_max_shrink_steps(5);
        response.set_sphere_set_key("spheres/v1/moved");
        response.set_deformed_mesh_sha256("sha256:moved");
        return response;
      })
      .WillOnce(Return(DeformationOk()));
  Client client(connection);
  DeformationSettings settings;
  settings.options.xi = 0.01;
  settings.options.strict = settings.bounds = settings.store = true;
  settings.options.direction = ContactDirection::kInterpolatedNormal;
  absl::StatusOr<DeformationResult> moved =
      client.UpdateDeformation("sha256:cube", "spheres/v1/two", vertices, settings);
  ASSERT_TRUE(moved.ok()) << moved.status();
  EXPECT_THAT(moved->reference_index, ElementsAre(0, 3));
  EXPECT_EQ(moved->set.spheres[0].radius, 0.5);
  EXPECT_EQ(moved->max_shrink_steps, 5);
  EXPECT_EQ(moved->sphere_set_key, "spheres/v1/moved");
  EXPECT_EQ(moved->deformed_mesh_sha256, "sha256:moved");
  ASSERT_TRUE(moved->bounds.has_value());
  EXPECT_EQ(moved->bounds->nerr_lower, 0.1);
  EXPECT_EQ(moved->bounds->nerr_upper, 0.2);
  EXPECT_EQ(moved->bounds->nerr_upper_uniform_xi, 0.3);
  EXPECT_EQ(moved->bounds->seconds, 0.4);

  // Bounds not asked for: none reported.
  moved = client.UpdateDeformation("sha256:cube", "spheres/v1/two", vertices);
  ASSERT_TRUE(moved.ok()) << moved.status();
  EXPECT_FALSE(moved->bounds.has_value());
}

TEST(Client, PutSphereSetAndEvaluateSendTheSetTheKeyAndTheSettings) {
  SphereSet set;
  set.spheres = {Sphere{Vector3(1, 2, 3), 0.5}};
  set.contacts = {SurfaceContact{7, Vector3(0.25, 0.25, 0.5)}};
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, PutSphereSet(_, _))
      .WillOnce([](const v1::PutSphereSetRequest& request, Deadline) {
        EXPECT_EQ(request.mesh_sha256(), "sha256:cube");
        EXPECT_THAT(request.spheres().centers(), ElementsAre(1, 2, 3));
        EXPECT_THAT(request.spheres().contact_triangles(), ElementsAre(7));
        v1::PutSphereSetResponse response = PutSphereSetOk();
        response.set_already_stored(true);
        return response;
      });
  EXPECT_CALL(*connection, Evaluate(_, _))
      .WillOnce([](const v1::EvaluateRequest& request, Deadline) {
        EXPECT_EQ(request.spheres_case(), v1::EvaluateRequest::kSphereSetKey);
        EXPECT_EQ(request.sphere_set_key(), "spheres/v1/two");
        EXPECT_TRUE(request.has_samples());
        EXPECT_EQ(request.samples(), 0);
        EXPECT_EQ(request.voxel_size(), 0.25);
        EXPECT_EQ(request.coverage_tolerance(), 0.001);
        return EvaluateOk();
      })
      .WillOnce([](const v1::EvaluateRequest& request, Deadline) {
        EXPECT_EQ(request.spheres_case(), v1::EvaluateRequest::kSphereSet);
        EXPECT_THAT(request.sphere_set().radii(), ElementsAre(0.5));
        EXPECT_EQ(request.mesh_sha256(), "sha256:cube");
        // Core's defaults stay off the wire.
        EXPECT_FALSE(request.has_samples() || request.has_coverage_tolerance());
        return EvaluateOk();
      });
  Client client(connection);
  absl::StatusOr<PutSphereSetResult> put = client.PutSphereSet(set, "sha256:cube");
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->sphere_set_key, "spheres/v1/two");
  EXPECT_TRUE(put->already_stored);

  EvaluateSettings settings;
  settings.surface_samples = 0;
  settings.voxel_size = 0.25;
  settings.coverage_tolerance = 0.001;
  absl::StatusOr<QualityReport> by_key = client.Evaluate("sha256:cube", "spheres/v1/two", settings);
  ASSERT_TRUE(by_key.ok()) << by_key.status();
  EXPECT_EQ(by_key->nerr, 0.125);
  EXPECT_TRUE(client.Evaluate("sha256:cube", set).ok());
}

TEST(Client, CacheStatsCopiesEveryCounter) {
  v1::CacheStatsResponse response;
  response.set_entries(1);
  response.set_bytes(2);
  response.set_memory_hits(3);
  response.set_disk_hits(4);
  response.set_hits(5);
  response.set_misses(6);
  response.set_computations(7);
  response.set_joined(8);
  response.set_evictions(9);
  response.set_disk_entries(10);
  response.set_disk_bytes(11);
  response.set_disk_errors(12);
  response.set_disk_bytes_limit(24);
  response.set_disk_evictions(25);
  response.set_disk_evicted_bytes(26);
  response.set_disk_writes_too_large(27);
  auto connection = std::make_shared<MockConnection>();
  EXPECT_CALL(*connection, CacheStats(_, _)).WillOnce(Return(response));
  absl::StatusOr<ServerCacheStats> s = Client(connection).CacheStats();
  ASSERT_TRUE(s.ok());
  EXPECT_THAT(
      (std::vector<std::int64_t>{
          s->entries, s->bytes, s->memory_hits, s->disk_hits, s->hits, s->misses, s->computations,
          s->joined, s->evictions, s->disk_entries, s->disk_bytes, s->disk_errors,
          s->disk_bytes_limit, s->disk_evictions, s->disk_evicted_bytes, s->disk_writes_too_large}),
      ElementsAre(1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 24, 25, 26, 27));
}

}  // namespace
}  // namespace inscribe::client
