// SceneStream against the real server in-process on loopback: every reply checked against
// core's Scene::ClosePairs on the same scene and against brute force over every pair; errors
// naming the object, the --max-scene-* limits, a client that cancels or goes away (its scene
// freed: InscribeServer::open_scenes), and draining, idle or in the middle of a message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/client/client.h"
#include "inscribe/distance/separation_distance.h"
#include "inscribe/distance/sphere_hierarchy.h"
#include "inscribe/scene/scene.h"
#include "spheres_rpc_fixture.h"
#include "support/sphere_sets.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

using Stream = grpc::ClientReaderWriter<v1::SceneMessage, v1::SceneReply>;

class SceneStreamTest : public SpheresRpcTest {
 protected:
  // Uploads `spheres` (no mesh); the set's key.
  std::string PutSet(const std::vector<Sphere>& spheres) {
    v1::PutSphereSetRequest request;
    SphereSet set;
    set.spheres = spheres;
    wire::SphereSetToProto(set, request.mutable_spheres());
    v1::PutSphereSetResponse response;
    const grpc::Status s = stub_->PutSphereSet(Context().get(), request, &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    return response.sphere_set_key();
  }

  // The first message: objects with `keys[i]` as object i's set.
  static v1::SceneMessage Create(const std::vector<SceneObject>& objects,
                                 const std::vector<std::string>& keys, const SceneQuery& query) {
    v1::SceneMessage message;
    for (std::size_t i = 0; i < objects.size(); ++i) {
      wire::SceneObjectToProto(objects[i], keys[i], "", message.add_add());
    }
    wire::SceneQueryToProto(query, message.mutable_query());
    return message;
  }

  // Sends `message` and reads its reply; false when the stream ended instead.
  static bool Send(Stream& stream, const v1::SceneMessage& message, v1::SceneReply* reply) {
    return stream.Write(message) && stream.Read(reply);
  }

  // Polls open_scenes() until it is `n` (10 s at most).
  bool OpenScenesReach(std::int64_t n) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
      if (server_->open_scenes() == n) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return server_->open_scenes() == n;
  }
};

// The reply equals `expected` (core's frame on the same scene): pairs, distances, witnesses.
// Numbers agree to rounding: the server normalises each pose once more than the local scene
// (wire's PoseFromProto, then Scene::Add), which can move a last bit.
void ExpectSameFrame(const v1::SceneReply& reply, const SceneFrame& expected) {
  absl::StatusOr<SceneFrame> got = wire::SceneFrameFromProto(reply);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->candidate_pairs, expected.candidate_pairs);
  EXPECT_EQ(got->close_pairs, expected.close_pairs);
  EXPECT_EQ(got->truncated, expected.truncated);
  ASSERT_EQ(got->pairs.size(), expected.pairs.size());
  for (std::size_t i = 0; i < expected.pairs.size(); ++i) {
    const ScenePair& g = got->pairs[i];
    const ScenePair& e = expected.pairs[i];
    EXPECT_EQ(g.a, e.a);
    EXPECT_EQ(g.b, e.b);
    EXPECT_NEAR(g.result.distance, e.result.distance, 1e-12);
    EXPECT_EQ(g.result.sphere_a, e.result.sphere_a);
    EXPECT_LT((g.result.point_b - e.result.point_b).norm(), 1e-12);
  }
}

