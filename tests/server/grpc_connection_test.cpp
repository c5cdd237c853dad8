// The gRPC Connection against a scripted in-process server: Generate's progress and result,
// DistanceStream round trips, a frame that is not answered in time (cancelled at its deadline),
// a stream dropped while open (cancelled, without hanging), several streams at once.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <thread>
#include <vector>

#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server.h"
#include "grpcpp/server_builder.h"
#include "inscribe/client/connection.h"
#include "inscribe/v1/service.grpc.pb.h"

namespace inscribe::client {
namespace {

using std::chrono::milliseconds;
using ::testing::ElementsAre;
using Clock = std::chrono::steady_clock;

Deadline In(milliseconds timeout) { return std::chrono::system_clock::now() + timeout; }

// Scripted by the request: Generate sends two progress messages, then a result unless the mesh
// key is "sha256:none" (ends OK without one) or "sha256:missing" (NOT_FOUND). DistanceStream
// answers each frame with one result per pair (distance = frame number), until a frame whose
// first pair names set "stall" (never answered: waits for the cancellation) or "missing"
// (ends the call NOT_FOUND).
class ScriptedInscribe final : public v1::Inscribe::Service {
 public:
  grpc::Status Generate(grpc::ServerContext* /*context*/, const v1::GenerateRequest* request,
                        grpc::ServerWriter<v1::GenerateResponse>* writer) override {
    for (double fraction : {0.25, 0.5}) {
      v1::GenerateResponse progress;
      progress.mutable_progress()->set_fraction(fraction);
      writer->Write(progress);
    }
    if (request->mesh_sha256() == "sha256:missing") {
      return grpc::Status(grpc::StatusCode::NOT_FOUND, "unknown mesh sha256:missing");
    }
    if (request->mesh_sha256() == "sha256:none") return grpc::Status::OK;
    v1::GenerateResponse result;
    result.mutable_result()->set_sphere_set_key("spheres/v1/made");
    writer->Write(result);
    return grpc::Status::OK;
  }

  grpc::Status DistanceStream(
      grpc::ServerContext* context,
      grpc::ServerReaderWriter<v1::DistanceFrameResult, v1::DistanceFrame>* stream) override {
    v1::DistanceFrame frame;
    while (stream->Read(&frame)) {
      const std::string first = frame.pairs_size() > 0 ? frame.pairs(0).sphere_set_a() : "";
      if (first == "stall") {
        while (!context->IsCancelled()) std::this_thread::sleep_for(milliseconds(1));
        ++cancelled_calls;
        return grpc::Status::CANCELLED;
      }
      if (first == "missing") return grpc::Status(grpc::StatusCode::NOT_FOUND, "unknown set");
      v1::DistanceFrameResult reply;
      reply.set_frame(frame.frame());
      for (int i = 0; i < frame.pairs_size(); ++i) {
        reply.mutable_results()->add_distances(static_cast<double>(frame.frame()));
      }
      if (!stream->Write(reply)) break;
    }
    // The client half-closed (clean end) or went away (cancelled).
    if (context->IsCancelled()) ++cancelled_calls;
    return grpc::Status::OK;
  }

  std::atomic<int> cancelled_calls{0};
};

class GrpcConnectionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.RegisterService(&service_);
    server_ = builder.BuildAndStart();
    ASSERT_NE(server_, nullptr);
    connection_ = MakeGrpcConnection("127.0.0.1:" + std::to_string(port));
  }
  void TearDown() override { server_->Shutdown(In(milliseconds(1000))); }

  // Waits up to 2 s for the server to see `n` cancelled streams.
  bool ServerSawCancellations(int n) {
    const auto until = Clock::now() + std::chrono::seconds(2);
    while (service_.cancelled_calls.load() < n && Clock::now() < until) {
      std::this_thread::sleep_for(milliseconds(1));
    }
    return service_.cancelled_calls.load() == n;
  }

