// PutMesh, Generate, GetSphereSet, GetHierarchy, Distance and CacheStats against the real
// server in-process on loopback, with a disk cache; answers checked against the core library
// called directly.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/solid/mesh_validation.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "inscribe/wire/convert.h"
#include "spheres_rpc_fixture.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

TEST_F(SpheresRpcTest, PutMeshKeysByContentAndRefusesUnusableMeshes) {
  const Mesh cube = testing::UnitCube();
  const std::string key = PutMesh(cube);
  EXPECT_EQ(key, FormatSha256(MeshSha256(ValidateMesh(cube).mesh)));

  v1::PutMeshRequest again;
  wire::MeshToProto(cube, again.mutable_mesh());
  v1::PutMeshResponse response;
  ASSERT_TRUE(stub_->PutMesh(Context().get(), again, &response).ok());
  EXPECT_TRUE(response.already_stored());

  v1::PutMeshRequest open;
  wire::MeshToProto(testing::OpenUnitCube(), open.mutable_mesh());
  const grpc::Status refused = stub_->PutMesh(Context().get(), open, &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr("not closed"));

  v1::PutMeshRequest ragged;
  ragged.mutable_mesh()->add_vertices(1.0);
  EXPECT_EQ(stub_->PutMesh(Context().get(), ragged, &response).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

TEST_F(SpheresRpcTest, GenerateComputesOnceThenHitsMemoryThenDiskAfterRestart) {
  const std::string mesh = PutMesh(testing::Icosphere(3));
  v1::GenerateResult first, second, third;
  ASSERT_TRUE(Generate(SphereRequest(mesh, 0.1), &first).ok());
  EXPECT_EQ(first.cache(), "computed");
  EXPECT_GT(first.spheres().radii_size(), 4);
  EXPECT_GT(first.quality().volume_union(), 0.0);
  EXPECT_THAT(first.sphere_set_key(), ::testing::StartsWith("spheres/v1/"));
  const std::int64_t computations = Stats().computations();

  ASSERT_TRUE(Generate(SphereRequest(mesh, 0.1), &second).ok());
  EXPECT_EQ(second.cache(), "memory");
  EXPECT_EQ(second.sphere_set_key(), first.sphere_set_key());
  EXPECT_EQ(second.spheres().SerializeAsString(), first.spheres().SerializeAsString());
  EXPECT_EQ(Stats().computations(), computations);  // no recomputation
  EXPECT_GE(Stats().memory_hits(), 1);

  Restart();
  ASSERT_TRUE(Generate(SphereRequest(mesh, 0.1), &third).ok());
  EXPECT_EQ(third.cache(), "disk");
  EXPECT_EQ(third.spheres().SerializeAsString(), first.spheres().SerializeAsString());
  EXPECT_EQ(Stats().computations(), 0);
  EXPECT_EQ(Stats().disk_hits(), 1);
}

TEST_F(SpheresRpcTest, ConcurrentIdenticalGeneratesComputeOnce) {
  const std::string mesh = PutMesh(testing::Icosphere(3));
  const std::int64_t before = Stats().computations();
  std::vector<std::thread> threads;
  std::vector<std::string> sources(8);
  std::vector<grpc::Status> statuses(8);
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&, i] {
      v1::GenerateResult result;
      statuses[i] = Generate(SphereRequest(mesh, 0.08), &result);
      sources[i] = result.cache();
    });
  }
  for (std::thread& t : threads) t.join();
  for (int i = 0; i < 8; ++i) EXPECT_TRUE(statuses[i].ok()) << statuses[i].error_message();
  EXPECT_EQ(Stats().computations() - before, 1);
  EXPECT_EQ(std::count(sources.begin(), sources.end(), "computed"), 1);
}

