// Scale-out as an operator runs it: one redis-server and three inscribed replicas on loopback
// sharing it (--redis). A result computed through one replica is served by the others from
// Redis without recomputation; when Redis dies, every replica keeps answering every call from
// its own tiers or by computing, and says so in its counters and its log.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <array>
#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/client/client.h"
#include "inscribe/geometry/mesh.h"
#include "support/inscribed_process.h"
#include "support/redis_process.h"
#include "support/synthetic_meshes.h"
#include "support/test_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

class ScaleOut : public ::testing::Test {
 protected:
  void SetUp() override {
    redis_ = std::make_unique<testing::RedisProcess>();
    ASSERT_TRUE(redis_->ready()) << "redis-server did not start";
    for (int i = 0; i < 3; ++i) {
      replicas_[i] = std::make_unique<testing::InscribedProcess>(
          INSCRIBED, std::vector<std::string>{"--listen", "127.0.0.1:0", "--redis", redis_->url(),
                                              "--redis-timeout-ms", "200", "--jobs", "1"});
      ASSERT_TRUE(replicas_[i]->started());
      const std::string address = replicas_[i]->WaitUntilListening();
      ASSERT_FALSE(address.empty()) << replicas_[i]->log();
      replicas_[i]->DrainLogInBackground();
      clients_.emplace_back(client::MakeGrpcConnection(address));
    }
  }

  client::ServerCacheStats Stats(int replica) {
    absl::StatusOr<client::ServerCacheStats> stats = clients_[replica].CacheStats();
    EXPECT_TRUE(stats.ok()) << stats.status();
    return stats.ok() ? *stats : client::ServerCacheStats{};
  }

  // Polls (up to 10 s) until the replica's log holds `text`: the log arrives on a pipe.
  bool LogShows(int replica, const std::string& text) {
    const auto give_up = Clock::now() + 10s;
    while (replicas_[replica]->log().find(text) == std::string::npos) {
      if (Clock::now() > give_up) return false;
      std::this_thread::sleep_for(50ms);
    }
    return true;
  }

  std::unique_ptr<testing::RedisProcess> redis_;
  std::array<std::unique_ptr<testing::InscribedProcess>, 3> replicas_;
  std::vector<client::Client> clients_;
};

client::GenerateSettings Settings(const Mesh& mesh, double fraction) {
  client::GenerateSettings settings;
  settings.parameters.voxel_size = fraction * ComputeBoundingBox(mesh.vertices).diagonal();
  settings.parameters.evaluate = false;
  return settings;
}

TEST_F(ScaleOut, ReplicasServeEachOthersResultsFromRedis) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh mesh = testing::LoadTestMesh("eight.off");
  // Replica 1 stores the mesh and computes two sphere sets.
  absl::StatusOr<client::PutMeshResult> put = clients_[0].PutMesh(mesh);
  ASSERT_TRUE(put.ok()) << put.status();
  absl::StatusOr<client::GenerateResult> coarse =
      clients_[0].Generate(put->mesh_sha256, Settings(mesh, 0.08));
  ASSERT_TRUE(coarse.ok()) << coarse.status();
  EXPECT_EQ(coarse->cache, "computed");
  absl::StatusOr<client::GenerateResult> fine =
      clients_[0].Generate(put->mesh_sha256, Settings(mesh, 0.05));
  ASSERT_TRUE(fine.ok()) << fine.status();
  const client::ServerCacheStats first = Stats(0);
  EXPECT_EQ(first.computations, 3);  // the mesh and two sets
  EXPECT_EQ(first.shared_writes, 3);
  EXPECT_EQ(first.shared_available, 1);

  // Replica 3 has neither: both come from Redis, nothing is computed.
  absl::StatusOr<client::StoredSphereSet> stored = clients_[2].GetSphereSet(coarse->sphere_set_key);
  ASSERT_TRUE(stored.ok()) << stored.status();
  EXPECT_EQ(stored->spheres.size(), coarse->set.size());
  EXPECT_EQ(stored->mesh_sha256, put->mesh_sha256);
  absl::StatusOr<client::GenerateResult> again =
      clients_[2].Generate(put->mesh_sha256, Settings(mesh, 0.05));
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->cache, "redis");
  EXPECT_EQ(again->sphere_set_key, fine->sphere_set_key);
  ASSERT_EQ(again->set.size(), fine->set.size());
  for (std::size_t i = 0; i < fine->set.size(); ++i) {
    EXPECT_EQ(again->set.spheres[i].center, fine->set.spheres[i].center);
    EXPECT_EQ(again->set.spheres[i].radius, fine->set.spheres[i].radius);
  }
  EXPECT_EQ(again->seconds, fine->seconds);  // the original run's time: not run again
  const client::ServerCacheStats third = Stats(2);
  EXPECT_EQ(third.computations, 0);
  EXPECT_EQ(third.shared_hits, 2);
  EXPECT_EQ(third.misses, 0);

  // Replica 2 builds a hierarchy and answers distances off the Redis copy of the set.
  absl::StatusOr<SphereHierarchy> hierarchy =
      clients_[1].GetHierarchy(coarse->sphere_set_key, HierarchyVolume::kSphere);
  ASSERT_TRUE(hierarchy.ok()) << hierarchy.status();
  RigidPose apart;
  apart.translation = Vector3(10.0 * ComputeBoundingBox(mesh.vertices).diagonal(), 0.0, 0.0);
  absl::StatusOr<client::DistanceBatchResult> distance =
      clients_[1].Distance(coarse->sphere_set_key, fine->sphere_set_key, {RigidPose{}}, {apart});
  ASSERT_TRUE(distance.ok()) << distance.status();
  ASSERT_EQ(distance->results.size(), 1u);
  EXPECT_GT(distance->results[0].distance, 0.0);
  const client::ServerCacheStats second = Stats(1);
  EXPECT_GE(second.shared_hits, 2);   // both sets
  EXPECT_EQ(second.computations, 2);  // the two hierarchies only
  EXPECT_EQ(second.shared_errors, 0);
}