  // Destroys `stream` on another thread: a destructor that hangs fails the test instead of
  // hanging it (TearDown's shutdown then cancels the call and releases it).
  bool DroppedWithin(std::unique_ptr<DistanceStreamConnection> stream, milliseconds limit) {
    drops_.push_back(std::async(std::launch::async,
                                [dropped = std::move(stream)]() mutable { dropped.reset(); }));
    return drops_.back().wait_for(limit) == std::future_status::ready;
  }

  static v1::DistanceFrame Frame(std::int64_t number, const std::string& set, int pairs = 1) {
    v1::DistanceFrame frame;
    frame.set_frame(number);
    for (int i = 0; i < pairs; ++i) frame.add_pairs()->set_sphere_set_a(set);
    return frame;
  }

  ScriptedInscribe service_;
  std::unique_ptr<grpc::Server> server_;
  std::shared_ptr<Connection> connection_;
  // Last, so destroyed first, after TearDown's shutdown has released any hung drop.
  std::vector<std::future<void>> drops_;
};

TEST_F(GrpcConnectionTest, GenerateForwardsProgressAndReturnsTheResult) {
  v1::GenerateRequest request;
  request.set_mesh_sha256("sha256:cube");
  std::vector<double> progress;
  absl::StatusOr<v1::GenerateResult> result = connection_->Generate(
      request, In(milliseconds(5000)), [&](double fraction) { progress.push_back(fraction); });
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->sphere_set_key(), "spheres/v1/made");
  EXPECT_THAT(progress, ElementsAre(0.25, 0.5));

  // No progress callback: allowed.
  EXPECT_TRUE(connection_->Generate(request, In(milliseconds(5000)), nullptr).ok());

  request.set_mesh_sha256("sha256:none");
  EXPECT_EQ(connection_->Generate(request, In(milliseconds(5000)), nullptr).status().code(),
            absl::StatusCode::kInternal);
  request.set_mesh_sha256("sha256:missing");
  EXPECT_EQ(connection_->Generate(request, In(milliseconds(5000)), nullptr).status(),
            absl::NotFoundError("unknown mesh sha256:missing"));
}

TEST_F(GrpcConnectionTest, DistanceStreamAnswersFramesInOrderAndFinishesCleanly) {
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(Deadline::max());
  ASSERT_TRUE(stream.ok()) << stream.status();
  for (int f = 0; f < 100; ++f) {
    absl::StatusOr<v1::DistanceFrameResult> reply =
        (*stream)->RoundTrip(Frame(f, "spheres/v1/a", 3), In(milliseconds(5000)));
    ASSERT_TRUE(reply.ok()) << reply.status();
    EXPECT_EQ(reply->frame(), f);
    ASSERT_EQ(reply->results().distances_size(), 3);
    EXPECT_EQ(reply->results().distances(2), f);
  }
  EXPECT_TRUE((*stream)->Finish().ok());
  EXPECT_EQ(service_.cancelled_calls.load(), 0);
}

TEST_F(GrpcConnectionTest, AFrameNotAnsweredInTimeIsDeadlineExceededAndCancelsTheCall) {
  // The session's own deadline only bounds the test should the frame's deadline not work.
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(In(milliseconds(5000)));
  ASSERT_TRUE(stream.ok());
  ASSERT_TRUE((*stream)->RoundTrip(Frame(0, "spheres/v1/a"), In(milliseconds(5000))).ok());

  const Clock::time_point start = Clock::now();
  absl::StatusOr<v1::DistanceFrameResult> late =
      (*stream)->RoundTrip(Frame(1, "stall"), In(milliseconds(200)));
  const double waited = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(late.status().code(), absl::StatusCode::kDeadlineExceeded) << late.status();
  EXPECT_GE(waited, 0.19);
  EXPECT_LT(waited, 1.5);
  EXPECT_TRUE(ServerSawCancellations(1));

  // The stream is over: the same error, at once, and a quick teardown.
  const Clock::time_point after = Clock::now();
  EXPECT_EQ((*stream)->RoundTrip(Frame(2, "spheres/v1/a"), In(milliseconds(5000))).status(),
            late.status());
  EXPECT_EQ((*stream)->Finish(), late.status());
  stream->reset();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - after).count(), 0.5);
}

