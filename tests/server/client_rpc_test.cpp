// The Client over MakeGrpcConnection against the real server in-process on loopback (disk
// cache in a temporary directory); every answer checked against the core library called
// directly on the same mesh and spheres.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/balls/sphere_quality.h"
#include "inscribe/client/client.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/medial/medial_spheres.h"
#include "inscribe/server/inscribe_server.h"
#include "inscribe/solid/boundary_oracle.h"
#include "inscribe/solid/mesh_validation.h"
#include "support/sphere_sets.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe::client {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

class ClientRpcTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cache_dir_ = std::filesystem::temp_directory_path() /
                 ("inscribe-client-rpc-" + std::to_string(std::random_device{}()));
    server::ServerOptions options;
    options.listen = "127.0.0.1:0";
    options.jobs = 2;
    options.max_queue = 64;
    options.cache.disk_dir = cache_dir_.string();
    absl::StatusOr<std::unique_ptr<server::InscribeServer>> started =
        server::InscribeServer::Start(options);
    ASSERT_TRUE(started.ok()) << started.status();
    server_ = *std::move(started);
    client_ = std::make_unique<Client>(MakeGrpcConnection(server_->address()));
  }
  void TearDown() override {
    client_.reset();
    server_.reset();
    std::filesystem::remove_all(cache_dir_);
  }

  // PutMesh, then Generate at `voxel_size`; fails the test on any error.
  GenerateResult Generated(const Mesh& mesh, double voxel_size, bool dilate = false) {
    GenerateSettings settings;
    settings.parameters.voxel_size = voxel_size;
    if (dilate) settings.parameters.kind = SphereSetKind::kDilated;
    absl::StatusOr<GenerateResult> result = client_->Generate(mesh, settings);
    EXPECT_TRUE(result.ok()) << result.status();
    return result.ok() ? *std::move(result) : GenerateResult();
  }

  std::filesystem::path cache_dir_;
  std::unique_ptr<server::InscribeServer> server_;
  std::unique_ptr<Client> client_;
};

// The core library's oracle for `mesh` as the server stores it (validated, orientation fixed).
BoundaryOracle OracleOf(const Mesh& mesh) {
  absl::StatusOr<BoundaryOracle> oracle = BoundaryOracle::Build(ValidateMesh(mesh).mesh);
  EXPECT_TRUE(oracle.ok()) << oracle.status();
  return *std::move(oracle);
}

SphereSet LibrarySpheres(const Mesh& mesh, double voxel_size) {
  MedialSphereOptions options;
  options.voxel_size = voxel_size;
  absl::StatusOr<MedialSphereResult> result = GenerateMedialSpheres(OracleOf(mesh), options);
  EXPECT_TRUE(result.ok()) << result.status();
  return result.ok() ? std::move(result->set) : SphereSet();
}

void ExpectSameSpheres(const SphereSet& actual, const SphereSet& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  ASSERT_EQ(actual.contacts.size(), expected.contacts.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    EXPECT_EQ(actual.spheres[i].center, expected.spheres[i].center) << i;
    EXPECT_EQ(actual.spheres[i].radius, expected.spheres[i].radius) << i;
  }
  for (std::size_t i = 0; i < actual.contacts.size(); ++i) {
    EXPECT_EQ(actual.contacts[i].triangle, expected.contacts[i].triangle) << i;
    EXPECT_EQ(actual.contacts[i].barycentric, expected.contacts[i].barycentric) << i;
  }
}

// Server distance (world-frame witnesses) against the all-pairs reference.
void ExpectBruteForce(const DistanceResult& actual, const std::vector<Sphere>& a,
                      const RigidPose& pose_a, const std::vector<Sphere>& b,
                      const RigidPose& pose_b) {
  absl::StatusOr<DistanceResult> brute = BruteForceSeparationDistance(a, pose_a, b, pose_b);
  ASSERT_TRUE(brute.ok()) << brute.status();
  EXPECT_NEAR(actual.distance, brute->distance, 1e-9);
  // The witnesses lie |distance| apart, on the spheres the answer names.
  EXPECT_NEAR((actual.point_a - actual.point_b).norm(), std::abs(actual.distance), 1e-9);
  ASSERT_GE(actual.sphere_a, 0);
  ASSERT_GE(actual.sphere_b, 0);
  const Sphere& sa = a[static_cast<std::size_t>(actual.sphere_a)];
  EXPECT_NEAR((actual.point_a - pose_a * sa.center).norm(), sa.radius, 1e-9);
}

