// DistanceStream frames answered inline on the gRPC thread (server/src/frame_dispatch.h) keep
// every guarantee of frames answered on the pool: answers equal to brute force and in order,
// frames that are big, unknown or name new sets on the pool, --max-poses and --memory-budget
// applied, drain and cancellation in the middle of inline frames, no reservation left behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "inscribe/distance/separation_distance.h"
#include "spheres_rpc_fixture.h"
#include "support/sphere_sets.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

class StreamDispatchTest : public SpheresRpcTest {
 protected:
  void SetUp() override {
    observer_ = [this](const CallRecord& record) {
      if (std::string(record.method) != "DistanceStream") return;
      std::lock_guard<std::mutex> lock(mutex_);
      streams_.push_back(record);
    };
    SpheresRpcTest::SetUp();
  }

  // Stores `spheres` (no mesh); its key.
  std::string PutSpheres(const std::vector<Sphere>& spheres) {
    v1::PutSphereSetRequest request;
    SphereSet set;
    set.spheres = spheres;
    wire::SphereSetToProto(set, request.mutable_spheres());
    v1::PutSphereSetResponse response;
    const grpc::Status s = stub_->PutSphereSet(Context().get(), request, &response);
    EXPECT_TRUE(s.ok()) << s.error_message();
    return response.sphere_set_key();
  }

  // A frame numbered `number` of `pairs` pairs between the sets `keys` (pair p names keys[p %
  // size] and keys[(p + 1) % size]) at random poses; the poses in `poses`.
  v1::DistanceFrame Frame(std::int64_t number, int pairs, const std::vector<std::string>& keys,
                          std::mt19937_64& rng,
                          std::vector<std::pair<RigidPose, RigidPose>>* poses = nullptr) {
    v1::DistanceFrame frame;
    frame.set_frame(number);
    frame.set_volume(v1::SPHERE);
    for (int p = 0; p < pairs; ++p) {
      v1::DistancePair* pair = frame.add_pairs();
      pair->set_sphere_set_a(keys[p % keys.size()]);
      pair->set_sphere_set_b(keys[(p + 1) % keys.size()]);
      const RigidPose a = testing::RandomPose(rng, 3.0), b = testing::RandomPose(rng, 3.0);
      wire::PoseToProto(a, pair->mutable_pose_a());
      wire::PoseToProto(b, pair->mutable_pose_b());
      if (poses != nullptr) poses->emplace_back(a, b);
    }
    return frame;
  }

  // The records of the DistanceStreams that ended, once `n` have.
  std::vector<CallRecord> Streams(std::size_t n) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < deadline) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (streams_.size() >= n) return streams_;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ADD_FAILURE() << n << " streams never ended";
    std::lock_guard<std::mutex> lock(mutex_);
    return streams_;
  }

  std::mutex mutex_;
  std::vector<CallRecord> streams_;  // guarded by mutex_
};

TEST_F(StreamDispatchTest, SmallFramesAreAnsweredInlineInOrderLikeBruteForce) {
  const std::vector<Sphere> a = testing::RandomSpheres(60, 1), b = testing::RandomSpheres(40, 2);
  const std::vector<std::string> keys = {PutSpheres(a), PutSpheres(b)};
  const std::vector<Sphere>* spheres[] = {&a, &b};
  constexpr int kFrames = 200;
  std::mt19937_64 rng(3);
  auto context = Context();
  auto stream = stub_->DistanceStream(context.get());
  for (int f = 0; f < kFrames; ++f) {
    std::vector<std::pair<RigidPose, RigidPose>> poses;
    ASSERT_TRUE(stream->Write(Frame(500 + f, 3, keys, rng, &poses)));
    v1::DistanceFrameResult result;
    ASSERT_TRUE(stream->Read(&result));
    ASSERT_EQ(result.frame(), 500 + f);
    ASSERT_EQ(result.results().distances_size(), 3);
    for (int p = 0; p < 3; ++p) {
      absl::StatusOr<DistanceResult> brute = BruteForceSeparationDistance(
          *spheres[p % 2], poses[p].first, *spheres[(p + 1) % 2], poses[p].second);
      ASSERT_TRUE(brute.ok());
      EXPECT_NEAR(result.results().distances(p), brute->distance, 1e-9) << f << " " << p;
    }
  }
  stream->WritesDone();
  ASSERT_TRUE(stream->Finish().ok());
  const CallRecord record = Streams(1)[0];
  EXPECT_TRUE(record.status.ok()) << record.status;
  EXPECT_EQ(record.frames, kFrames);
  // The first frame's cost is unknown (and it looks the sets up): never inline. Most of the
  // others are, unless the machine is so loaded that the frames measure over the budget; under
  // a sanitizer they may all do (none did under TSan), so the count is checked at normal speed.
  EXPECT_LT(record.inline_frames, kFrames);
  if (!testing::kSanitizedBuild) {
    EXPECT_GT(record.inline_frames, kFrames / 2);
  }
}

