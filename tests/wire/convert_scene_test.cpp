// Scene conversions: objects, moved poses, ignored pairs, queries (defaults left off the wire,
// the server's max_pairs limit) and frames, both ways.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "inscribe/wire/convert.h"

namespace inscribe::wire {
namespace {

using ::testing::HasSubstr;

TEST(SceneConvert, ObjectsKeepIdPoseGroupAndMaskAndLeaveDefaultsUnset) {
  SceneObject object;
  object.id = 1ull << 40;
  object.pose.translation = Vector3(1, -2, 3);
  object.mask = 6;
  v1::SceneObject w;
  SceneObjectToProto(object, "spheres/v1/a", "spheres/v1/c", &w);
  EXPECT_FALSE(w.has_group());
  EXPECT_EQ(w.mask(), 6u);
  EXPECT_EQ(w.cover(), "spheres/v1/c");
  absl::StatusOr<SceneObject> back = SceneObjectFromProto(w, "add[0]");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->id, object.id);
  EXPECT_EQ(back->group, SceneObject{}.group);
  EXPECT_EQ(back->mask, 6u);
  EXPECT_EQ(back->pose.translation, object.pose.translation);
  EXPECT_EQ(back->spheres, nullptr);

  w.mutable_pose()->set_qw(0.0);
  EXPECT_THAT(SceneObjectFromProto(w, "add[0]").status().message(),
              HasSubstr("add[0] (object 1099511627776).pose"));
  w.clear_sphere_set();
  EXPECT_THAT(SceneObjectFromProto(w, "add[0]").status().message(), HasSubstr("sphere_set"));
}

TEST(SceneConvert, PosesAndIgnoredPairsRoundTrip) {
  RigidPose pose;
  pose.translation = Vector3(4, 5, 6);
  v1::SceneMessage m;
  ScenePosesToProto({{7, pose}, {9, RigidPose{}}}, &m);
  SceneIgnoredToProto({{1, 2}, {3, 4}}, &m);
  absl::StatusOr<std::vector<std::pair<SceneObjectId, RigidPose>>> poses = ScenePosesFromProto(m);
  ASSERT_TRUE(poses.ok()) << poses.status();
  ASSERT_EQ(poses->size(), 2u);
  EXPECT_EQ((*poses)[0].first, 7u);
  EXPECT_EQ((*poses)[0].second.translation, pose.translation);
  absl::StatusOr<std::vector<std::pair<SceneObjectId, SceneObjectId>>> ignored =
      SceneIgnoredFromProto(m);
  ASSERT_TRUE(ignored.ok());
  EXPECT_EQ(*ignored, (std::vector<std::pair<SceneObjectId, SceneObjectId>>{{1, 2}, {3, 4}}));

  m.add_pose_ids(11);
  EXPECT_THAT(ScenePosesFromProto(m).status().message(), HasSubstr("3 ids for 2 poses"));
  m.add_ignore(5);
  EXPECT_EQ(SceneIgnoredFromProto(m).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(SceneConvert, QueryDefaultsAndTheServersPairLimit) {
  SceneQuery query;
  query.threshold = -0.5;
  query.rel_err = 0.01;
  query.stop_at_first = true;
  v1::SceneQuery w;
  SceneQueryToProto(query, &w);
  EXPECT_FALSE(w.has_max_pairs());
  absl::StatusOr<SceneQuery> back = SceneQueryFromProto(w, 1'000'000, "--max-scene-pairs");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->threshold, -0.5);
  EXPECT_EQ(back->rel_err, 0.01);
  EXPECT_TRUE(back->stop_at_first);
  EXPECT_EQ(back->max_pairs, SceneQuery{}.max_pairs);
  // Unset: core's default capped by the limit; set above it: refused naming the flag.
  EXPECT_EQ(SceneQueryFromProto(w, 50, "--max-scene-pairs")->max_pairs, 50u);
  w.set_max_pairs(51);
  EXPECT_EQ(SceneQueryFromProto(w, 50, "--max-scene-pairs").status().code(),
            absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(SceneQueryFromProto(w, 50, "--max-scene-pairs").status().message(),
              HasSubstr("--max-scene-pairs"));
  w.set_max_pairs(0);
  EXPECT_EQ(SceneQueryFromProto(w, 50, "--max-scene-pairs").status().code(),
            absl::StatusCode::kInvalidArgument);
  w.clear_max_pairs();
  w.set_threshold(std::numeric_limits<double>::quiet_NaN());
  EXPECT_THAT(SceneQueryFromProto(w, 50, "--max-scene-pairs").status().message(),
              HasSubstr("query: "));
}

TEST(SceneConvert, FramesRoundTripAndMismatchedArraysAreRefused) {
  SceneFrame frame;
  ScenePair plain, certified;
  plain.a = 1;
  plain.b = 2;
  plain.result.distance = -0.125;
  plain.result.sphere_a = 4;
  plain.result.sphere_b = 9;
  plain.result.point_a = Vector3(1, 2, 3);
  plain.result.point_b = Vector3(4, 5, 6);
  certified.a = 2;
  certified.b = 3;
  certified.certified = true;
  certified.lower = 0.5;
  certified.upper = 0.75;
  frame.pairs = {plain, certified};
  frame.candidate_pairs = 5;
  frame.close_pairs = 3;
  frame.truncated = true;
  v1::SceneReply reply;
  SceneFrameToProto(frame, &reply);
  absl::StatusOr<SceneFrame> back = SceneFrameFromProto(reply);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->pairs.size(), 2u);
  EXPECT_EQ(back->pairs[0].result.distance, -0.125);
  EXPECT_EQ(back->pairs[0].result.sphere_b, 9);
  EXPECT_EQ(back->pairs[0].result.point_b, Vector3(4, 5, 6));
  EXPECT_FALSE(back->pairs[0].certified);
  EXPECT_EQ(back->pairs[0].upper, std::numeric_limits<double>::infinity());
  EXPECT_TRUE(back->pairs[1].certified);
  EXPECT_EQ(back->pairs[1].upper, 0.75);
  EXPECT_EQ(back->candidate_pairs, 5);
  EXPECT_EQ(back->close_pairs, 3);
  EXPECT_TRUE(back->truncated);

  reply.mutable_pairs()->add_lower(0.0);
  EXPECT_EQ(SceneFrameFromProto(reply).status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace inscribe::wire