std::vector<RigidPose> RandomPoses(int n, std::uint64_t seed, double spread) {
  std::mt19937_64 rng(seed);
  std::vector<RigidPose> poses;
  for (int i = 0; i < n; ++i) poses.push_back(testing::RandomPose(rng, spread));
  return poses;
}

TEST_F(ClientRpcTest, GenerateMatchesTheLibraryThenComesFromMemory) {
  const Mesh mesh = testing::Icosphere(3);
  absl::StatusOr<PutMeshResult> stored = client_->PutMesh(mesh);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->mesh_sha256, FormatSha256(MeshSha256(ValidateMesh(mesh).mesh)));
  EXPECT_FALSE(stored->already_stored);
  EXPECT_TRUE(stored->report.usable());
  EXPECT_EQ(stored->report.triangles, 1280);

  GenerateSettings settings;
  settings.parameters.voxel_size = 0.1;
  absl::StatusOr<GenerateResult> first = client_->Generate(stored->mesh_sha256, settings);
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_EQ(first->cache, "computed");
  EXPECT_THAT(first->sphere_set_key, StartsWith("spheres/v1/"));
  EXPECT_EQ(first->mesh_sha256, stored->mesh_sha256);
  EXPECT_EQ(first->voxel_size, 0.1);
  ExpectSameSpheres(first->set, LibrarySpheres(mesh, 0.1));
  ASSERT_TRUE(first->quality.has_value());
  EXPECT_EQ(first->quality->spheres, static_cast<std::int64_t>(first->set.size()));

  // The mesh overload: uploads (already stored), then the cached set.
  absl::StatusOr<GenerateResult> second = client_->Generate(mesh, settings);
  ASSERT_TRUE(second.ok()) << second.status();
  EXPECT_EQ(second->cache, "memory");
  EXPECT_EQ(second->sphere_set_key, first->sphere_set_key);
  ExpectSameSpheres(second->set, first->set);
}

TEST_F(ClientRpcTest, GenerateOnARealMeshMatchesTheLibrary) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  const double voxel_size = 0.05 * ComputeBoundingBox(mesh.vertices).diagonal();
  GenerateSettings settings;
  settings.parameters.voxel_size = voxel_size;
  settings.parameters.evaluate = false;
  int progress_calls = 0;
  GenerateOptions options;
  options.on_progress = [&](double) { ++progress_calls; };
  absl::StatusOr<GenerateResult> result = client_->Generate(mesh, settings, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_FALSE(result->quality.has_value());
  EXPECT_GT(result->set.size(), 10u);
  ExpectSameSpheres(result->set, LibrarySpheres(mesh, voxel_size));
}

TEST_F(ClientRpcTest, GetSphereSetAndGetHierarchyReturnTheGeneratedSet) {
  const GenerateResult generated = Generated(testing::Icosphere(2), 0.2);
  absl::StatusOr<StoredSphereSet> stored = client_->GetSphereSet(generated.sphere_set_key);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->mesh_sha256, generated.mesh_sha256);
  ExpectSameSpheres(stored->spheres, generated.set);

  for (const HierarchyVolume volume : {HierarchyVolume::kRss, HierarchyVolume::kSphere}) {
    absl::StatusOr<SphereHierarchy> hierarchy =
        client_->GetHierarchy(generated.sphere_set_key, volume);
    ASSERT_TRUE(hierarchy.ok()) << hierarchy.status();
    EXPECT_EQ(hierarchy->volume(), volume);
    ASSERT_EQ(hierarchy->spheres().size(), generated.set.size());
    for (std::size_t i = 0; i < generated.set.size(); ++i) {
      EXPECT_EQ(hierarchy->spheres()[i].center, generated.set.spheres[i].center);
    }
  }
  EXPECT_EQ(client_->GetSphereSet("spheres/v1/" + std::string(64, 'c')).status().code(),
            absl::StatusCode::kNotFound);
}