// Every frame (poses moved, objects removed and added, the threshold changed) is answered as
// core's Scene answers it locally, and as brute force over every considered pair.
TEST_F(SceneStreamTest, EveryReplyEqualsCoreAndBruteForce) {
  std::vector<std::vector<Sphere>> sets;
  std::vector<std::string> set_keys;
  std::vector<std::shared_ptr<const SphereHierarchy>> hierarchies;
  for (int k = 0; k < 3; ++k) {
    sets.push_back(testing::RandomSpheres(30 + 10 * k, 100 + k));
    set_keys.push_back(PutSet(sets.back()));
    absl::StatusOr<SphereHierarchy> h =
        SphereHierarchy::Build(sets.back(), HierarchyVolume::kSphere);
    ASSERT_TRUE(h.ok()) << h.status();
    hierarchies.push_back(std::make_shared<const SphereHierarchy>(*std::move(h)));
  }
  std::mt19937_64 rng(7);
  std::map<SceneObjectId, int> set_of;  // id -> index into sets
  std::vector<SceneObject> objects;
  std::vector<std::string> keys;
  for (int i = 0; i < 12; ++i) {
    SceneObject object;
    object.id = 10 + i;
    object.pose = testing::RandomPose(rng, 1.2);
    if (i % 4 == 3) {  // group 2 only sees group 1
      object.group = 2;
      object.mask = 1;
    }
    set_of[object.id] = i % 3;
    objects.push_back(object);
    keys.push_back(set_keys[i % 3]);
  }
  SceneQuery query;
  query.threshold = 0.2;
  Scene local;
  for (SceneObject object : objects) {
    object.spheres = hierarchies[set_of[object.id]];
    ASSERT_TRUE(local.Add(object).ok());
  }
  ASSERT_TRUE(local.Ignore(10, 11).ok());

  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
  v1::SceneMessage create = Create(objects, keys, query);
  create.set_frame(500);
  wire::SceneIgnoredToProto({{11, 10}}, &create);
  v1::SceneReply reply;
  ASSERT_TRUE(Send(*stream, create, &reply)) << stream->Finish().error_message();
  EXPECT_EQ(reply.frame(), 500);
  EXPECT_EQ(reply.objects(), 12);
  {
    absl::StatusOr<SceneFrame> expected = local.ClosePairs(query);
    ASSERT_TRUE(expected.ok());
    ExpectSameFrame(reply, *expected);
  }
  std::map<SceneObjectId, RigidPose> poses;
  for (const SceneObject& object : objects) poses[object.id] = object.pose;
  std::int64_t reported = 0;
  for (int frame = 0; frame < 40; ++frame) {
    SCOPED_TRACE(frame);
    v1::SceneMessage message;
    message.set_frame(frame);
    std::vector<std::pair<SceneObjectId, RigidPose>> moved;
    for (int m = 0; m < 4; ++m) {
      const SceneObjectId id =
          std::next(poses.begin(), static_cast<long>(rng() % poses.size()))->first;
      if (std::any_of(moved.begin(), moved.end(), [&](const auto& p) { return p.first == id; })) {
        continue;
      }
      moved.emplace_back(id, testing::RandomPose(rng, 1.2));
    }
    if (frame == 15) {  // one object out, another in
      message.add_remove(12);
      ASSERT_TRUE(local.Remove(12).ok());
      poses.erase(12);
      moved.erase(
          std::remove_if(moved.begin(), moved.end(), [](const auto& p) { return p.first == 12; }),
          moved.end());
      SceneObject added;
      added.id = 99;
      added.pose = testing::RandomPose(rng, 1.2);
      wire::SceneObjectToProto(added, set_keys[2], "", message.add_add());
      added.spheres = hierarchies[2];
      set_of[99] = 2;
      poses[99] = added.pose;
      ASSERT_TRUE(local.Add(added).ok());
    }
    if (frame == 25) {
      query.threshold = 0.4;
      wire::SceneQueryToProto(query, message.mutable_query());
    }
    wire::ScenePosesToProto(moved, &message);
    ASSERT_TRUE(local.SetPoses(moved).ok());
    for (const auto& [id, pose] : moved) poses[id] = pose;
    ASSERT_TRUE(Send(*stream, message, &reply)) << stream->Finish().error_message();
    EXPECT_EQ(reply.frame(), frame);
    absl::StatusOr<SceneFrame> expected = local.ClosePairs(query);
    ASSERT_TRUE(expected.ok());
    ExpectSameFrame(reply, *expected);

    // Brute force: every pair the groups, masks and ignore list allow.
    std::vector<std::pair<SceneObjectId, SceneObjectId>> close;
    std::map<std::pair<SceneObjectId, SceneObjectId>, double> distance;
    for (auto i = poses.begin(); i != poses.end(); ++i) {
      for (auto j = std::next(i); j != poses.end(); ++j) {
        const auto group = [&](SceneObjectId id) {
          return (id - 10) % 4 == 3 && id != 99 ? 2u : 1u;
        };
        const auto mask = [&](SceneObjectId id) {
          return (id - 10) % 4 == 3 && id != 99 ? 1u : kAllSceneGroups;
        };
        if ((group(i->first) & mask(j->first)) == 0 || (group(j->first) & mask(i->first)) == 0) {
          continue;
        }
        if (i->first == 10 && j->first == 11) continue;
        absl::StatusOr<DistanceResult> brute = BruteForceSeparationDistance(
            sets[set_of[i->first]], i->second, sets[set_of[j->first]], j->second);
        ASSERT_TRUE(brute.ok());
        if (brute->distance < query.threshold) {
          close.emplace_back(i->first, j->first);
          distance[{i->first, j->first}] = brute->distance;
        }
      }
    }
    ASSERT_EQ(reply.pairs().a_size(), static_cast<int>(close.size()));
    for (int p = 0; p < reply.pairs().a_size(); ++p) {
      const std::pair<SceneObjectId, SceneObjectId> ids{reply.pairs().a(p), reply.pairs().b(p)};
      EXPECT_EQ(ids, close[static_cast<std::size_t>(p)]);
      EXPECT_NEAR(reply.pairs().distances(p), distance[ids], 1e-9);
    }
    reported += reply.pairs().a_size();
  }
  EXPECT_GT(reported, 20) << "the scene should have close pairs to check";
  stream->WritesDone();
  const grpc::Status s = stream->Finish();
  EXPECT_TRUE(s.ok()) << s.error_message();
  EXPECT_TRUE(OpenScenesReach(0));
}