TEST_F(GrpcConnectionTest, AnEarlierFrameDeadlineWakesTheWatchdog) {
  // The watchdog sleeps until the first frame's (far) deadline; the second frame's earlier one
  // must still fire on time. (The session's deadline only bounds the test.)
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(In(milliseconds(5000)));
  ASSERT_TRUE(stream.ok());
  ASSERT_TRUE((*stream)->RoundTrip(Frame(0, "spheres/v1/a"), In(milliseconds(60'000))).ok());
  const Clock::time_point start = Clock::now();
  EXPECT_EQ((*stream)->RoundTrip(Frame(1, "stall"), In(milliseconds(100))).status().code(),
            absl::StatusCode::kDeadlineExceeded);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 1.5);
}

TEST_F(GrpcConnectionTest, TheSessionDeadlineEndsAStalledFrame) {
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(In(milliseconds(200)));
  ASSERT_TRUE(stream.ok());
  const Clock::time_point start = Clock::now();
  EXPECT_EQ((*stream)->RoundTrip(Frame(0, "stall"), In(milliseconds(60'000))).status().code(),
            absl::StatusCode::kDeadlineExceeded);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 1.5);
}

TEST_F(GrpcConnectionTest, AServerErrorEndsTheStreamWithItsStatus) {
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(Deadline::max());
  ASSERT_TRUE(stream.ok());
  ASSERT_TRUE((*stream)->RoundTrip(Frame(0, "spheres/v1/a"), In(milliseconds(5000))).ok());
  const absl::Status error = absl::NotFoundError("unknown set");
  EXPECT_EQ((*stream)->RoundTrip(Frame(1, "missing"), In(milliseconds(5000))).status(), error);
  EXPECT_EQ((*stream)->RoundTrip(Frame(2, "spheres/v1/a"), In(milliseconds(5000))).status(), error);
  EXPECT_EQ((*stream)->Finish(), error);
}

TEST_F(GrpcConnectionTest, DroppingAnOpenStreamCancelsItWithoutHanging) {
  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
      connection_->OpenDistanceStream(Deadline::max());
  ASSERT_TRUE(stream.ok());
  ASSERT_TRUE((*stream)->RoundTrip(Frame(0, "spheres/v1/a"), In(milliseconds(5000))).ok());
  // The server is blocked reading the next frame.
  EXPECT_TRUE(DroppedWithin(*std::move(stream), milliseconds(500)));
  EXPECT_TRUE(ServerSawCancellations(1));

  // Never used at all: dropped just as quickly.
  stream = connection_->OpenDistanceStream(Deadline::max());
  ASSERT_TRUE(stream.ok());
  EXPECT_TRUE(DroppedWithin(*std::move(stream), milliseconds(500)));
}

// Streams are independent: one per thread, each with its own watchdog, over one channel.
TEST_F(GrpcConnectionTest, ConcurrentStreamsEachGetTheirOwnAnswers) {
  constexpr int kStreams = 6, kFrames = 200;
  std::vector<std::thread> threads;
  std::atomic<int> answered{0};
  for (int s = 0; s < kStreams; ++s) {
    threads.emplace_back([&, s] {
      absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> stream =
          connection_->OpenDistanceStream(Deadline::max());
      if (!stream.ok()) return;
      for (int f = 0; f < kFrames; ++f) {
        absl::StatusOr<v1::DistanceFrameResult> reply =
            (*stream)->RoundTrip(Frame(f, "spheres/v1/a", 1 + s), In(milliseconds(10'000)));
        if (reply.ok() && reply->frame() == f && reply->results().distances_size() == 1 + s) {
          ++answered;
        }
      }
      EXPECT_TRUE((*stream)->Finish().ok());
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(answered.load(), kStreams * kFrames);
  EXPECT_EQ(service_.cancelled_calls.load(), 0);
}

}  // namespace
}  // namespace inscribe::client