TEST_F(SpheresRpcTest, GenerateErrorsHaveTheirCodes) {
  v1::GenerateResult result;
  const std::string unknown = "sha256:" + std::string(64, 'a');
  grpc::Status s = Generate(SphereRequest(unknown, 0.2), &result);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(s.error_message(), HasSubstr("PutMesh"));

  const std::string mesh = PutMesh(testing::UnitCube());
  v1::GenerateRequest both = SphereRequest(mesh, 0.2);
  both.mutable_parameters()->set_max_spheres(10);
  EXPECT_EQ(Generate(both, &result).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  v1::GenerateRequest angle = SphereRequest(mesh, 0.2);
  angle.mutable_parameters()->set_object_angle(4.0);
  s = Generate(angle, &result);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("parameters: object angle"));
  EXPECT_EQ(Generate(SphereRequest("not a key!", 0.2), &result).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// Found by fuzz_requests: every kind of value shares the cache, and a mesh key sent as a
// sphere set key handed the mesh's object to a blind cast; the server crashed.
TEST_F(SpheresRpcTest, KeysOfAnotherKindAreUnknownNotReinterpreted) {
  const std::string mesh = PutMesh(testing::UnitCube());
  v1::GenerateResult generated;
  ASSERT_TRUE(Generate(SphereRequest(mesh, 0.25), &generated).ok());
  const std::string set_key = generated.sphere_set_key();

  v1::GetSphereSetRequest get;
  get.set_sphere_set_key(mesh);
  v1::GetSphereSetResponse set;
  grpc::Status s = stub_->GetSphereSet(Context().get(), get, &set);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(s.error_message(), HasSubstr("unknown sphere set " + mesh));

  v1::GetHierarchyRequest get_h;
  get_h.set_sphere_set_key(mesh);
  v1::GetHierarchyResponse h;
  EXPECT_EQ(stub_->GetHierarchy(Context().get(), get_h, &h).error_code(),
            grpc::StatusCode::NOT_FOUND);

  // The other way round: a sphere set key where a mesh key belongs.
  s = Generate(SphereRequest(set_key, 0.25), &generated);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(s.error_message(), HasSubstr("unknown mesh " + set_key));
  v1::EvaluateRequest evaluate;
  evaluate.set_mesh_sha256(set_key);
  evaluate.set_sphere_set_key(mesh);
  v1::EvaluateResponse quality;
  EXPECT_EQ(stub_->Evaluate(Context().get(), evaluate, &quality).error_code(),
            grpc::StatusCode::NOT_FOUND);

  // Still serving, and the right keys still work.
  get.set_sphere_set_key(set_key);
  EXPECT_TRUE(stub_->GetSphereSet(Context().get(), get, &set).ok());
  EXPECT_EQ(set.mesh_sha256(), mesh);
}

TEST_F(SpheresRpcTest, DeadlineStopsAHugeGeneration) {
  const std::string mesh = PutMesh(testing::Icosphere(4));
  v1::GenerateResult result;
  const auto start = std::chrono::steady_clock::now();
  // 8 million voxels (under the default --max-voxels): far more than half a second of work.
  const grpc::Status s = Generate(SphereRequest(mesh, 0.01), &result, nullptr, 0.5);
  EXPECT_EQ(s.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The worker stops too: shutting the server down waits for its pool, and takes a second or
  // so at most (1.6 s seen on a loaded machine), where finishing the generation would take far
  // longer. Times, like the deadline, are stretched under a sanitizer.
  const double scale = testing::kSanitizerTimeScale;
  const auto stop = std::chrono::steady_clock::now();
  server_.reset();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - stop).count(),
            5.0 * scale);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
            6.0 * scale);
}