// Frames over kSerialFramePairs pairs would run parallel loops, and frames naming a set the
// stream does not hold yet look it up in the cache: both stay on the pool.
TEST_F(StreamDispatchTest, BigFramesAndFramesNamingNewSetsGoToThePool) {
  const std::vector<std::string> keys = {PutSpheres(testing::RandomSpheres(20, 4))};
  std::mt19937_64 rng(5);
  // One stream of `frames` frames of `pairs` pairs naming the sets keys(f); each answered.
  const auto stream_frames = [&](int frames, int pairs,
                                 const std::function<std::vector<std::string>(int)>& keys_of) {
    auto context = Context();
    auto stream = stub_->DistanceStream(context.get());
    for (int f = 0; f < frames; ++f) {
      ASSERT_TRUE(stream->Write(Frame(f, pairs, keys_of(f), rng)));
      v1::DistanceFrameResult result;
      ASSERT_TRUE(stream->Read(&result));
      ASSERT_EQ(result.results().distances_size(), pairs);
    }
    stream->WritesDone();
    ASSERT_TRUE(stream->Finish().ok());
  };
  stream_frames(20, 65, [&](int) { return keys; });
  // A new set each frame (and the held one, whose cost the stream knows).
  stream_frames(10, 2, [&](int f) {
    return std::vector<std::string>{keys[0], PutSpheres(testing::RandomSpheres(20, 100 + f))};
  });
  const std::vector<CallRecord> records = Streams(2);
  EXPECT_EQ(records[0].frames, 20);
  EXPECT_EQ(records[0].inline_frames, 0);
  EXPECT_EQ(records[1].frames, 10);
  EXPECT_EQ(records[1].inline_frames, 0);
}