TEST_F(ClientRpcTest, DistanceMatchesBruteForce) {
  const GenerateResult sphere = Generated(testing::Icosphere(2), 0.15, /*dilate=*/true);
  const GenerateResult box =
      Generated(testing::Box(Vector3(0, 0, 0), Vector3(2.0, 0.5, 0.5)), 0.1, /*dilate=*/true);
  const std::vector<RigidPose> poses_a = RandomPoses(150, 1, 2.0);
  const std::vector<RigidPose> poses_b = RandomPoses(150, 2, 2.0);
  for (const HierarchyVolume volume : {HierarchyVolume::kRss, HierarchyVolume::kSphere}) {
    DistanceOptions options;
    options.volume = volume;
    absl::StatusOr<DistanceBatchResult> batch =
        client_->Distance(sphere.sphere_set_key, box.sphere_set_key, poses_a, poses_b, options);
    ASSERT_TRUE(batch.ok()) << batch.status();
    ASSERT_EQ(batch->results.size(), poses_b.size());
    for (std::size_t i = 0; i < poses_b.size(); ++i) {
      SCOPED_TRACE(i);
      ExpectBruteForce(batch->results[i], sphere.set.spheres, poses_a[i], box.set.spheres,
                       poses_b[i]);
    }
  }
  // One pose of A for every query.
  absl::StatusOr<DistanceBatchResult> shared =
      client_->Distance(box.sphere_set_key, sphere.sphere_set_key, {poses_a[0]}, poses_b);
  ASSERT_TRUE(shared.ok()) << shared.status();
  for (std::size_t i = 0; i < poses_b.size(); ++i) {
    ExpectBruteForce(shared->results[i], box.set.spheres, poses_a[0], sphere.set.spheres,
                     poses_b[i]);
  }
}

TEST_F(ClientRpcTest, DistanceSessionMatchesBruteForceOver200Frames) {
  const GenerateResult sphere = Generated(testing::Icosphere(2), 0.2, /*dilate=*/true);
  const GenerateResult box =
      Generated(testing::Box(Vector3(0, 0, 0), Vector3(1.0, 0.5, 0.5)), 0.1, /*dilate=*/true);
  absl::StatusOr<DistanceSession> session = client_->OpenDistanceSession();
  ASSERT_TRUE(session.ok()) << session.status();
  const std::vector<Sphere>& s = sphere.set.spheres;
  const std::vector<Sphere>& b = box.set.spheres;
  std::mt19937_64 rng(3);
  for (int frame = 0; frame < 200; ++frame) {
    SCOPED_TRACE(frame);
    std::vector<PosePair> pairs = {{sphere.sphere_set_key, box.sphere_set_key, {}, {}},
                                   {box.sphere_set_key, sphere.sphere_set_key, {}, {}},
                                   {box.sphere_set_key, box.sphere_set_key, {}, {}}};
    for (PosePair& pair : pairs) {
      pair.pose_a = testing::RandomPose(rng, 1.5);
      pair.pose_b = testing::RandomPose(rng, 1.5);
    }
    absl::StatusOr<std::vector<DistanceResult>> results = session->Query(pairs);
    ASSERT_TRUE(results.ok()) << results.status();
    ASSERT_EQ(results->size(), 3u);
    ExpectBruteForce((*results)[0], s, pairs[0].pose_a, b, pairs[0].pose_b);
    ExpectBruteForce((*results)[1], b, pairs[1].pose_a, s, pairs[1].pose_b);
    ExpectBruteForce((*results)[2], b, pairs[2].pose_a, b, pairs[2].pose_b);
  }
  EXPECT_TRUE(session->Close().ok());
}

TEST_F(ClientRpcTest, AFrameNamingAnUnknownSetIsNotFoundAndEndsTheSession) {
  const GenerateResult sphere = Generated(testing::Icosphere(1), 0.3);
  absl::StatusOr<DistanceSession> session = client_->OpenDistanceSession();
  ASSERT_TRUE(session.ok());
  const PosePair known{sphere.sphere_set_key, sphere.sphere_set_key, RigidPose(),
                       RigidPose{Eigen::Quaterniond::Identity(), Vector3(5, 0, 0)}};
  ASSERT_TRUE(session->Query({known}).ok());
  PosePair unknown = known;
  unknown.sphere_set_b = "spheres/v1/" + std::string(64, 'd');
  const absl::Status status = session->Query({known, unknown}).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kNotFound) << status;
  // Broken: the known pair is not even sent.
  EXPECT_EQ(session->Query({known}).status(), status);
  EXPECT_EQ(session->Close(), status);
}