TEST_F(ScaleOut, EveryCallSucceedsAfterRedisDies) {
  INSCRIBE_REQUIRE_MESH("eight.off");
  const Mesh eight = testing::LoadTestMesh("eight.off");
  absl::StatusOr<client::GenerateResult> before =
      clients_[0].Generate(eight, Settings(eight, 0.08));
  ASSERT_TRUE(before.ok()) << before.status();
  absl::StatusOr<client::GenerateResult> shared =
      clients_[2].Generate(before->mesh_sha256, Settings(eight, 0.08));
  ASSERT_TRUE(shared.ok()) << shared.status();
  EXPECT_EQ(shared->cache, "redis");

  redis_->Kill();
  // New meshes must be computed; known results come from each replica's memory.
  const std::vector<Mesh> meshes = {testing::UnitCube(), testing::Icosphere(2),
                                    testing::Box(Vector3(0, 0, 0), Vector3(2, 1, 1))};
  for (int round = 0; round < 2; ++round) {
    for (int r = 0; r < 3; ++r) {
      SCOPED_TRACE(::testing::Message() << "round " << round << " replica " << r + 1);
      const Mesh& mesh = meshes[(r + round) % meshes.size()];
      absl::StatusOr<client::GenerateResult> generated =
          clients_[r].Generate(mesh, Settings(mesh, 0.05));
      ASSERT_TRUE(generated.ok()) << generated.status();
      absl::StatusOr<client::StoredSphereSet> got =
          clients_[r].GetSphereSet(generated->sphere_set_key);
      ASSERT_TRUE(got.ok()) << got.status();
      absl::StatusOr<SphereHierarchy> hierarchy =
          clients_[r].GetHierarchy(generated->sphere_set_key, HierarchyVolume::kSphere);
      ASSERT_TRUE(hierarchy.ok()) << hierarchy.status();
      // The eight: from memory on replicas 1 and 3, recomputed on replica 2.
      absl::StatusOr<client::GenerateResult> known =
          clients_[r].Generate(eight, Settings(eight, 0.08));
      ASSERT_TRUE(known.ok()) << known.status();
      EXPECT_EQ(known->sphere_set_key, before->sphere_set_key);
    }
  }
  for (int r = 0; r < 3; ++r) {
    SCOPED_TRACE(::testing::Message() << "replica " << r + 1);
    const client::ServerCacheStats s = Stats(r);
    EXPECT_EQ(s.shared_available, 0);
    EXPECT_GE(s.shared_errors + s.shared_write_errors, 1);
    EXPECT_GE(s.shared_errors + s.shared_write_errors + s.shared_skipped, 3);
    EXPECT_TRUE(LogShows(r, "event=redis_down")) << replicas_[r]->log();
    EXPECT_THAT(replicas_[r]->log(), HasSubstr("event=serving"));
  }
  EXPECT_THAT(replicas_[0]->log(), HasSubstr("redis=\"redis://127.0.0.1:"));
}

}  // namespace
}  // namespace inscribe::server