// Objects with covers: a pair of two is reported with the certified interval Distance gives
// for the same sets and poses (and left out only when its lower bound is at least the
// threshold); a pair with a plain object gets the internal sets' plain distance.
TEST_F(SceneStreamTest, CertifiedPairsGetDistancesIntervals) {
  client::Client client(client::MakeGrpcConnection(server_->address()));
  std::string internal[2], cover[2];
  for (int k = 0; k < 2; ++k) {
    const Mesh box =
        testing::Box(Vector3::Zero(), k == 0 ? Vector3(2.0, 1.0, 0.5) : Vector3(1.0, 0.4, 0.4));
    client::GenerateSettings settings;
    settings.parameters.max_spheres = 30;
    settings.parameters.evaluate = false;
    absl::StatusOr<client::GenerateResult> made = client.Generate(box, settings);
    ASSERT_TRUE(made.ok()) << made.status();
    internal[k] = made->sphere_set_key;
    settings.parameters.kind = SphereSetKind::kCover;
    made = client.Generate(box, settings);
    ASSERT_TRUE(made.ok()) << made.status();
    cover[k] = made->sphere_set_key;
  }
  // Objects 1, 2: the slab, certified; 3: the bar, certified; 4: the bar, plain.
  const int solid[] = {0, 0, 1, 1};
  std::vector<client::SceneSessionObject> objects(4);
  std::mt19937_64 rng(9);
  for (int i = 0; i < 4; ++i) {
    objects[i].object.id = i + 1;
    objects[i].sphere_set_key = internal[solid[i]];
    if (i < 3) objects[i].cover_key = cover[solid[i]];
  }
  client::SceneSessionOptions options;
  options.query.threshold = 0.3;
  absl::StatusOr<client::SceneSession> session = client.OpenSceneSession(objects, options);
  ASSERT_TRUE(session.ok()) << session.status();
  int certified_reported = 0, plain_reported = 0;
  for (int frame = 0; frame < 12; ++frame) {
    SCOPED_TRACE(frame);
    std::vector<std::pair<SceneObjectId, RigidPose>> poses;
    for (auto& object : objects) {
      object.object.pose = testing::RandomPose(rng, 1.5);
      poses.emplace_back(object.object.id, object.object.pose);
    }
    absl::StatusOr<client::SceneFrameResult> result = session->Frame(poses);
    ASSERT_TRUE(result.ok()) << result.status();
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        const auto reported =
            std::find_if(result->pairs.begin(), result->pairs.end(), [&](const ScenePair& p) {
              return p.a == objects[i].object.id && p.b == objects[j].object.id;
            });
        client::DistanceOptions query;
        if (j < 3) {
          query.cover_a = cover[solid[i]];
          query.cover_b = cover[solid[j]];
        }
        absl::StatusOr<client::DistanceBatchResult> batch =
            client.Distance(internal[solid[i]], internal[solid[j]], {objects[i].object.pose},
                            {objects[j].object.pose}, query);
        ASSERT_TRUE(batch.ok()) << batch.status();
        if (j < 3) {
          const CertifiedDistanceResult& interval = batch->certified[0];
          if (reported == result->pairs.end()) {
            EXPECT_GE(interval.lower, options.query.threshold) << i << " " << j;
            continue;
          }
          ++certified_reported;
          EXPECT_TRUE(reported->certified);
          EXPECT_EQ(reported->lower, interval.lower) << i << " " << j;
          EXPECT_EQ(reported->upper, interval.upper) << i << " " << j;
        } else {
          const double distance = batch->results[0].distance;
          EXPECT_EQ(reported != result->pairs.end(), distance < options.query.threshold);
          if (reported == result->pairs.end()) continue;
          ++plain_reported;
          EXPECT_FALSE(reported->certified);
          EXPECT_NEAR(reported->result.distance, distance, 1e-9) << i << " " << j;
        }
      }
    }
  }
  EXPECT_GT(certified_reported, 3);
  EXPECT_GT(plain_reported, 0);
  EXPECT_TRUE(session->Close().ok());
}