TEST_F(ClientRpcTest, CacheStatsCountComputationsAndHits) {
  absl::StatusOr<ServerCacheStats> before = client_->CacheStats();
  ASSERT_TRUE(before.ok()) << before.status();
  EXPECT_EQ(before->computations, 0);
  EXPECT_EQ(before->hits, 0);
  const GenerateResult first = Generated(testing::Icosphere(1), 0.3);  // mesh + spheres
  absl::StatusOr<ServerCacheStats> computed = client_->CacheStats();
  ASSERT_TRUE(computed.ok());
  EXPECT_EQ(computed->computations, 2);
  EXPECT_GE(computed->entries, 2);
  EXPECT_GT(computed->bytes, 0);

  const GenerateResult second = Generated(testing::Icosphere(1), 0.3);  // both from memory
  EXPECT_EQ(second.cache, "memory");
  absl::StatusOr<ServerCacheStats> hit = client_->CacheStats();
  ASSERT_TRUE(hit.ok());
  EXPECT_EQ(hit->computations, 2);
  EXPECT_EQ(hit->memory_hits - computed->memory_hits, 2);
  EXPECT_EQ(hit->hits, hit->memory_hits + hit->disk_hits);
}

TEST_F(ClientRpcTest, PutSphereSetThenDistanceOnTheUploadedSets) {
  SphereSet a{testing::RandomSpheres(60, 11), {}};
  SphereSet b{testing::RandomBalls(40, 1.0, 0.05, 0.2, 12), {}};
  absl::StatusOr<PutSphereSetResult> key_a = client_->PutSphereSet(a);
  absl::StatusOr<PutSphereSetResult> key_b = client_->PutSphereSet(b);
  ASSERT_TRUE(key_a.ok()) << key_a.status();
  ASSERT_TRUE(key_b.ok()) << key_b.status();
  EXPECT_FALSE(key_a->already_stored);
  EXPECT_THAT(key_a->sphere_set_key, StartsWith("spheres/v1/"));
  EXPECT_NE(key_a->sphere_set_key, key_b->sphere_set_key);
  absl::StatusOr<PutSphereSetResult> again = client_->PutSphereSet(a);
  ASSERT_TRUE(again.ok());
  EXPECT_TRUE(again->already_stored);
  EXPECT_EQ(again->sphere_set_key, key_a->sphere_set_key);

  absl::StatusOr<StoredSphereSet> stored = client_->GetSphereSet(key_a->sphere_set_key);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->mesh_sha256, "");
  ExpectSameSpheres(stored->spheres, a);

  const std::vector<RigidPose> poses_a = RandomPoses(100, 4, 1.0);
  const std::vector<RigidPose> poses_b = RandomPoses(100, 5, 1.0);
  absl::StatusOr<DistanceBatchResult> batch =
      client_->Distance(key_a->sphere_set_key, key_b->sphere_set_key, poses_a, poses_b);
  ASSERT_TRUE(batch.ok()) << batch.status();
  for (std::size_t i = 0; i < poses_b.size(); ++i) {
    ExpectBruteForce(batch->results[i], a.spheres, poses_a[i], b.spheres, poses_b[i]);
  }

  // A bad set is refused by the server, naming the sphere.
  SphereSet bad{{Sphere{Vector3::Zero(), -1.0}}, {}};
  const absl::Status refused = client_->PutSphereSet(bad).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument) << refused;
  EXPECT_THAT(refused.message(), HasSubstr("sphere 0"));
}

TEST_F(ClientRpcTest, EvaluateByKeyAndInlineMatchesTheLibrary) {
  const Mesh mesh = testing::Icosphere(2);
  const GenerateResult generated = Generated(mesh, 0.2);
  EvaluateSettings settings;
  settings.surface_samples = 2000;
  settings.voxel_size = 0.2;
  settings.coverage_tolerance = 0.01;
  QualityOptions options;
  options.surface_samples = 2000;
  options.voxel_size = 0.2;
  options.coverage_tolerance = 0.01;
  absl::StatusOr<QualityReport> expected =
      EvaluateSpheres(OracleOf(mesh), generated.set.spheres, options);
  ASSERT_TRUE(expected.ok()) << expected.status();

  // The set's own mesh by key (mesh_sha256 empty), and the set sent inline with its mesh.
  absl::StatusOr<QualityReport> by_key = client_->Evaluate("", generated.sphere_set_key, settings);
  absl::StatusOr<QualityReport> inline_set =
      client_->Evaluate(generated.mesh_sha256, generated.set, settings);
  for (const absl::StatusOr<QualityReport>* report : {&by_key, &inline_set}) {
    ASSERT_TRUE(report->ok()) << report->status();
    const QualityReport& r = **report;
    EXPECT_EQ(r.spheres, expected->spheres);
    EXPECT_NEAR(r.volume_mesh, expected->volume_mesh, 1e-12);
    EXPECT_NEAR(r.volume_union, expected->volume_union, 1e-9);
    EXPECT_NEAR(r.nerr, expected->nerr, 1e-9);
    EXPECT_EQ(r.nerr_is_exact, expected->nerr_is_exact);
    EXPECT_NEAR(r.protrusion_max, expected->protrusion_max, 1e-12);
    EXPECT_EQ(r.surface_samples, 2000);
    EXPECT_EQ(r.coverage, expected->coverage);
    EXPECT_EQ(r.coverage_tolerance, 0.01);
    EXPECT_NEAR(r.boundary_to_union_hausdorff, expected->boundary_to_union_hausdorff, 1e-12);
    EXPECT_EQ(r.radius_min, expected->radius_min);
    EXPECT_EQ(r.fat, expected->fat);
  }
  EXPECT_EQ(client_->Evaluate("", "spheres/v1/" + std::string(64, 'e')).status().code(),
            absl::StatusCode::kNotFound);
}

