// DistanceSession against a mock stream: frame numbering, the query on every frame, replies
// that do not match, and the session staying broken after any error. Client's
// OpenDistanceSession against a mock Connection.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client_test_support.h"

namespace inscribe::client {
namespace {

using std::chrono::milliseconds;
using ::testing::_;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Return;

// The answer to frame `frame` with `n` results.
v1::DistanceFrameResult Reply(std::int64_t frame, int n) {
  v1::DistanceFrameResult reply;
  reply.set_frame(frame);
  *reply.mutable_results() = Results(n);
  return reply;
}

// A session over `stream`, which the test keeps a pointer to.
DistanceSession SessionOver(std::unique_ptr<MockDistanceStream> stream,
                            const DistanceSessionOptions& options = {}) {
  return DistanceSession(std::move(stream), options);
}

PosePair Pair(const std::string& a, const std::string& b, double tx) {
  PosePair pair;
  pair.sphere_set_a = a;
  pair.sphere_set_b = b;
  pair.pose_b.translation = Vector3(tx, 0, 0);
  return pair;
}

TEST(DistanceSession, NumbersFramesAndSendsEveryPairWithTheQuery) {
  auto owned = std::make_unique<MockDistanceStream>();
  MockDistanceStream& stream = *owned;
  DistanceSessionOptions options;
  options.volume = HierarchyVolume::kRss;
  options.tolerance.rel_err = 0.01;
  options.tolerance.closer_than = 0.5;
  options.frame_timeout = milliseconds(40);
  std::vector<std::int64_t> frames;
  EXPECT_CALL(stream, RoundTrip(_, _))
      .Times(3)
      .WillRepeatedly([&](const v1::DistanceFrame& frame, Deadline deadline) {
        frames.push_back(frame.frame());
        EXPECT_EQ(frame.volume(), v1::RSS);
        EXPECT_EQ(frame.tolerance().rel_err(), 0.01);
        EXPECT_EQ(frame.tolerance().closer_than(), 0.5);
        EXPECT_LE(deadline, std::chrono::system_clock::now() + milliseconds(40));
        EXPECT_GE(deadline, std::chrono::system_clock::now() + milliseconds(20));
        EXPECT_EQ(frame.pairs_size(), 2);
        EXPECT_EQ(frame.pairs(1).sphere_set_a(), "spheres/v1/c");
        EXPECT_EQ(frame.pairs(1).pose_b().tx(), 2.0 + frame.frame());
        EXPECT_EQ(frame.pairs(1).pose_a().qw(), 1.0);
        return Reply(frame.frame(), frame.pairs_size());
      });
  EXPECT_CALL(stream, Finish()).WillOnce(Return(absl::OkStatus()));
  EXPECT_CALL(stream, Destroyed());
  DistanceSession session = SessionOver(std::move(owned), options);

  for (int f = 0; f < 3; ++f) {
    absl::StatusOr<std::vector<DistanceResult>> results =
        session.Query({Pair("spheres/v1/a", "spheres/v1/b", 1.0 + f),
                       Pair("spheres/v1/c", "spheres/v1/d", 2.0 + f)});
    ASSERT_TRUE(results.ok()) << results.status();
    ASSERT_EQ(results->size(), 2u);
    EXPECT_EQ((*results)[1].distance, 1.0);
    EXPECT_EQ((*results)[1].point_b, Vector3(1, 1, 0));
  }
  EXPECT_THAT(frames, ElementsAre(0, 1, 2));
  EXPECT_TRUE(session.Close().ok());
  // Closed: nothing more is sent.
  EXPECT_EQ(session.Query({}).status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST(DistanceSession, AReplyToAnotherFrameBreaksTheSession) {
  auto owned = std::make_unique<MockDistanceStream>();
  MockDistanceStream& stream = *owned;
  ::testing::Sequence order;
  EXPECT_CALL(stream, RoundTrip(_, _)).InSequence(order).WillOnce(Return(Reply(0, 1)));
  EXPECT_CALL(stream, RoundTrip(_, _)).InSequence(order).WillOnce(Return(Reply(0, 1)));
  // The call is let go at once, not when the session is.
  EXPECT_CALL(stream, Destroyed()).InSequence(order);
  EXPECT_CALL(stream, Finish()).Times(0);
  DistanceSession session = SessionOver(std::move(owned));

  ASSERT_TRUE(session.Query({Pair("a", "b", 1)}).ok());
  const absl::Status mismatch = session.Query({Pair("a", "b", 1)}).status();
  EXPECT_EQ(mismatch.code(), absl::StatusCode::kInternal);
  EXPECT_THAT(mismatch.message(), HasSubstr("frame 1 was answered as frame 0"));
  EXPECT_EQ(session.Query({Pair("a", "b", 1)}).status(), mismatch);
  EXPECT_EQ(session.Close(), mismatch);
}

TEST(DistanceSession, TheWrongNumberOfResultsBreaksTheSession) {
  for (const v1::DistanceFrameResult& reply : {Reply(0, 1), Reply(0, 3)}) {
    auto owned = std::make_unique<MockDistanceStream>();
    EXPECT_CALL(*owned, RoundTrip(_, _)).WillOnce(Return(reply));
    EXPECT_CALL(*owned, Destroyed());
    DistanceSession session = SessionOver(std::move(owned));
    const absl::Status status = session.Query({Pair("a", "b", 1), Pair("a", "b", 2)}).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInternal);
    EXPECT_THAT(status.message(), HasSubstr("for 2 pairs"));
    EXPECT_EQ(session.Query({Pair("a", "b", 1), Pair("a", "b", 2)}).status(), status);
  }
  // Arrays of different lengths within the results.
  v1::DistanceFrameResult ragged = Reply(0, 2);
  ragged.mutable_results()->mutable_spheres_b()->RemoveLast();
  auto owned = std::make_unique<MockDistanceStream>();
  EXPECT_CALL(*owned, RoundTrip(_, _)).WillOnce(Return(ragged));
  EXPECT_CALL(*owned, Destroyed());
  DistanceSession session = SessionOver(std::move(owned));
  const absl::Status status = session.Query({Pair("a", "b", 1), Pair("a", "b", 2)}).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInternal);
  EXPECT_THAT(status.message(), HasSubstr("spheres_b"));
}

TEST(DistanceSession, AServerErrorEndsTheSessionWithThatError) {
  auto owned = std::make_unique<MockDistanceStream>();
  MockDistanceStream& stream = *owned;
  const absl::Status unknown = absl::NotFoundError("unknown sphere set spheres/v1/x");
  EXPECT_CALL(stream, RoundTrip(_, _)).WillOnce(Return(Reply(0, 1))).WillOnce(Return(unknown));
  EXPECT_CALL(stream, Finish()).Times(0);
  EXPECT_CALL(stream, Destroyed());
  DistanceSession session = SessionOver(std::move(owned));
  ASSERT_TRUE(session.Query({Pair("a", "b", 1)}).ok());
  EXPECT_EQ(session.Query({Pair("a", "spheres/v1/x", 1)}).status(), unknown);
  // Later frames are not sent (RoundTrip is expected twice only).
  EXPECT_EQ(session.Query({Pair("a", "b", 1)}).status(), unknown);
  EXPECT_EQ(session.Close(), unknown);
}

TEST(DistanceSession, DestroyingAnOpenSessionLetsGoOfTheCallWithoutFinishing) {
  auto owned = std::make_unique<MockDistanceStream>();
  MockDistanceStream& stream = *owned;
  EXPECT_CALL(stream, RoundTrip(_, _)).WillOnce(Return(Reply(0, 1)));
  EXPECT_CALL(stream, Finish()).Times(0);
  ::testing::MockFunction<void()> scope_ends;
  {
    ::testing::InSequence order;
    EXPECT_CALL(stream, Destroyed());
    EXPECT_CALL(scope_ends, Call());
  }
  {
    DistanceSession session = SessionOver(std::move(owned));
    ASSERT_TRUE(session.Query({Pair("a", "b", 1)}).ok());
  }
  scope_ends.Call();
}

TEST(DistanceSession, AMovedSessionKeepsNumbering) {
  auto owned = std::make_unique<MockDistanceStream>();
  std::vector<std::int64_t> frames;
  EXPECT_CALL(*owned, RoundTrip(_, _))
      .Times(3)
      .WillRepeatedly([&](const v1::DistanceFrame& frame, Deadline) {
        frames.push_back(frame.frame());
        return Reply(frame.frame(), 1);
      });
  EXPECT_CALL(*owned, Destroyed());
  DistanceSession first = SessionOver(std::move(owned));
  ASSERT_TRUE(first.Query({Pair("a", "b", 1)}).ok());
  DistanceSession second(std::move(first));
  ASSERT_TRUE(second.Query({Pair("a", "b", 1)}).ok());
  auto replaced = std::make_unique<MockDistanceStream>();
  EXPECT_CALL(*replaced, Destroyed());
  DistanceSession third = SessionOver(std::move(replaced));
  third = std::move(second);  // lets go of the replaced stream
  ASSERT_TRUE(third.Query({Pair("a", "b", 1)}).ok());
  EXPECT_THAT(frames, ElementsAre(0, 1, 2));
}

TEST(Client, OpenDistanceSessionPassesTheSessionDeadlineAndIsNotRetried) {
  auto connection = std::make_shared<MockConnection>();
  const Deadline earliest = std::chrono::system_clock::now() + milliseconds(500);
  EXPECT_CALL(*connection, OpenDistanceStream(Deadline::max()))
      .WillOnce([](Deadline) -> absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> {
        auto stream = std::make_unique<MockDistanceStream>();
        EXPECT_CALL(*stream, Destroyed());
        return stream;
      });
  EXPECT_CALL(*connection,
              OpenDistanceStream(::testing::AllOf(::testing::Ge(earliest),
                                                  ::testing::Le(earliest + milliseconds(500)))))
      .WillOnce(Return(absl::UnavailableError("no channel")));
  Client client(connection, FastRetries());

  EXPECT_TRUE(client.OpenDistanceSession().ok());
  DistanceSessionOptions bounded;
  bounded.session_timeout = milliseconds(500);
  EXPECT_EQ(client.OpenDistanceSession(bounded).status().code(), absl::StatusCode::kUnavailable);
}

}  // namespace
}  // namespace inscribe::client