// --memory-budget holds exactly one frame of 3 pairs, and --max-poses is 4: after inline
// frames, a frame of 4 pairs does not fit the budget and one of 5 is over the limit.
TEST_F(StreamDispatchTest, LimitsApplyToInlineFrames) {
  // Stored (on disk) before the budget is too small for a PutSphereSet.
  const std::vector<std::string> keys = {PutSpheres(testing::RandomSpheres(30, 6))};
  configure_ = [](ServerOptions& options) {
    options.limits.memory_budget_bytes = 3 * 512;
    options.limits.max_poses = 4;
  };
  Restart();
  std::mt19937_64 rng(7);
  for (const int last : {4, 5}) {
    SCOPED_TRACE(last);
    auto context = Context();
    auto stream = stub_->DistanceStream(context.get());
    v1::DistanceFrameResult result;
    for (int f = 0; f < 20; ++f) {
      ASSERT_TRUE(stream->Write(Frame(f, 3, keys, rng)));
      ASSERT_TRUE(stream->Read(&result));
    }
    stream->Write(Frame(20, last, keys, rng));
    EXPECT_FALSE(stream->Read(&result));
    const grpc::Status s = stream->Finish();
    EXPECT_EQ(s.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << s.error_message();
    EXPECT_THAT(s.error_message(), HasSubstr(last == 4 ? "--memory-budget" : "--max-poses"));
  }
  const std::vector<CallRecord> records = Streams(2);
  // Some frames ran inline, so the limits were met there too; a sanitizer's build can be too
  // slow for any frame to fit the inline time budget (kInlineFrameSeconds).
  if (!testing::kSanitizedBuild) {
    EXPECT_GT(records[0].inline_frames + records[1].inline_frames, 0);
  }
}

// Clients streaming small frames as fast as they can while the server drains, or while they
// cancel: every answer read is the right one, in order; streams end UNAVAILABLE (drain) or
// CANCELLED / OK (cancel), and no frame's memory reservation is left behind (the budget holds
// one frame, and a new stream is still answered).
TEST_F(StreamDispatchTest, DrainAndCancelInTheMiddleOfInlineFrames) {
  const std::vector<std::string> keys = {PutSpheres(testing::RandomSpheres(30, 8)),
                                         PutSpheres(testing::RandomSpheres(30, 9))};
  configure_ = [](ServerOptions& options) { options.limits.memory_budget_bytes = 3 * 512; };
  Restart();
  // Streams 3-pair frames until `stop` (then half-closes) or a failure; `answered` counts.
  auto stream_until_stopped = [&](std::atomic<bool>& stop, std::uint64_t seed,
                                  grpc::ClientContext* context, std::atomic<int>* answered) {
    std::mt19937_64 rng(seed);
    auto stream = stub_->DistanceStream(context);
    v1::DistanceFrameResult result;
    for (int f = 0; !stop; ++f) {
      if (!stream->Write(Frame(f, 3, keys, rng)) || !stream->Read(&result)) break;
      EXPECT_EQ(result.frame(), f);
      EXPECT_EQ(result.results().distances_size(), 3);
      ++*answered;
    }
    if (stop) stream->WritesDone();
    return stream->Finish();
  };
  // Waits until `answered` passes `n` (the stream is past its first, pooled frames).
  auto wait_for = [](const std::atomic<int>& answered, int n) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (answered.load() < n && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  };

  // Cancel: the client goes away mid-stream, several times.
  for (int round = 0; round < 5; ++round) {
    std::atomic<bool> stop{false};
    auto context = Context();
    std::atomic<int> answered{0};
    std::thread client([&] { stream_until_stopped(stop, round, context.get(), &answered); });
    wait_for(answered, 5 + 20 * round);
    context->TryCancel();
    client.join();
    EXPECT_GT(answered.load(), 0);
    // The server sees the cancel after the client does; the next round starts once it has
    // ended this stream (and released its frame's reservation), as the budget holds one frame.
    Streams(static_cast<std::size_t>(round) + 1);
  }
  std::vector<CallRecord> records = Streams(5);
  std::int64_t inline_frames = 0;
  for (const CallRecord& record : records) {
    EXPECT_THAT(record.status.code(),
                ::testing::AnyOf(absl::StatusCode::kOk, absl::StatusCode::kCancelled))
        << record.status;
    inline_frames += record.inline_frames;
  }
  // Under a sanitizer the frames may all measure over the inline budget and run on the pool
  // (they did under TSan), which this test then exercises instead.
  if (!testing::kSanitizedBuild) {
    EXPECT_GT(inline_frames, 0);
  }

  // A new stream is answered: no cancelled frame kept its reservation.
  {
    std::atomic<bool> stop{false};
    auto context = Context();
    std::atomic<int> answered{0};
    std::thread client([&] {
      const grpc::Status s = stream_until_stopped(stop, 50, context.get(), &answered);
      EXPECT_TRUE(s.ok()) << s.error_message();
    });
    wait_for(answered, 20);
    stop = true;
    client.join();
    EXPECT_GT(answered.load(), 0);
  }

  // Drain while a stream is busy with inline frames: it ends UNAVAILABLE promptly.
  std::atomic<bool> stop{false};
  auto context = Context();
  std::atomic<int> answered{0};
  grpc::Status drained;
  std::thread client([&] { drained = stream_until_stopped(stop, 60, context.get(), &answered); });
  wait_for(answered, 50);
  const auto start = std::chrono::steady_clock::now();
  server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(30));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  client.join();
  EXPECT_GT(answered.load(), 0);
  EXPECT_EQ(drained.error_code(), grpc::StatusCode::UNAVAILABLE) << drained.error_message();
  records = Streams(7);
  EXPECT_EQ(records.back().status.code(), absl::StatusCode::kUnavailable) << records.back().status;
  if (!testing::kSanitizedBuild) {
    EXPECT_GT(records.back().inline_frames, 0);
  }
}

}  // namespace
}  // namespace inscribe::server
