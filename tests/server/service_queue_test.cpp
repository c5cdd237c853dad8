// The service's admission and cancellation rules, with a pool the test can hold busy.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/security/server_credentials.h"
#include "grpcpp/server.h"
#include "grpcpp/server_builder.h"
#include "inscribe/server/inscribe_service.h"
#include "inscribe/server/job_pool.h"
#include "inscribe/wire/convert.h"
#include "support/synthetic_meshes.h"

namespace inscribe::server {
namespace {

using ::testing::HasSubstr;

// One pool thread and room for two jobs; the test occupies the thread with a job it releases.
// No small-job lane (job_pool_test covers it): the small calls here would run on it.
class ServiceQueueTest : public ::testing::Test {
 protected:
  void SetUp() override {
    JobPoolOptions options{/*concurrency=*/1, /*max_jobs=*/2};
    options.small_job_threads = 0;  // one queue, so the held thread holds up every call
    pool_ = std::make_unique<JobPool>(options);
    cache_ = *ResultCache::Open(ResultCacheOptions{});
    service_ = std::make_unique<InscribeService>(pool_.get(), cache_.get(), ServiceLimits{},
                                                 [this](const CallRecord& record) {
                                                   std::lock_guard<std::mutex> lock(records_mutex_);
                                                   records_.push_back(record);
                                                 });
    grpc::ServerBuilder builder;
    int port = 0;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
    builder.RegisterService(service_.get());
    server_ = builder.BuildAndStart();
    ASSERT_NE(server_, nullptr);
    stub_ = v1::Inscribe::NewStub(grpc::CreateChannel("127.0.0.1:" + std::to_string(port),
                                                      grpc::InsecureChannelCredentials()));
    // TBB runs enqueued jobs in no guaranteed order: wait until the holding job really occupies
    // the pool thread, or a later job could run first.
    auto started = std::make_shared<std::promise<void>>();
    std::future<void> holding = started->get_future();
    ASSERT_TRUE(pool_->TrySubmit([gate = release_.get_future().share(), started] {
      started->set_value();
      gate.wait();
    }));
    holding.wait();
  }

  void TearDown() override {
    ReleasePool();
    server_->Shutdown();
    pool_->WaitIdle();
  }

  void ReleasePool() {
    if (!released_) release_.set_value();
    released_ = true;
  }

  grpc::Status Inspect(std::chrono::milliseconds timeout) {
    v1::InspectMeshRequest request;
    wire::MeshToProto(testing::UnitCube(), request.mutable_mesh());
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + timeout);
    v1::InspectMeshResponse response;
    return stub_->InspectMesh(&context, request, &response);
  }

  void WaitForJobsInFlight(std::int64_t n) {
    for (int i = 0; i < 1000 && pool_->jobs_in_flight() != n; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_EQ(pool_->jobs_in_flight(), n);
  }

  std::vector<CallRecord> Records() {
    std::lock_guard<std::mutex> lock(records_mutex_);
    return records_;
  }

  std::promise<void> release_;
  bool released_ = false;
  std::unique_ptr<JobPool> pool_;
  std::unique_ptr<ResultCache> cache_;
  std::unique_ptr<InscribeService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<v1::Inscribe::Stub> stub_;
  std::mutex records_mutex_;
  std::vector<CallRecord> records_;
};

TEST_F(ServiceQueueTest, FullQueueIsResourceExhaustedNamingTheFlag) {
  // Fills the second place; this call waits for the pool.
  auto queued =
      std::async(std::launch::async, [this] { return Inspect(std::chrono::seconds(30)); });
  WaitForJobsInFlight(2);

  const grpc::Status refused = Inspect(std::chrono::seconds(30));
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("--max-queue"));
  EXPECT_THAT(refused.error_message(), HasSubstr("is 2"));

  ReleasePool();
  const grpc::Status served = queued.get();
  EXPECT_TRUE(served.ok()) << served.error_message();
}

TEST_F(ServiceQueueTest, CallCancelledWhileQueuedIsNeverRun) {
  const grpc::Status status = Inspect(std::chrono::milliseconds(200));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The job is still queued behind the held one; once released it must see that its caller
  // is gone (the server's copy of the deadline may end a little after the client's).
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ReleasePool();
  pool_->WaitIdle();
  const std::vector<CallRecord> records = Records();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_THAT(records[0].status.code(),
              ::testing::AnyOf(absl::StatusCode::kCancelled, absl::StatusCode::kDeadlineExceeded));
  EXPECT_EQ(records[0].run_seconds, 0.0);
  EXPECT_GE(records[0].queued_seconds, 0.15);
}

TEST_F(ServiceQueueTest, DrainingRefusesNewCallsAndWaitsForAcceptedOnes) {
  auto accepted =
      std::async(std::launch::async, [this] { return Inspect(std::chrono::seconds(30)); });
  WaitForJobsInFlight(2);
  service_->StartDraining();

  const grpc::Status refused = Inspect(std::chrono::seconds(30));
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_THAT(refused.error_message(), HasSubstr("shutting down"));
  // The accepted call is still waiting for the held pool thread.
  EXPECT_FALSE(
      service_->WaitForCalls(std::chrono::system_clock::now() + std::chrono::milliseconds(50)));

  ReleasePool();
  EXPECT_TRUE(service_->WaitForCalls(std::chrono::system_clock::now() + std::chrono::seconds(30)));
  const grpc::Status served = accepted.get();
  EXPECT_TRUE(served.ok()) << served.error_message();
}

TEST_F(ServiceQueueTest, ObserverSeesEveryFinishedCall) {
  ReleasePool();
  ASSERT_TRUE(Inspect(std::chrono::seconds(30)).ok());
  pool_->WaitIdle();
  const std::vector<CallRecord> records = Records();
  ASSERT_EQ(records.size(), 1u);
  EXPECT_STREQ(records[0].method, "InspectMesh");
  EXPECT_TRUE(records[0].status.ok());
  EXPECT_EQ(records[0].triangles, 12);
  EXPECT_THAT(records[0].peer, HasSubstr("127.0.0.1"));
}

}  // namespace
}  // namespace inscribe::server