TEST_F(ClientRpcTest, UpdateDeformationByARigidTranslationMovesEverySphere) {
  const Mesh mesh = testing::Icosphere(2);
  const GenerateResult generated = Generated(mesh, 0.2);
  ASSERT_TRUE(generated.set.has_contacts());
  const Vector3 shift(0.25, -0.5, 1.0);
  Vertices moved = ValidateMesh(mesh).mesh.vertices;  // the stored mesh's vertex order
  moved.rowwise() += shift.transpose();

  DeformationSettings settings;
  settings.store = true;
  absl::StatusOr<DeformationResult> result =
      client_->UpdateDeformation("", generated.sphere_set_key, moved, settings);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->dropped, 0);
  EXPECT_EQ(result->reference_spheres, static_cast<std::int64_t>(generated.set.size()));
  ASSERT_EQ(result->set.size(), generated.set.size());
  for (std::size_t i = 0; i < result->set.size(); ++i) {
    const std::size_t from = static_cast<std::size_t>(result->reference_index[i]);
    const Sphere& before = generated.set.spheres[from];
    const Sphere& after = result->set.spheres[i];
    EXPECT_LT((after.center - (before.center + shift)).norm(), 1e-9) << i;
    EXPECT_NEAR(after.radius, before.radius, 1e-9) << i;
  }
  // Stored: the moved set is served under its key.
  ASSERT_THAT(result->sphere_set_key, StartsWith("spheres/v1/"));
  absl::StatusOr<StoredSphereSet> stored = client_->GetSphereSet(result->sphere_set_key);
  ASSERT_TRUE(stored.ok()) << stored.status();
  ExpectSameSpheres(stored->spheres, result->set);
}

// One Client shared by threads making batch calls and running their own sessions at once.
TEST_F(ClientRpcTest, ConcurrentCallsAndSessionsShareOneClient) {
  const GenerateResult sphere = Generated(testing::Icosphere(1), 0.3, /*dilate=*/true);
  const std::vector<Sphere>& s = sphere.set.spheres;
  constexpr int kThreads = 4;
  std::atomic<int> wrong{0}, failed{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      const std::vector<RigidPose> poses = RandomPoses(20, 100 + t, 1.0);
      absl::StatusOr<DistanceSession> session = client_->OpenDistanceSession();
      if (!session.ok()) {
        ++failed;
        return;
      }
      for (int i = 0; i < 20; ++i) {
        absl::StatusOr<DistanceBatchResult> batch =
            client_->Distance(sphere.sphere_set_key, sphere.sphere_set_key, {RigidPose()}, poses);
        absl::StatusOr<std::vector<DistanceResult>> frame =
            session->Query({{sphere.sphere_set_key, sphere.sphere_set_key, RigidPose(), poses[i]}});
        if (!batch.ok() || !frame.ok()) {
          ++failed;
          continue;
        }
        const double brute = BruteForceSeparationDistance(s, RigidPose(), s, poses[i])->distance;
        if (std::abs(batch->results[i].distance - brute) > 1e-9 ||
            std::abs((*frame)[0].distance - brute) > 1e-9) {
          ++wrong;
        }
      }
      if (!session->Close().ok()) ++failed;
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_EQ(wrong.load(), 0);
}

}  // namespace
}  // namespace inscribe::client