// max_pairs keeps the nearest pairs and says the frame was truncated, as core does.
TEST_F(SceneStreamTest, MaxPairsKeepsTheNearestPairs) {
  const std::vector<Sphere> spheres = testing::RandomSpheres(20, 3);
  const std::string key = PutSet(spheres);
  absl::StatusOr<SphereHierarchy> h = SphereHierarchy::Build(spheres, HierarchyVolume::kSphere);
  ASSERT_TRUE(h.ok());
  const auto hierarchy = std::make_shared<const SphereHierarchy>(*std::move(h));
  std::mt19937_64 rng(4);
  std::vector<SceneObject> objects(6);
  Scene local;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    objects[i].id = i;
    objects[i].pose = testing::RandomPose(rng, 1.0);
    SceneObject with = objects[i];
    with.spheres = hierarchy;
    ASSERT_TRUE(local.Add(with).ok());
  }
  SceneQuery query;
  query.threshold = std::numeric_limits<double>::infinity();
  query.max_pairs = 100;
  query.max_pairs = 4;
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
  v1::SceneReply reply;
  ASSERT_TRUE(Send(*stream, Create(objects, std::vector<std::string>(6, key), query), &reply))
      << stream->Finish().error_message();
  absl::StatusOr<SceneFrame> expected = local.ClosePairs(query);
  ASSERT_TRUE(expected.ok());
  EXPECT_TRUE(reply.truncated());
  EXPECT_EQ(reply.close_pairs(), 15);
  EXPECT_EQ(reply.pairs().a_size(), 4);
  ExpectSameFrame(reply, *expected);
}