TEST_F(SpheresRpcTest, SphereSetHierarchyAndDistanceMatchTheLibrary) {
  const std::string mesh = PutMesh(testing::Icosphere(3));
  v1::GenerateRequest request = SphereRequest(mesh, 0.15);
  request.mutable_parameters()->set_dilate(true);
  v1::GenerateResult generated;
  ASSERT_TRUE(Generate(request, &generated).ok());

  v1::GetSphereSetRequest get;
  get.set_sphere_set_key(generated.sphere_set_key());
  v1::GetSphereSetResponse set;
  ASSERT_TRUE(stub_->GetSphereSet(Context().get(), get, &set).ok());
  EXPECT_EQ(set.mesh_sha256(), mesh);
  absl::StatusOr<SphereSet> spheres = wire::SphereSetFromProto(set.spheres());
  ASSERT_TRUE(spheres.ok());

  v1::GetHierarchyRequest get_h;
  get_h.set_sphere_set_key(generated.sphere_set_key());
  get_h.set_volume(v1::RSS);
  v1::GetHierarchyResponse h;
  ASSERT_TRUE(stub_->GetHierarchy(Context().get(), get_h, &h).ok());
  absl::StatusOr<SphereHierarchy> hierarchy = SphereHierarchy::Deserialize(h.hierarchy());
  ASSERT_TRUE(hierarchy.ok()) << hierarchy.status();
  EXPECT_EQ(hierarchy->volume(), HierarchyVolume::kRss);
  EXPECT_EQ(hierarchy->spheres().size(), spheres->size());

  // 300 random pose pairs; the server's answers equal the brute force over the same spheres.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::vector<RigidPose> poses_a, poses_b;
  for (int i = 0; i < 300; ++i) {
    for (auto* poses : {&poses_a, &poses_b}) {
      RigidPose p;
      p.rotation = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng));
      p.rotation.normalize();
      p.translation = Vector3(normal(rng), normal(rng), normal(rng)) * 2.0;
      poses->push_back(p);
    }
  }
  v1::DistanceRequest distance;
  distance.set_sphere_set_a(generated.sphere_set_key());
  distance.set_sphere_set_b(generated.sphere_set_key());
  wire::PosesToProto(poses_a, distance.mutable_poses_a());
  wire::PosesToProto(poses_b, distance.mutable_poses_b());
  v1::DistanceResponse answer;
  const grpc::Status s = stub_->Distance(Context().get(), distance, &answer);
  ASSERT_TRUE(s.ok()) << s.error_message();
  ASSERT_EQ(answer.results().distances_size(), 300);
  for (int i = 0; i < 300; ++i) {
    absl::StatusOr<DistanceResult> brute =
        BruteForceSeparationDistance(spheres->spheres, poses_a[i], spheres->spheres, poses_b[i]);
    ASSERT_TRUE(brute.ok());
    EXPECT_NEAR(answer.results().distances(i), brute->distance, 1e-9) << i;
    EXPECT_NEAR(answer.results().points_a(3 * i), brute->point_a.x(), 1e-6) << i;
  }

  // Bad requests: unknown set, ragged poses, too many poses.
  v1::DistanceRequest unknown = distance;
  unknown.set_sphere_set_b("spheres/v1/" + std::string(64, 'b'));
  EXPECT_EQ(stub_->Distance(Context().get(), unknown, &answer).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::DistanceRequest ragged = distance;
  ragged.mutable_poses_b()->add_values(1.0);
  EXPECT_EQ(stub_->Distance(Context().get(), ragged, &answer).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::DistanceRequest huge = distance;
  huge.mutable_poses_b()->mutable_values()->Resize(7 * 6000, 0.0);
  const grpc::Status too_many = stub_->Distance(Context().get(), huge, &answer);
  EXPECT_EQ(too_many.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(too_many.error_message(), HasSubstr("--max-poses"));
}

// poses_a holds one pose or one per pose of poses_b; any other count is refused on the gRPC
// thread, before the sets are looked up (unknown keys here: a call that passes the rule is
// NOT_FOUND, one that breaks it INVALID_ARGUMENT, never queued).
TEST_F(SpheresRpcTest, DistanceTakesOnePoseAOrOnePerPoseB) {
  std::vector<CallRecord> calls;
  std::mutex calls_mutex;
  observer_ = [&](const CallRecord& call) {
    std::lock_guard<std::mutex> lock(calls_mutex);
    calls.push_back(call);
  };
  Restart();
  auto request = [](int count_a, int count_b) {
    v1::DistanceRequest distance;
    distance.set_sphere_set_a("spheres/v1/" + std::string(64, 'a'));
    distance.set_sphere_set_b("spheres/v1/" + std::string(64, 'b'));
    wire::PosesToProto(std::vector<RigidPose>(count_a), distance.mutable_poses_a());
    wire::PosesToProto(std::vector<RigidPose>(count_b), distance.mutable_poses_b());
    return distance;
  };
  v1::DistanceResponse answer;
  const grpc::Status two_for_three = stub_->Distance(Context().get(), request(2, 3), &answer);
  EXPECT_EQ(two_for_three.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(two_for_three.error_message(),
              HasSubstr("poses_a has 2 poses and poses_b 3; poses_a must have one pose or as "
                        "many as poses_b"));
  EXPECT_EQ(stub_->Distance(Context().get(), request(1, 3), &answer).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(stub_->Distance(Context().get(), request(3, 3), &answer).error_code(),
            grpc::StatusCode::NOT_FOUND);
  std::lock_guard<std::mutex> lock(calls_mutex);
  ASSERT_EQ(calls.size(), 3u);
  EXPECT_EQ(calls[0].run_seconds, 0.0);  // refused before it was queued
  EXPECT_EQ(calls[0].memory_bytes, 0);
  EXPECT_GT(calls[1].memory_bytes, 0);
}

TEST_F(SpheresRpcTest, CorruptDiskEntryIsRecomputed) {
  const std::string mesh = PutMesh(testing::Icosphere(2));
  v1::GenerateResult first;
  ASSERT_TRUE(Generate(SphereRequest(mesh, 0.25), &first).ok());
  // Damage every cache file's last byte (payloads end the files), then restart: the mesh and
  // the sphere set must both be recomputed or refused, never served damaged.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(cache_dir_)) {
    if (!entry.is_regular_file()) continue;
    std::fstream f(entry.path(), std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(-1, std::ios::end);
    char c;
    f.get(c);
    f.seekp(-1, std::ios::end);
    f.put(static_cast<char>(c ^ 0x5a));
  }
  Restart();
  v1::GenerateResult again;
  const grpc::Status s = Generate(SphereRequest(mesh, 0.25), &again);
  // The stored mesh was damaged too: it is dropped, so the server asks for it again.
  EXPECT_EQ(s.error_code(), grpc::StatusCode::NOT_FOUND) << s.error_message();
  EXPECT_GE(Stats().disk_errors(), 1);
  PutMesh(testing::Icosphere(2));
  ASSERT_TRUE(Generate(SphereRequest(mesh, 0.25), &again).ok());
  EXPECT_EQ(again.cache(), "computed");
  EXPECT_EQ(again.spheres().SerializeAsString(), first.spheres().SerializeAsString());
}

}  // namespace
}  // namespace inscribe::server
