// Three inscribed processes on loopback behind one routed Client (no shared Redis tier): each
// mesh's work lands on the replica rendezvous hashing gives it, the keys of a mesh route
// together, and a replica killed (SIGKILL) in the middle of a stream of idempotent calls from
// two threads costs the callers nothing: its keys are served by their second choice.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/client/client.h"
#include "inscribe/client/routing.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/wire/keys.h"
#include "support/inscribed_process.h"
#include "support/test_meshes.h"

namespace inscribe::client {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

constexpr int kReplicas = 3;

// Small meshes and a coarse grid (5% of the bounding-box diagonal): Generate takes well under
// a second. Each mesh also shifted by 10 units, which changes its hash and so its replica.
std::vector<Mesh> SmallMeshes() {
  std::vector<Mesh> meshes;
  for (const char* name : {"eight.off", "cube.off", "knot1.off"}) {
    Mesh mesh = testing::LoadTestMesh(name);
    Mesh shifted = mesh;
    shifted.vertices.col(0).array() += 10.0;
    meshes.push_back(std::move(mesh));
    meshes.push_back(std::move(shifted));
  }
  return meshes;
}

GenerateSettings CoarseFor(const Mesh& mesh) {
  GenerateSettings settings;
  settings.parameters.voxel_size = 0.05 * ComputeBoundingBox(mesh.vertices).diagonal();
  settings.parameters.evaluate = false;
  return settings;
}

class FailoverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    INSCRIBE_REQUIRE_MESH("knot1.off");
    std::vector<Endpoint> endpoints;
    for (int i = 0; i < kReplicas; ++i) {
      replicas_.push_back(std::make_unique<testing::InscribedProcess>(
          INSCRIBED, std::vector<std::string>{"--listen", "127.0.0.1:0", "--jobs", "1"}));
      ASSERT_TRUE(replicas_.back()->started());
      const std::string address = replicas_.back()->WaitUntilListening();
      ASSERT_FALSE(address.empty()) << replicas_.back()->log();
      replicas_.back()->DrainLogInBackground();
      names_.push_back(address);
      direct_.emplace_back(MakeGrpcConnection(address));
      endpoints.push_back({address, MakeGrpcConnection(address)});
    }
    absl::StatusOr<std::shared_ptr<Connection>> routed = MakeRoutedConnection(std::move(endpoints));
    ASSERT_TRUE(routed.ok()) << routed.status();
    // One attempt per replica and no time for a backoff: failing over (each attempt at once,
    // to the next replica) must hide the dead replica.
    ClientOptions options;
    options.retry.max_attempts = 3;
    options.retry.initial_backoff = std::chrono::milliseconds(600'000);
    options.retry.max_backoff = std::chrono::milliseconds(600'000);
    routed_ = std::make_unique<Client>(*std::move(routed), options);
    meshes_ = SmallMeshes();
  }

  // Rendezvous order of a key's replicas.
  std::vector<int> Order(const std::string& key) const {
    return RendezvousOrder(wire::RouteKey(key), names_);
  }

  std::vector<ServerCacheStats> Stats(const std::vector<int>& which) const {
    std::vector<ServerCacheStats> stats;
    for (int i : which) {
      absl::StatusOr<ServerCacheStats> s = direct_[i].CacheStats();
      EXPECT_TRUE(s.ok()) << names_[i] << ": " << s.status();
      stats.push_back(s.value_or(ServerCacheStats{}));
    }
    return stats;
  }

  std::vector<std::unique_ptr<testing::InscribedProcess>> replicas_;
  std::vector<std::string> names_;  // "127.0.0.1:PORT", what the routing hashes
  std::vector<Client> direct_;      // one plain client per replica
  std::unique_ptr<Client> routed_;
  std::vector<Mesh> meshes_;
};

TEST_F(FailoverTest, EachMeshComputesOnItsOwnReplicaAndItsKeysRouteTogether) {
  const std::vector<int> all = {0, 1, 2};
  for (const Mesh& mesh : meshes_) {
    const std::vector<ServerCacheStats> before = Stats(all);
    absl::StatusOr<GenerateResult> made = routed_->Generate(mesh, CoarseFor(mesh));
    ASSERT_TRUE(made.ok()) << made.status();
    const std::vector<ServerCacheStats> after = Stats(all);
    const int owner = Order(made->mesh_sha256)[0];
    for (int i : all) {
      const std::int64_t computed = after[i].computations - before[i].computations;
      if (i == owner) {
        EXPECT_EQ(computed, 2) << "the mesh and its set, on " << names_[i];
      } else {
        EXPECT_EQ(computed, 0) << names_[i] << " is not " << made->mesh_sha256 << "'s replica";
        EXPECT_EQ(after[i].entries, before[i].entries) << names_[i];
      }
    }
    // The set's key carries the mesh's route digits.
    EXPECT_EQ(made->sphere_set_key.substr(0, 11 + 16),
              "spheres/v1/" + made->mesh_sha256.substr(7, 16));
    EXPECT_EQ(made->sphere_set_key.size(), 11u + 64u);
    EXPECT_EQ(wire::RouteKey(made->sphere_set_key), wire::RouteKey(made->mesh_sha256));

    // Asked again: answered from the owner's memory, computed nowhere.
    absl::StatusOr<GenerateResult> again = routed_->Generate(mesh, CoarseFor(mesh));
    ASSERT_TRUE(again.ok()) << again.status();
    EXPECT_EQ(again->cache, "memory");
    EXPECT_EQ(again->sphere_set_key, made->sphere_set_key);
    std::int64_t total = 0;
    for (const ServerCacheStats& s : Stats(all)) total += s.computations;
    std::int64_t before_total = 0;
    for (const ServerCacheStats& s : after) before_total += s.computations;
    EXPECT_EQ(total, before_total);
  }

  // Uploaded sets: with a mesh, its route digits; a set moved by UpdateDeformation and stored,
  // those of the set it came from; both found by the routed client (on the replica that holds
  // them, or GetSphereSet would be NOT_FOUND).
  const Mesh& mesh = meshes_[0];
  absl::StatusOr<GenerateResult> made = routed_->Generate(mesh, CoarseFor(mesh));
  ASSERT_TRUE(made.ok()) << made.status();
  const std::string route = made->mesh_sha256.substr(7, 16);
  absl::StatusOr<PutSphereSetResult> uploaded = routed_->PutSphereSet(made->set, made->mesh_sha256);
  ASSERT_TRUE(uploaded.ok()) << uploaded.status();
  EXPECT_EQ(uploaded->sphere_set_key.substr(11, 16), route);
  DeformationSettings store;
  store.store = true;
  Vertices moved = mesh.vertices;
  moved.col(2).array() *= 1.05;
  absl::StatusOr<DeformationResult> deformed =
      routed_->UpdateDeformation("", made->sphere_set_key, moved, store);
  ASSERT_TRUE(deformed.ok()) << deformed.status();
  EXPECT_EQ(deformed->sphere_set_key.substr(11, 16), route);
  EXPECT_TRUE(routed_->GetSphereSet(deformed->sphere_set_key).ok());
  // Without a mesh: a full hash, found wherever it routes (put there too when need be).
  for (int k = 0; k < 4; ++k) {
    SphereSet set;
    set.spheres = {Sphere{Vector3(k, 0, 0), 1.0}};
    absl::StatusOr<PutSphereSetResult> loose = routed_->PutSphereSet(set);
    ASSERT_TRUE(loose.ok()) << loose.status();
    absl::StatusOr<StoredSphereSet> got = routed_->GetSphereSet(loose->sphere_set_key);
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_TRUE(got->mesh_sha256.empty());
  }
}

TEST_F(FailoverTest, KillingAReplicaMidStreamFailsNoIdempotentCall) {
  // Every mesh generated through the routing, then on every replica directly: without a shared
  // tier a replica can only serve the sets it holds, and this test is about failover, not about
  // recomputing what a dead replica took with it.
  std::vector<std::string> mesh_keys, set_keys;
  for (const Mesh& mesh : meshes_) {
    absl::StatusOr<GenerateResult> made = routed_->Generate(mesh, CoarseFor(mesh));
    ASSERT_TRUE(made.ok()) << made.status();
    mesh_keys.push_back(made->mesh_sha256);
    set_keys.push_back(made->sphere_set_key);
    for (const Client& direct : direct_) {
      absl::StatusOr<GenerateResult> copy = direct.Generate(mesh, CoarseFor(mesh));
      ASSERT_TRUE(copy.ok()) << copy.status();
      ASSERT_EQ(copy->sphere_set_key, made->sphere_set_key);  // content keys: the same everywhere
    }
  }
  // The victim owns the first mesh (so at least one).
  const int victim = Order(mesh_keys[0])[0];

  // A simulator's session on the victim's set, answering before the kill.
  absl::StatusOr<DistanceSession> session = routed_->OpenDistanceSession();
  ASSERT_TRUE(session.ok());
  RigidPose apart;
  apart.translation = Vector3(5, 0, 0);
  const std::vector<PosePair> frame = {PosePair{set_keys[0], set_keys[0], RigidPose(), apart}};
  absl::StatusOr<std::vector<DistanceResult>> before_kill = session->Query(frame);
  ASSERT_TRUE(before_kill.ok()) << before_kill.status();

  // Two threads: PutMesh, Generate, GetSphereSet, Distance over every mesh in turn.
  constexpr int kRounds = 40;
  std::atomic<int> calls{0};
  std::mutex failures_mutex;
  std::vector<std::string> failures;
  const auto check = [&](const char* rpc, const absl::Status& status, std::size_t m) {
    ++calls;
    if (status.ok()) return;
    std::lock_guard<std::mutex> lock(failures_mutex);
    failures.push_back(std::string(rpc) + " mesh " + std::to_string(m) + ": " + status.ToString());
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t) {
    threads.emplace_back([&, t] {
      for (int r = 0; r < kRounds; ++r) {
        const std::size_t m = static_cast<std::size_t>(r + 3 * t) % meshes_.size();
        check("PutMesh", routed_->PutMesh(meshes_[m]).status(), m);
        check("Generate", routed_->Generate(mesh_keys[m], CoarseFor(meshes_[m])).status(), m);
        check("GetSphereSet", routed_->GetSphereSet(set_keys[m]).status(), m);
        check("Distance",
              routed_->Distance(set_keys[m], set_keys[m], {RigidPose()}, {apart, RigidPose()})
                  .status(),
              m);
      }
    });
  }
  const int total = 2 * kRounds * 4;
  while (calls.load() < total / 4) std::this_thread::sleep_for(milliseconds(5));
  const int calls_at_kill = calls.load();
  EXPECT_NE(replicas_[victim]->StopWith(SIGKILL, seconds(10)), -1);
  for (std::thread& t : threads) t.join();

  int owned = 0;
  for (const std::string& key : mesh_keys) owned += Order(key)[0] == victim;
  std::cout << "killed " << names_[victim] << " (owner of " << owned << " of " << mesh_keys.size()
            << " meshes) after " << calls_at_kill << " of " << total << " calls\n";
  EXPECT_EQ(calls.load(), total);
  EXPECT_LT(calls_at_kill, total / 2) << "the kill came too late to test anything";
  EXPECT_TRUE(failures.empty()) << failures.size()
                                << " failed calls, the first: " << failures.front();

  // The session that was on the victim reopened on the second choice and keeps answering.
  absl::StatusOr<std::vector<DistanceResult>> after_kill = session->Query(frame);
  ASSERT_TRUE(after_kill.ok()) << after_kill.status();
  EXPECT_NEAR((*after_kill)[0].distance, (*before_kill)[0].distance, 1e-12);
  EXPECT_TRUE(session->Close().ok());

  // Each key is now served by its first surviving choice: the victim's keys by their second.
  std::vector<int> survivors;
  for (int i = 0; i < kReplicas; ++i) {
    if (i != victim) survivors.push_back(i);
  }
  for (std::size_t m = 0; m < set_keys.size(); ++m) {
    const std::vector<int> order = Order(set_keys[m]);
    const int expected = order[0] == victim ? order[1] : order[0];
    const std::vector<ServerCacheStats> before = Stats(survivors);
    ASSERT_TRUE(routed_->GetSphereSet(set_keys[m]).ok());
    const std::vector<ServerCacheStats> after = Stats(survivors);
    for (std::size_t s = 0; s < survivors.size(); ++s) {
      EXPECT_EQ(after[s].memory_hits - before[s].memory_hits, survivors[s] == expected ? 1 : 0)
          << "mesh " << m << " on " << names_[survivors[s]]
          << (order[0] == victim ? " (the victim's)" : "");
    }
  }
}

}  // namespace
}  // namespace inscribe::client