// A bad message ends the stream with a status naming the frame and the object or field.
TEST_F(SceneStreamTest, ErrorsEndTheStreamNamingTheObject) {
  const std::string key = PutSet(testing::RandomSpheres(10, 1));
  std::vector<SceneObject> objects(2);
  objects[0].id = 1;
  objects[1].id = 2;
  objects[1].pose.translation = Vector3(3, 0, 0);
  struct Case {
    std::function<void(v1::SceneMessage&)> spoil;
    grpc::StatusCode code;
    std::string says;
  };
  const auto add = [&](SceneObjectId id, const std::string& set) {
    return [id, set](v1::SceneMessage& m) {
      SceneObject object;
      object.id = id;
      wire::SceneObjectToProto(object, set, "", m.add_add());
    };
  };
  const std::vector<Case> cases = {
      {add(7, "spheres/v1/" + std::string(64, 'f')), grpc::StatusCode::NOT_FOUND,
       "frame 1 add[0] (object 7).sphere_set"},
      {add(2, key), grpc::StatusCode::ALREADY_EXISTS, "add[0] (object 2)"},
      {add(8, "not a key"), grpc::StatusCode::INVALID_ARGUMENT, "add[0] (object 8)"},
      {[](v1::SceneMessage& m) {
         wire::ScenePosesToProto({{99, RigidPose{}}}, &m);
       },
       grpc::StatusCode::NOT_FOUND, "pose_ids[0]: no object 99"},
      {[](v1::SceneMessage& m) {
         wire::ScenePosesToProto({{1, RigidPose{}}}, &m);
         m.mutable_poses()->set_values(0, 0.0);
       },
       grpc::StatusCode::INVALID_ARGUMENT, "poses pose 0"},
      {[](v1::SceneMessage& m) { m.add_pose_ids(1); }, grpc::StatusCode::INVALID_ARGUMENT,
       "pose_ids has 1 ids for 0 poses"},
      {[](v1::SceneMessage& m) { m.add_remove(5); }, grpc::StatusCode::NOT_FOUND, "remove[0]"},
      {[](v1::SceneMessage& m) { m.add_ignore(1); }, grpc::StatusCode::INVALID_ARGUMENT,
       "ignore has 1 ids"},
      {[](v1::SceneMessage& m) {
         wire::SceneIgnoredToProto({{1, 1}}, &m);
       },
       grpc::StatusCode::INVALID_ARGUMENT, "ignore pair 0 (1, 1)"},
      {[](v1::SceneMessage& m) { m.set_volume(v1::RSS); }, grpc::StatusCode::INVALID_ARGUMENT,
       "only the first message"},
      {[](v1::SceneMessage& m) { m.mutable_query()->set_abs_err(-1.0); },
       grpc::StatusCode::INVALID_ARGUMENT, "query"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.says);
    auto context = Context();
    std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
    v1::SceneReply reply;
    ASSERT_TRUE(Send(*stream, Create(objects, {key, key}, SceneQuery{}), &reply));
    v1::SceneMessage message;
    message.set_frame(1);
    c.spoil(message);
    EXPECT_FALSE(Send(*stream, message, &reply));
    const grpc::Status s = stream->Finish();
    EXPECT_EQ(s.error_code(), c.code) << s.error_message();
    EXPECT_THAT(s.error_message(), HasSubstr(c.says));
  }
  // The first message must carry the query.
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
  v1::SceneMessage no_query = Create(objects, {key, key}, SceneQuery{});
  no_query.clear_query();
  v1::SceneReply reply;
  EXPECT_FALSE(Send(*stream, no_query, &reply));
  const grpc::Status s = stream->Finish();
  EXPECT_EQ(s.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(s.error_message(), HasSubstr("must carry its query"));
  EXPECT_TRUE(OpenScenesReach(0));
}

// Each --max-scene-* limit and --memory-budget refuses a scene beyond it, naming the flag.
TEST_F(SceneStreamTest, LimitsAreRefusedNamingTheFlag) {
  configure_ = [](ServerOptions& options) {
    options.limits.max_scene_objects = 4;
    options.limits.max_scene_pairs = 10;
    options.limits.max_scene_ignored = 2;
    options.limits.memory_budget_bytes = 64 << 10;
  };
  Restart();
  const std::string key = PutSet(testing::RandomSpheres(10, 1));
  std::vector<SceneObject> objects(4);
  for (std::size_t i = 0; i < objects.size(); ++i) objects[i].id = i;
  SceneQuery query;
  query.max_pairs = 10;
  struct Case {
    std::function<void(v1::SceneMessage&)> spoil;
    std::string says;
  };
  const std::vector<Case> cases = {
      {[&](v1::SceneMessage& m) {
         SceneObject extra;
         extra.id = 9;
         wire::SceneObjectToProto(extra, key, "", m.add_add());
       },
       "--max-scene-objects"},
      {[](v1::SceneMessage& m) { m.mutable_query()->set_max_pairs(11); }, "--max-scene-pairs"},
      {[](v1::SceneMessage& m) {
         wire::SceneIgnoredToProto({{0, 1}, {1, 2}, {2, 3}}, &m);
       },
       "--max-scene-ignored"},
      {[](v1::SceneMessage& m) {
         for (int i = 0; i < 200; ++i) {
           SceneObject extra;
           extra.id = 100 + i;
           wire::SceneObjectToProto(extra, "x", "", m.add_add());
         }
       },
       "--memory-budget"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.says);
    if (c.says == "--memory-budget") {
      configure_ = [](ServerOptions& options) {
        options.limits.max_scene_pairs = 1000;
        options.limits.memory_budget_bytes = 64 << 10;
      };
      Restart();
    }
    auto context = Context();
    std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
    v1::SceneMessage message = Create(objects, std::vector<std::string>(4, key), query);
    c.spoil(message);
    v1::SceneReply reply;
    EXPECT_FALSE(Send(*stream, message, &reply));
    const grpc::Status s = stream->Finish();
    EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << s.error_message();
    EXPECT_THAT(s.error_message(), HasSubstr(c.says));
  }
}

// A client that cancels, or goes away without finishing, frees its scene.
TEST_F(SceneStreamTest, CancelledOrVanishedClientFreesItsScene) {
  const std::string key = PutSet(testing::RandomSpheres(10, 1));
  std::vector<SceneObject> objects(3);
  for (std::size_t i = 0; i < objects.size(); ++i) objects[i].id = i;
  const v1::SceneMessage create = Create(objects, {key, key, key}, SceneQuery{});
  EXPECT_EQ(server_->open_scenes(), 0);
  {
    auto context = Context();
    std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
    v1::SceneReply reply;
    ASSERT_TRUE(Send(*stream, create, &reply));
    EXPECT_EQ(server_->open_scenes(), 1);
    context->TryCancel();
    EXPECT_TRUE(OpenScenesReach(0));
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::CANCELLED);
  }
  {
    // Its own channel, dropped with the stream open: the client is gone.
    auto channel = grpc::CreateChannel(server_->address(), grpc::InsecureChannelCredentials());
    auto stub = v1::Inscribe::NewStub(channel);
    auto context = Context();
    std::unique_ptr<Stream> stream = stub->SceneStream(context.get());
    v1::SceneReply reply;
    ASSERT_TRUE(Send(*stream, create, &reply));
    EXPECT_EQ(server_->open_scenes(), 1);
    stream.reset();
    context.reset();  // an unfinished call is cancelled
    stub.reset();
    channel.reset();
  }
  EXPECT_TRUE(OpenScenesReach(0));
}

