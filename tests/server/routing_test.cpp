// The routed Connection against mock replicas: which replica each RPC reaches, failover on
// UNAVAILABLE only (in rendezvous order, down replicas last, until the deadline), the double put
// of a moved key, DistanceStream failover, round robin, and concurrent calls while a replica
// goes down. RouteKey and RendezvousOrder themselves: rendezvous_test.cpp.
#include "inscribe/client/routing.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "absl/strings/str_cat.h"
#include "client_test_support.h"
#include "inscribe/geometry/mesh_hash.h"
#include "inscribe/wire/keys.h"

namespace inscribe::client {
namespace {

using std::chrono::milliseconds;
using ::testing::_;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::NiceMock;
using ::testing::Return;

std::string RandomHex(std::mt19937_64& bits, int digits) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string hex;
  for (int i = 0; i < digits; ++i) hex += kDigits[bits() & 15];
  return hex;
}

std::string MeshKey(std::mt19937_64& bits) { return "sha256:" + RandomHex(bits, 64); }

// A set key of `mesh_key`'s layout: its 16 route digits, then 48 of a hash.
std::string SetKeyOf(const std::string& mesh_key, std::mt19937_64& bits) {
  return "spheres/v1/" + mesh_key.substr(7, 16) + RandomHex(bits, 48);
}

std::string HashOf(const Mesh& mesh) { return FormatSha256(MeshSha256(mesh)); }

Deadline In(milliseconds ms) { return std::chrono::system_clock::now() + ms; }

// Client options with `attempts` RPCs per call and a backoff longer than any test waits: a
// call that succeeds within its 5 s timeout failed over without waiting.
ClientOptions Attempts(int attempts) {
  ClientOptions options;
  options.default_timeout = milliseconds(5000);
  options.retry.max_attempts = attempts;
  options.retry.initial_backoff = milliseconds(60'000);
  options.retry.max_backoff = milliseconds(60'000);
  return options;
}

// `n` mock replicas ("replica-0", ...) behind one routed connection. Every RPC answers OK by
// default and records which replica it reached (thread-safe). Not movable: the default
// actions point at it.
class Fleet {
 public:
  explicit Fleet(int n, const RoutingOptions& options = {}) {
    std::vector<Endpoint> endpoints;
    for (int i = 0; i < n; ++i) {
      names.push_back("replica-" + std::to_string(i));
      replicas.push_back(std::make_shared<NiceMock<MockConnection>>());
      Answer(i);
      endpoints.push_back({names.back(), replicas.back()});
    }
    absl::StatusOr<std::shared_ptr<Connection>> made =
        MakeRoutedConnection(std::move(endpoints), options);
    EXPECT_TRUE(made.ok()) << made.status();
    routed = *std::move(made);
  }
  Fleet(const Fleet&) = delete;
  Fleet& operator=(const Fleet&) = delete;

  // The replica rendezvous hashing gives `key` first, and the one after it.
  int Owner(const std::string& key) const { return RendezvousOrder(wire::RouteKey(key), names)[0]; }
  int Second(const std::string& key) const {
    return RendezvousOrder(wire::RouteKey(key), names)[1];
  }

  // Replicas reached since the last call, in order.
  std::vector<int> TakeCalls() {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::exchange(calls_, {});
  }
  void Record(int i) {
    std::lock_guard<std::mutex> lock(mutex_);
    calls_.push_back(i);
  }

  std::vector<std::string> names;
  std::vector<std::shared_ptr<NiceMock<MockConnection>>> replicas;
  std::shared_ptr<Connection> routed;

 private:
  // An action answering `response` and recording that replica `i` was reached.
  template <typename Response>
  auto Answering(int i, Response response) {
    return [this, i, response](const auto&...) {
      Record(i);
      return absl::StatusOr<Response>(response);
    };
  }

  void Answer(int i) {
    MockConnection& m = *replicas[i];
    ON_CALL(m, InspectMesh(_, _)).WillByDefault(Answering(i, CubeResponse()));
    // The key of the mesh as sent: the server changed nothing.
    ON_CALL(m, PutMesh(_, _)).WillByDefault([this, i](const v1::PutMeshRequest& r, Deadline) {
      Record(i);
      v1::PutMeshResponse response = PutMeshOk();
      response.set_mesh_sha256(HashOf(*wire::MeshFromProto(r.mesh())));
      return absl::StatusOr<v1::PutMeshResponse>(response);
    });
    ON_CALL(m, Generate(_, _, _)).WillByDefault(Answering(i, GenerateOk()));
    // A set of a mesh gets the mesh's route digits (as inscribed does).
    ON_CALL(m, PutSphereSet(_, _))
        .WillByDefault([this, i](const v1::PutSphereSetRequest& r, Deadline) {
          Record(i);
          v1::PutSphereSetResponse response = PutSphereSetOk();
          if (!r.mesh_sha256().empty()) {
            response.set_sphere_set_key("spheres/v1/" + r.mesh_sha256().substr(7, 16) +
                                        std::string(48, '0'));
          }
          return absl::StatusOr<v1::PutSphereSetResponse>(response);
        });
    ON_CALL(m, GetSphereSet(_, _)).WillByDefault(Answering(i, GetSphereSetOk()));
    ON_CALL(m, GetHierarchy(_, _))
        .WillByDefault(Answering(i, HierarchyOk(HierarchyVolume::kSphere)));
    ON_CALL(m, UpdateDeformation(_, _)).WillByDefault(Answering(i, DeformationOk()));
    // seconds = the replica's index, so that concurrent callers can tell who answered.
    v1::DistanceResponse distance = DistanceOk(1);
    distance.set_seconds(i);
    ON_CALL(m, Distance(_, _)).WillByDefault(Answering(i, distance));
    ON_CALL(m, Evaluate(_, _)).WillByDefault(Answering(i, EvaluateOk()));
    v1::CacheStatsResponse stats;
    stats.set_entries(i);
    ON_CALL(m, CacheStats(_, _)).WillByDefault(Answering(i, stats));
  }

  std::mutex mutex_;
  std::vector<int> calls_;  // guarded by mutex_
};

TEST(MakeRoutedConnection, RejectsNoEndpointsDuplicatesAndNull) {
  EXPECT_EQ(MakeRoutedConnection({}).status().code(), absl::StatusCode::kInvalidArgument);
  auto c = std::make_shared<NiceMock<MockConnection>>();
  absl::StatusOr<std::shared_ptr<Connection>> twice = MakeRoutedConnection({{"a", c}, {"a", c}});
  EXPECT_EQ(twice.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(twice.status().message(), HasSubstr("a"));
  EXPECT_EQ(MakeRoutedConnection({{"a", c}, {"b", nullptr}}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(MakeRoutedConnection({{"a", c}}).ok());
}

// Meshes with different hashes, at least one owned by each of the fleet's replicas.
std::vector<Mesh> MeshesOwnedByEach(const Fleet& fleet) {
  std::vector<Mesh> meshes;
  std::set<int> owners;
  for (int k = 0; k < 64 && owners.size() < fleet.names.size(); ++k) {
    Mesh mesh = testing::Box(Vector3(k, 0, 0), Vector3(k + 1, 1, 1));
    owners.insert(fleet.Owner(HashOf(mesh)));
    meshes.push_back(std::move(mesh));
  }
  EXPECT_EQ(owners.size(), fleet.names.size());
  return meshes;
}

TEST(RoutedConnection, SendsEachCallToTheOwnerOfTheKeyItNames) {
  Fleet fleet(3);
  Client client(fleet.routed);
  std::mt19937_64 bits(5);
  for (const Mesh& mesh : MeshesOwnedByEach(fleet)) {
    const std::string mesh_key = HashOf(mesh);
    const int owner = fleet.Owner(mesh_key);
    const std::string set_key = SetKeyOf(mesh_key, bits);
    ASSERT_EQ(fleet.Owner(set_key), owner);
    const std::vector<int> expected = {owner};

    ASSERT_TRUE(client.InspectMesh(mesh).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "InspectMesh";
    ASSERT_TRUE(client.PutMesh(mesh).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "PutMesh";
    GenerateSettings settings;
    settings.parameters.voxel_size = 0.1;
    ASSERT_TRUE(client.Generate(mesh_key, settings).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "Generate";
    SphereSet set;
    set.spheres = {Sphere{Vector3(0.5, 0.5, 0.5), 0.25}};
    ASSERT_TRUE(client.PutSphereSet(set, mesh_key).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "PutSphereSet";
    ASSERT_TRUE(client.GetSphereSet(set_key).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "GetSphereSet";
    ASSERT_TRUE(client.GetHierarchy(set_key, HierarchyVolume::kSphere).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "GetHierarchy";
    ASSERT_TRUE(client.UpdateDeformation("", set_key, mesh.vertices).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "UpdateDeformation";
    // Routed by set A, whatever B is.
    ASSERT_TRUE(
        client.Distance(set_key, SetKeyOf(MeshKey(bits), bits), {RigidPose()}, {RigidPose()}).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "Distance";
    ASSERT_TRUE(client.Evaluate(MeshKey(bits), set_key).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "Evaluate by set key";
    ASSERT_TRUE(client.Evaluate(mesh_key, set).ok());
    EXPECT_EQ(fleet.TakeCalls(), expected) << "Evaluate inline";
  }
  // CacheStats: the first endpoint listed.
  absl::StatusOr<ServerCacheStats> stats = client.CacheStats();
  ASSERT_TRUE(stats.ok());
  EXPECT_EQ(stats->entries, 0);
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(0));
}

TEST(RoutedConnection, FailsOverInRendezvousOrderAndTriesADownReplicaLast) {
  RoutingOptions options;
  options.down_for = std::chrono::hours(1);
  Fleet fleet(3, options);
  std::mt19937_64 bits(9);
  const std::string key = SetKeyOf(MeshKey(bits), bits);
  const std::vector<int> order = RendezvousOrder(wire::RouteKey(key), fleet.names);
  EXPECT_CALL(*fleet.replicas[order[0]], GetSphereSet(_, _))
      .WillOnce([&](const v1::GetSphereSetRequest&, Deadline) {
        fleet.Record(order[0]);
        return absl::UnavailableError("connection refused");
      });
  const Client client(fleet.routed, Attempts(3));
  absl::StatusOr<StoredSphereSet> got = client.GetSphereSet(key);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(order[0], order[1]));

  // The failed replica is now tried last: straight to the second.
  ASSERT_TRUE(client.GetSphereSet(key).ok());
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(order[1]));
  // Also for other keys it owns; keys it does not own are unaffected.
  for (int k = 0; k < 50; ++k) {
    const std::string other = SetKeyOf(MeshKey(bits), bits);
    const std::vector<int> o = RendezvousOrder(wire::RouteKey(other), fleet.names);
    ASSERT_TRUE(client.GetSphereSet(other).ok());
    EXPECT_THAT(fleet.TakeCalls(), ElementsAre(o[0] == order[0] ? o[1] : o[0]));
  }

  // Every replica down: each tried once, the last error returned naming them all.
  for (int i = 0; i < 3; ++i) {
    EXPECT_CALL(*fleet.replicas[i], GetSphereSet(_, _))
        .WillOnce([&, i](const v1::GetSphereSetRequest&, Deadline) {
          fleet.Record(i);
          return absl::UnavailableError("down " + std::to_string(i));
        });
  }
  got = client.GetSphereSet(key);
  EXPECT_EQ(got.status().code(), absl::StatusCode::kUnavailable);
  // order[0] was marked down first, so it goes last.
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(order[1], order[2], order[0]));
  EXPECT_THAT(got.status().message(), HasSubstr("down " + std::to_string(order[0])));
  EXPECT_THAT(got.status().message(), HasSubstr(fleet.names[order[0]]));
  EXPECT_THAT(got.status().message(), HasSubstr("gave up after 3 attempts"));
  EXPECT_FALSE(got.status().GetPayload(kRetryElsewherePayload).has_value());
}

// The retry and failover policy has one layer (connection.h): a call makes exactly
// max_attempts RPCs however many replicas there are, each to a replica not yet tried while one
// is left, failing over at once; a single server gets the backoff between attempts.
TEST(RoutedConnection, ACallMakesMaxAttemptsRpcsInAll) {
  for (const int replicas : {1, 2, 3, 5}) {
    for (const int attempts : {1, 2, 3, 7}) {
      SCOPED_TRACE(absl::StrCat(replicas, " replicas, ", attempts, " attempts"));
      RoutingOptions routing;
      routing.down_for = std::chrono::hours(1);
      Fleet fleet(replicas, routing);
      for (int i = 0; i < replicas; ++i) {
        ON_CALL(*fleet.replicas[i], GetSphereSet(_, _))
            .WillByDefault([&fleet, i](const v1::GetSphereSetRequest&, Deadline) {
              fleet.Record(i);
              return absl::StatusOr<v1::GetSphereSetResponse>(absl::UnavailableError("down"));
            });
      }
      ClientOptions options;
      options.retry.max_attempts = attempts;
      options.retry.initial_backoff = milliseconds(40);
      options.retry.max_backoff = milliseconds(40);
      const Client client(fleet.routed, options);
      const auto start = std::chrono::steady_clock::now();
      const absl::StatusOr<StoredSphereSet> got =
          client.GetSphereSet("spheres/v1/" + std::string(64, 'b'));
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      EXPECT_EQ(got.status().code(), absl::StatusCode::kUnavailable);
      const std::vector<int> calls = fleet.TakeCalls();
      EXPECT_EQ(static_cast<int>(calls.size()), attempts);
      // Every replica is reached before any is tried twice.
      for (int k = 0; k < static_cast<int>(calls.size()); ++k) {
        EXPECT_EQ(calls[k], calls[k % replicas]) << k;
        if (k < replicas) {
          for (int j = 0; j < k; ++j) EXPECT_NE(calls[j], calls[k]);
        }
      }
      if (replicas == 1) {
        // A lone server: the backoff (jittered to 20-40 ms) before each further attempt.
        EXPECT_GE(seconds, 0.02 * (attempts - 1));
      }
    }
  }
}

TEST(RoutedConnection, ADownReplicaIsTriedFirstAgainAfterDownFor) {
  RoutingOptions options;
  options.down_for = milliseconds(50);
  Fleet fleet(3, options);
  std::mt19937_64 bits(13);
  const std::string key = MeshKey(bits);
  const int owner = fleet.Owner(key), second = fleet.Second(key);
  EXPECT_CALL(*fleet.replicas[owner], Generate(_, _, _))
      .WillOnce(Return(absl::UnavailableError("reset")))
      .WillRepeatedly(
          [&](const v1::GenerateRequest&, Deadline, const std::function<void(double)>&) {
            fleet.Record(owner);
            return absl::StatusOr<v1::GenerateResult>(GenerateOk());
          });
  const Client client(fleet.routed, Attempts(2));
  ASSERT_TRUE(client.Generate(key, GenerateSettings{}).ok());
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(second));
  std::this_thread::sleep_for(milliseconds(200));  // > down_for
  ASSERT_TRUE(client.Generate(key, GenerateSettings{}).ok());
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(owner));
}

TEST(RoutedConnection, StopsFailingOverAtTheDeadline) {
  Fleet fleet(3);
  std::mt19937_64 bits(17);
  const std::string key = SetKeyOf(MeshKey(bits), bits);
  EXPECT_CALL(*fleet.replicas[fleet.Owner(key)], GetHierarchy(_, _))
      .WillOnce(Return(absl::UnavailableError("refused")));
  v1::GetHierarchyRequest request;
  request.set_sphere_set_key(key);
  // Already past: the owner is tried, nobody after it.
  EXPECT_EQ(fleet.routed->GetHierarchy(request, In(milliseconds(-1000))).status().code(),
            absl::StatusCode::kUnavailable);
  EXPECT_TRUE(fleet.TakeCalls().empty());
}

TEST(RoutedConnection, ReturnsOtherErrorsUnchanged) {
  Fleet fleet(3);
  std::mt19937_64 bits(19);
  for (const absl::Status& error :
       {absl::NotFoundError("unknown sphere set"), absl::InvalidArgumentError("bad"),
        absl::DeadlineExceededError("late"), absl::ResourceExhaustedError("--max-poses"),
        absl::InternalError("bug")}) {
    const std::string key = SetKeyOf(MeshKey(bits), bits);
    EXPECT_CALL(*fleet.replicas[fleet.Owner(key)], Distance(_, _)).WillOnce(Return(error));
    v1::DistanceRequest request;
    request.set_sphere_set_a(key);
    EXPECT_EQ(fleet.routed->Distance(request, In(milliseconds(5000))).status(), error);
    EXPECT_TRUE(fleet.TakeCalls().empty()) << "failed over after " << error;
  }
}

TEST(RoutedConnection, PutMeshAlsoPutsWhereTheStoredKeyRoutes) {
  Fleet fleet(3);
  std::mt19937_64 bits(23);
  const Mesh mesh = testing::UnitCube();
  const int sent_owner = fleet.Owner(HashOf(mesh));
  // The server fixed the mesh: its key is another, owned by another replica.
  std::string fixed;
  do fixed = MeshKey(bits);
  while (fleet.Owner(fixed) == sent_owner);
  const int fixed_owner = fleet.Owner(fixed);
  for (int i : {sent_owner, fixed_owner}) {
    EXPECT_CALL(*fleet.replicas[i], PutMesh(_, _))
        .WillOnce([&, i](const v1::PutMeshRequest& r, Deadline) {
          EXPECT_EQ(r.mesh().vertices_size(), 24);
          fleet.Record(i);
          v1::PutMeshResponse response = PutMeshOk();
          response.set_mesh_sha256(fixed);
          response.set_already_stored(i == fixed_owner);
          return absl::StatusOr<v1::PutMeshResponse>(response);
        });
  }
  absl::StatusOr<PutMeshResult> put = Client(fleet.routed).PutMesh(mesh);
  ASSERT_TRUE(put.ok()) << put.status();
  EXPECT_EQ(put->mesh_sha256, fixed);
  EXPECT_TRUE(put->already_stored);  // the answer of the replica later calls reach
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(sent_owner, fixed_owner));

  // A key that routes to the same replica: one put.
  std::string same;
  do same = MeshKey(bits);
  while (fleet.Owner(same) != sent_owner);
  EXPECT_CALL(*fleet.replicas[sent_owner], PutMesh(_, _))
      .WillOnce([&](const v1::PutMeshRequest&, Deadline) {
        fleet.Record(sent_owner);
        v1::PutMeshResponse response = PutMeshOk();
        response.set_mesh_sha256(same);
        return absl::StatusOr<v1::PutMeshResponse>(response);
      });
  ASSERT_TRUE(Client(fleet.routed).PutMesh(mesh).ok());
  EXPECT_THAT(fleet.TakeCalls(), ElementsAre(sent_owner));
}

TEST(RoutedConnection, SetWithoutMeshIsPutWhereItsKeyRoutes) {
  Fleet fleet(3);
  std::mt19937_64 bits(29);
  int doubled = 0;
  for (int k = 0; k < 12; ++k) {
    const std::string key = "spheres/v1/" + RandomHex(bits, 64);  // the server's full hash
    std::vector<int> reached;
    for (int i = 0; i < 3; ++i) {
      EXPECT_CALL(*fleet.replicas[i], PutSphereSet(_, _))
          .WillRepeatedly([&, i](const v1::PutSphereSetRequest&, Deadline) {
            reached.push_back(i);
            v1::PutSphereSetResponse response;
            response.set_sphere_set_key(key);
            return absl::StatusOr<v1::PutSphereSetResponse>(response);
          });
    }
    SphereSet set;
    set.spheres = {Sphere{Vector3(k, 0, 0), 1.0}};
    absl::StatusOr<PutSphereSetResult> put = Client(fleet.routed).PutSphereSet(set);
    ASSERT_TRUE(put.ok());
    ASSERT_FALSE(reached.empty());
    EXPECT_EQ(reached.back(), fleet.Owner(key));
    EXPECT_LE(reached.size(), 2u);
    doubled += reached.size() == 2;
  }
  EXPECT_GT(doubled, 0);
}

// The answer to `frame`: one result per pair.
v1::DistanceFrameResult Reply(const v1::DistanceFrame& frame) {
  v1::DistanceFrameResult reply;
  reply.set_frame(frame.frame());
  *reply.mutable_results() = Results(frame.pairs_size());
  return reply;
}

TEST(RoutedConnection, DistanceSessionKeepsAnsweringAcrossAFailover) {
  Fleet fleet(3);
  std::mt19937_64 bits(37);
  const std::string key = SetKeyOf(MeshKey(bits), bits);
  const std::vector<int> order = RendezvousOrder(wire::RouteKey(key), fleet.names);
  std::vector<std::int64_t> owner_frames, second_frames;
  auto first_stream = std::make_unique<NiceMock<MockDistanceStream>>();
  EXPECT_CALL(*first_stream, RoundTrip(_, _))
      .Times(3)
      .WillRepeatedly(
          [&](const v1::DistanceFrame& frame, Deadline) -> absl::StatusOr<v1::DistanceFrameResult> {
            owner_frames.push_back(frame.frame());
            if (frame.frame() == 2) return absl::UnavailableError("Socket closed");
            return Reply(frame);
          });
  EXPECT_CALL(*first_stream, Finish()).Times(0);
  auto second_stream = std::make_unique<NiceMock<MockDistanceStream>>();
  EXPECT_CALL(*second_stream, RoundTrip(_, _))
      .Times(2)
      .WillRepeatedly([&](const v1::DistanceFrame& frame, Deadline) {
        second_frames.push_back(frame.frame());
        return absl::StatusOr<v1::DistanceFrameResult>(Reply(frame));
      });
  EXPECT_CALL(*second_stream, Finish()).WillOnce(Return(absl::OkStatus()));
  bool opened = false;
  EXPECT_CALL(*fleet.replicas[order[0]], OpenDistanceStream(_))
      .WillOnce([&](Deadline) -> absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> {
        opened = true;
        return std::unique_ptr<DistanceStreamConnection>(std::move(first_stream));
      });
  EXPECT_CALL(*fleet.replicas[order[1]], OpenDistanceStream(_))
      .WillOnce(Return(std::unique_ptr<DistanceStreamConnection>(std::move(second_stream))));
  EXPECT_CALL(*fleet.replicas[order[2]], OpenDistanceStream(_)).Times(0);

  absl::StatusOr<DistanceSession> session = Client(fleet.routed).OpenDistanceSession();
  ASSERT_TRUE(session.ok());
  EXPECT_FALSE(opened) << "the first frame says where the stream goes";
  for (int f = 0; f < 4; ++f) {
    // The first pair's set A routes the stream; B and later pairs name sets of other meshes.
    absl::StatusOr<std::vector<DistanceResult>> results =
        session->Query({PosePair{key, SetKeyOf(MeshKey(bits), bits), {}, {}},
                        PosePair{SetKeyOf(MeshKey(bits), bits), key, {}, {}}});
    ASSERT_TRUE(results.ok()) << "frame " << f << ": " << results.status();
    EXPECT_EQ(results->size(), 2u);
  }
  EXPECT_TRUE(session->Close().ok());
  // Frame 2 was sent again, with its own number, on the new stream.
  EXPECT_THAT(owner_frames, ElementsAre(0, 1, 2));
  EXPECT_THAT(second_frames, ElementsAre(2, 3));
}

TEST(RoutedConnection, DistanceStreamEndsOnOtherErrors) {
  Fleet fleet(3);
  std::mt19937_64 bits(41);
  const std::string key = SetKeyOf(MeshKey(bits), bits);
  const absl::Status unknown = absl::NotFoundError("unknown sphere set");
  auto stream = std::make_unique<NiceMock<MockDistanceStream>>();
  EXPECT_CALL(*stream, RoundTrip(_, _)).WillOnce(Return(unknown));
  EXPECT_CALL(*fleet.replicas[fleet.Owner(key)], OpenDistanceStream(_))
      .WillOnce(Return(std::unique_ptr<DistanceStreamConnection>(std::move(stream))));
  for (int i = 0; i < 3; ++i) {
    if (i != fleet.Owner(key)) EXPECT_CALL(*fleet.replicas[i], OpenDistanceStream(_)).Times(0);
  }
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> routed =
      fleet.routed->OpenDistanceStream(Deadline::max());
  ASSERT_TRUE(routed.ok());
  v1::DistanceFrame frame;
  frame.add_pairs()->set_sphere_set_a(key);
  EXPECT_EQ((*routed)->RoundTrip(frame, In(milliseconds(5000))).status(), unknown);
  // Ended: later frames and Finish report the same error, no new stream is opened.
  EXPECT_EQ((*routed)->RoundTrip(frame, In(milliseconds(5000))).status(), unknown);
  EXPECT_EQ((*routed)->Finish(), unknown);
}

// A scene goes to the first replica up in its first object's set's order (its creating
// message is sent again to the next when the owner is unreachable); once created, a broken
// replica ends the scene with UNAVAILABLE: its state lived there, so nothing is resent.
TEST(RoutedConnection, SceneStreamFollowsItsFirstObjectAndIsNotMoved) {
  Fleet fleet(3);
  std::mt19937_64 bits(43);
  const std::string key = SetKeyOf(MeshKey(bits), bits);
  const std::vector<int> order = RendezvousOrder(wire::RouteKey(key), fleet.names);
  auto refused = std::make_unique<NiceMock<MockSceneStream>>();
  EXPECT_CALL(*refused, RoundTrip(_, _)).WillOnce(Return(absl::UnavailableError("refused")));
  auto second = std::make_unique<NiceMock<MockSceneStream>>();
  EXPECT_CALL(*second, RoundTrip(_, _))
      .WillOnce([](const v1::SceneMessage& message, Deadline) {
        EXPECT_EQ(message.add_size(), 2);
        v1::SceneReply reply;
        reply.set_frame(message.frame());
        return absl::StatusOr<v1::SceneReply>(reply);
      })
      .WillOnce(Return(absl::UnavailableError("Socket closed")));
  EXPECT_CALL(*fleet.replicas[order[0]], OpenSceneStream(_))
      .WillOnce(Return(std::unique_ptr<SceneStreamConnection>(std::move(refused))));
  EXPECT_CALL(*fleet.replicas[order[1]], OpenSceneStream(_))
      .WillOnce(Return(std::unique_ptr<SceneStreamConnection>(std::move(second))));
  EXPECT_CALL(*fleet.replicas[order[2]], OpenSceneStream(_)).Times(0);

  std::vector<SceneSessionObject> objects(2);
  objects[0].sphere_set_key = key;  // routes the scene
  objects[1].object.id = 1;
  objects[1].sphere_set_key = SetKeyOf(MeshKey(bits), bits);
  absl::StatusOr<SceneSession> session = Client(fleet.routed).OpenSceneSession(objects);
  ASSERT_TRUE(session.ok()) << session.status();
  absl::StatusOr<SceneFrameResult> frame = session->Frame({});
  EXPECT_EQ(frame.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_EQ(session->Frame({}).status(), frame.status());
}

TEST(RoutedConnection, RoundRobinSpreadsEvenlyAndFailsOver) {
  RoutingOptions options;
  options.policy = RoutingPolicy::kRoundRobin;
  options.down_for = std::chrono::hours(1);
  Fleet fleet(3, options);
  const std::string key = "spheres/v1/" + std::string(64, 'a');
  const Client client(fleet.routed, Attempts(3));
  std::vector<int> count(3, 0);
  for (int k = 0; k < 300; ++k) {
    ASSERT_TRUE(client.GetSphereSet(key).ok());
    for (int i : fleet.TakeCalls()) ++count[i];
  }
  EXPECT_THAT(count, ElementsAre(100, 100, 100));

  // Replica 1 goes down: tried once, then last; every call still answered.
  EXPECT_CALL(*fleet.replicas[1], GetSphereSet(_, _))
      .WillRepeatedly(Return(absl::UnavailableError("down")));
  std::fill(count.begin(), count.end(), 0);
  for (int k = 0; k < 300; ++k) {
    ASSERT_TRUE(client.GetSphereSet(key).ok());
    for (int i : fleet.TakeCalls()) ++count[i];
  }
  EXPECT_EQ(count[1], 0);
  EXPECT_EQ(count[0] + count[2], 300);
  EXPECT_NEAR(count[0], 150, 10);
}

TEST(RoutedConnection, ConcurrentCallsLoseNothingWhileAReplicaGoesDown) {
  Fleet fleet(3);
  std::atomic<bool> down{false};
  constexpr int kDown = 1;
  EXPECT_CALL(*fleet.replicas[kDown], Distance(_, _))
      .WillRepeatedly(
          [&](const v1::DistanceRequest&, Deadline) -> absl::StatusOr<v1::DistanceResponse> {
            if (down.load()) return absl::UnavailableError("connection reset");
            v1::DistanceResponse response = DistanceOk(1);
            response.set_seconds(kDown);
            return response;
          });
  constexpr int kThreads = 4, kCalls = 500;
  const Client client(fleet.routed, Attempts(3));
  std::atomic<int> failed{0}, misrouted{0}, done{0}, moved{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      std::mt19937_64 bits(100 + t);
      for (int c = 0; c < kCalls; ++c) {
        const std::string set_a = SetKeyOf(MeshKey(bits), bits);
        const std::vector<int> order = RendezvousOrder(wire::RouteKey(set_a), fleet.names);
        const bool down_before = down.load();
        absl::StatusOr<DistanceBatchResult> answer =
            client.Distance(set_a, set_a, {RigidPose{}}, {RigidPose{}});
        const bool down_after = down.load();
        if (!answer.ok()) {
          ++failed;
          continue;
        }
        // The owner answers, or (while it is down) its second choice; nobody else.
        const int by = static_cast<int>(answer->server_seconds);
        const bool owner_ok = by == order[0] && !(down_before && order[0] == kDown);
        const bool second_ok = by == order[1] && order[0] == kDown && down_after;
        if (!owner_ok && !second_ok) ++misrouted;
        moved += second_ok;
        if (++done == kThreads * kCalls / 3) down = true;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(failed.load(), 0);
  EXPECT_EQ(misrouted.load(), 0);
  EXPECT_GT(moved.load(), 200);  // about 2/3 of the calls x 1/3 of the keys
}

}  // namespace
}  // namespace inscribe::client
