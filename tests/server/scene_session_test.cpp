// SceneSession against a mock Connection and stream: the creating message (objects, keys,
// ignored pairs, query), frames numbered with their moved poses, replies that do not match,
// and the session staying broken (its call cancelled) after any error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client_test_support.h"

namespace inscribe::client {
namespace {

using ::testing::_;
using ::testing::HasSubstr;
using ::testing::Return;

// The reply to message `frame`: one pair (3, 5) at distance 0.25.
v1::SceneReply Reply(std::int64_t frame) {
  SceneFrame answer;
  ScenePair pair;
  pair.a = 3;
  pair.b = 5;
  pair.result.distance = 0.25;
  pair.result.point_b = Vector3(1, 2, 3);
  answer.pairs.push_back(pair);
  answer.candidate_pairs = 2;
  answer.close_pairs = 1;
  v1::SceneReply reply;
  wire::SceneFrameToProto(answer, &reply);
  reply.set_frame(frame);
  reply.set_objects(2);
  reply.set_seconds(0.001);
  return reply;
}

std::vector<SceneSessionObject> TwoObjects() {
  std::vector<SceneSessionObject> objects(2);
  objects[0].object.id = 3;
  objects[0].sphere_set_key = "spheres/v1/a";
  objects[1].object.id = 5;
  objects[1].object.group = 2;
  objects[1].object.pose.translation = Vector3(1, 0, 0);
  objects[1].sphere_set_key = "spheres/v1/b";
  objects[1].cover_key = "spheres/v1/c";
  return objects;
}

TEST(SceneSession, CreatesTheSceneThenNumbersFramesWithTheirPoses) {
  auto connection = std::make_shared<MockConnection>();
  auto owned = std::make_unique<MockSceneStream>();
  MockSceneStream& stream = *owned;
  std::vector<std::int64_t> frames;
  EXPECT_CALL(stream, RoundTrip(_, _))
      .Times(3)
      .WillRepeatedly([&](const v1::SceneMessage& message, Deadline) {
        frames.push_back(message.frame());
        if (message.frame() == 0) {
          EXPECT_EQ(message.volume(), v1::RSS);
          EXPECT_EQ(message.add_size(), 2);
          EXPECT_EQ(message.add(1).id(), 5u);
          EXPECT_EQ(message.add(1).sphere_set(), "spheres/v1/b");
          EXPECT_EQ(message.add(1).cover(), "spheres/v1/c");
          EXPECT_EQ(message.add(1).group(), 2u);
          EXPECT_FALSE(message.add(1).has_mask());
          EXPECT_EQ(message.add(1).pose().tx(), 1.0);
          EXPECT_EQ(message.ignore_size(), 2);
          EXPECT_EQ(message.query().threshold(), 0.5);
          EXPECT_EQ(message.query().max_pairs(), 7);
        } else {
          EXPECT_FALSE(message.has_query());
          EXPECT_EQ(message.add_size(), 0);
          EXPECT_EQ(message.pose_ids_size(), 1);
          EXPECT_EQ(message.pose_ids(0), 5u);
          EXPECT_EQ(message.poses().values(4), static_cast<double>(message.frame()));
        }
        return Reply(message.frame());
      });
  EXPECT_CALL(stream, Finish()).WillOnce(Return(absl::OkStatus()));
  EXPECT_CALL(stream, Destroyed());
  EXPECT_CALL(*connection, OpenSceneStream(Deadline::max()))
      .WillOnce(Return(::testing::ByMove(std::move(owned))));
  Client client(connection);
  SceneSessionOptions options;
  options.volume = HierarchyVolume::kRss;
  options.query.threshold = 0.5;
  options.query.max_pairs = 7;
  options.ignored = {{3, 5}};
  absl::StatusOr<SceneSession> session = client.OpenSceneSession(TwoObjects(), options);
  ASSERT_TRUE(session.ok()) << session.status();
  EXPECT_EQ(session->created().pairs.size(), 1u);
  for (int f = 1; f <= 2; ++f) {
    RigidPose pose;
    pose.translation = Vector3(f, 0, 0);
    absl::StatusOr<SceneFrameResult> result = session->Frame({{5, pose}});
    ASSERT_TRUE(result.ok()) << result.status();
    ASSERT_EQ(result->pairs.size(), 1u);
    EXPECT_EQ(result->pairs[0].a, 3u);
    EXPECT_EQ(result->pairs[0].result.point_b, Vector3(1, 2, 3));
    EXPECT_EQ(result->objects, 2);
    EXPECT_EQ(result->close_pairs, 1);
  }
  EXPECT_EQ(frames, (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_TRUE(session->Close().ok());
  EXPECT_EQ(session->Frame({}).status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST(SceneSession, AnErrorOrAMismatchedReplyEndsTheSession) {
  // The server refuses the scene: OpenSceneSession fails with its error.
  {
    auto connection = std::make_shared<MockConnection>();
    auto owned = std::make_unique<MockSceneStream>();
    EXPECT_CALL(*owned, RoundTrip(_, _))
        .WillOnce(Return(absl::NotFoundError("frame 0 add[1] (object 5).sphere_set: unknown")));
    EXPECT_CALL(*owned, Destroyed());
    EXPECT_CALL(*connection, OpenSceneStream(_))
        .WillOnce(Return(::testing::ByMove(std::move(owned))));
    absl::StatusOr<SceneSession> session = Client(connection).OpenSceneSession(TwoObjects());
    EXPECT_EQ(session.status().code(), absl::StatusCode::kNotFound);
    EXPECT_THAT(session.status().message(), HasSubstr("object 5"));
  }
  // A reply for another frame: INTERNAL, the call cancelled at once, and the error kept.
  auto owned = std::make_unique<MockSceneStream>();
  MockSceneStream& stream = *owned;
  EXPECT_CALL(stream, RoundTrip(_, _)).WillOnce(Return(Reply(0))).WillOnce(Return(Reply(7)));
  EXPECT_CALL(stream, Destroyed());
  SceneSession session(std::move(owned), SceneSessionOptions{});
  ASSERT_TRUE(session.Update(SceneChanges{}).ok());
  absl::StatusOr<SceneFrameResult> wrong = session.Frame({});
  EXPECT_EQ(wrong.status().code(), absl::StatusCode::kInternal);
  EXPECT_THAT(wrong.status().message(), HasSubstr("frame 1 was answered as frame 7"));
  EXPECT_EQ(session.Frame({}).status(), wrong.status());
  EXPECT_EQ(session.Close(), wrong.status());
}

}  // namespace
}  // namespace inscribe::client