// Draining ends an idle scene at once with UNAVAILABLE and frees it.
TEST_F(SceneStreamTest, ShutdownEndsIdleScenesPromptly) {
  const std::string key = PutSet(testing::RandomSpheres(10, 1));
  std::vector<SceneObject> objects(2);
  objects[1].id = 1;
  auto context = Context();
  std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
  v1::SceneReply reply;
  ASSERT_TRUE(Send(*stream, Create(objects, {key, key}, SceneQuery{}), &reply));
  EXPECT_EQ(server_->open_scenes(), 1);
  const auto start = std::chrono::steady_clock::now();
  server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(30));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_FALSE(stream->Read(&reply));
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(server_->open_scenes(), 0);
}

// Draining while a message is being answered: its reply is written first, then the stream ends
// with UNAVAILABLE and its scene is freed.
TEST_F(SceneStreamTest, ShutdownAnswersTheBusyMessageFirst) {
  constexpr int kObjects = 400;
  const std::string key = PutSet(testing::RandomSpheres(2'000, 2));
  std::mt19937_64 rng(3);
  std::vector<SceneObject> objects(kObjects);
  for (int i = 0; i < kObjects; ++i) {
    objects[i].id = i;
    objects[i].pose = testing::RandomPose(rng, 1.0);
  }
  // Every pair's distance: the message takes well over the 50 ms below.
  SceneQuery query;
  query.threshold = std::numeric_limits<double>::infinity();
  query.max_pairs = 100;
  const v1::SceneMessage create = Create(objects, std::vector<std::string>(kObjects, key), query);

  auto context = Context(120.0);
  std::unique_ptr<Stream> stream = stub_->SceneStream(context.get());
  const auto written = std::chrono::steady_clock::now();
  ASSERT_TRUE(stream->Write(create));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const double drained_after =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - written).count();
  server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(60));
  v1::SceneReply reply;
  ASSERT_TRUE(stream->Read(&reply)) << stream->Finish().error_message();
  ASSERT_GT(reply.seconds(), drained_after + 0.05) << "the message ended before the drain began";
  EXPECT_EQ(reply.objects(), kObjects);
  EXPECT_EQ(reply.close_pairs(), kObjects * (kObjects - 1) / 2);
  EXPECT_FALSE(stream->Read(&reply));
  EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_EQ(server_->open_scenes(), 0);
}

}  // namespace
}  // namespace inscribe::server
