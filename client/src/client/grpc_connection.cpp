// The gRPC implementation of Connection: a channel and the generated stub.
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "grpcpp/channel.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/channel_arguments.h"
#include "grpcpp/support/sync_stream.h"
#include "inscribe/client/connection.h"
#include "inscribe/server/convert.h"
#include "inscribe/v1/service.grpc.pb.h"

namespace inscribe::client {
namespace {

using Stub = v1::Inscribe::Stub;

// One attempt of a unary RPC through the generated (blocking) stub method `method`.
template <typename Request, typename Response>
absl::StatusOr<Response> CallUnary(Stub& stub,
                                   grpc::Status (Stub::*method)(grpc::ClientContext*,
                                                                const Request&, Response*),
                                   const Request& request, Deadline deadline) {
  grpc::ClientContext context;
  context.set_deadline(deadline);
  Response response;
  const grpc::Status status = (stub.*method)(&context, request, &response);
  if (!status.ok()) return server::FromGrpcStatus(status);
  return response;
}

// Cancels `context` when a frame's deadline passes. A blocking Read cannot time out on its
// own, so one helper thread per stream (started once, not per frame) sleeps until the armed
// deadline. Arming and disarming a frame costs a mutex round trip and no wake-up while the
// deadlines only move later (a simulator loop's now + frame_timeout): the thread is woken only
// when a new deadline is earlier than the one it sleeps until, so p99 round trips stay at the
// network's cost.
class StreamWatchdog {
 public:
  explicit StreamWatchdog(grpc::ClientContext* context)
      : context_(context), thread_([this] { Run(); }) {}

  ~StreamWatchdog() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }

  StreamWatchdog(const StreamWatchdog&) = delete;
  StreamWatchdog& operator=(const StreamWatchdog&) = delete;

  // The call is cancelled if Disarm is not reached by `deadline`.
  void Arm(Deadline deadline) {
    bool wake = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      armed_ = true;
      deadline_ = deadline;
      wake = deadline < sleeping_until_;
    }
    if (wake) wake_.notify_one();
  }

  // Whether the deadline passed (and the call was cancelled) while armed.
  bool Disarm() {
    std::lock_guard<std::mutex> lock(mutex_);
    armed_ = false;
    const bool fired = fired_;
    fired_ = false;
    return fired;
  }

 private:
  void Run() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!stop_) {
      if (!armed_) {
        sleeping_until_ = Deadline::max();
        wake_.wait(lock);
        continue;
      }
      if (std::chrono::system_clock::now() >= deadline_) {
        armed_ = false;
        fired_ = true;
        context_->TryCancel();  // thread-safe; makes the blocked Read return false
        continue;
      }
      sleeping_until_ = deadline_;
      wake_.wait_until(lock, deadline_);
    }
  }

  grpc::ClientContext* const context_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool armed_ = false;
  bool fired_ = false;
  Deadline deadline_;
  Deadline sleeping_until_ = Deadline::max();
  std::thread thread_;  // last: starts after the state above exists
};

class GrpcDistanceStream final : public DistanceStreamConnection {
 public:
  GrpcDistanceStream(Stub& stub, Deadline deadline) {
    if (deadline != Deadline::max()) context_.set_deadline(deadline);
    stream_ = stub.DistanceStream(&context_);
    watchdog_ = std::make_unique<StreamWatchdog>(&context_);
  }

  // Cancels an unfinished call, then collects its status so that nothing is left pending;
  // after TryCancel, Finish returns at once.
  ~GrpcDistanceStream() override {
    watchdog_.reset();
    if (!finished_) {
      context_.TryCancel();
      stream_->Finish().IgnoreError();
    }
  }

  absl::StatusOr<v1::DistanceFrameResult> RoundTrip(const v1::DistanceFrame& frame,
                                                    Deadline deadline) override {
    if (finished_) return ended_;
    // Armed across the error path too, so that Finish cannot outlive the frame's deadline.
    watchdog_->Arm(deadline);
    v1::DistanceFrameResult result;
    const bool answered = stream_->Write(frame) && stream_->Read(&result);
    absl::Status status;
    if (!answered) {
      status = server::FromGrpcStatus(stream_->Finish());
      finished_ = true;
      if (status.ok()) {
        status = absl::InternalError(
            absl::StrCat("DistanceStream ended without answering frame ", frame.frame()));
      }
    }
    if (watchdog_->Disarm()) {
      // The call is cancelled, even if the answer slipped in just before.
      if (!finished_) stream_->Finish().IgnoreError();
      finished_ = true;
      status = absl::DeadlineExceededError(
          absl::StrCat("no answer to DistanceStream frame ", frame.frame(), " in time"));
    }
    if (!status.ok()) {
      ended_ = status;
      return status;
    }
    return result;
  }

  absl::Status Finish() override {
    if (finished_) return ended_;
    finished_ = true;
    stream_->WritesDone();
    // Finish waits for every incoming message to be read; a conforming server sends none
    // after the last answer, but draining keeps a misbehaving one from hanging us.
    v1::DistanceFrameResult unexpected;
    int extra = 0;
    while (stream_->Read(&unexpected)) ++extra;
    ended_ = server::FromGrpcStatus(stream_->Finish());
    if (ended_.ok() && extra > 0) {
      ended_ =
          absl::InternalError(absl::StrCat("DistanceStream sent ", extra, " results for no frame"));
    }
    return ended_;
  }

 private:
  grpc::ClientContext context_;
  std::unique_ptr<grpc::ClientReaderWriter<v1::DistanceFrame, v1::DistanceFrameResult>> stream_;
  std::unique_ptr<StreamWatchdog> watchdog_;  // destroyed before context_
  bool finished_ = false;                     // stream_->Finish() has been called
  absl::Status ended_ = absl::FailedPreconditionError("DistanceStream already finished");
};

class GrpcConnection final : public Connection {
 public:
  explicit GrpcConnection(std::shared_ptr<grpc::Channel> channel)
      : stub_(v1::Inscribe::NewStub(std::move(channel))) {}

  absl::StatusOr<v1::InspectMeshResponse> InspectMesh(const v1::InspectMeshRequest& request,
                                                      Deadline deadline) override {
    return CallUnary(*stub_, &Stub::InspectMesh, request, deadline);
  }

  absl::StatusOr<v1::PutMeshResponse> PutMesh(const v1::PutMeshRequest& request,
                                              Deadline deadline) override {
    return CallUnary(*stub_, &Stub::PutMesh, request, deadline);
  }

  absl::StatusOr<v1::GenerateResult> Generate(
      const v1::GenerateRequest& request, Deadline deadline,
      const std::function<void(double fraction)>& on_progress) override {
    grpc::ClientContext context;
    context.set_deadline(deadline);
    std::unique_ptr<grpc::ClientReader<v1::GenerateResponse>> reader =
        stub_->Generate(&context, request);
    v1::GenerateResponse message;
    v1::GenerateResult result;
    bool has_result = false;
    while (reader->Read(&message)) {
      if (message.has_progress()) {
        if (on_progress) on_progress(message.progress().fraction());
      } else if (message.has_result()) {
        result = std::move(*message.mutable_result());
        has_result = true;
      }
    }
    const grpc::Status status = reader->Finish();
    if (!status.ok()) return server::FromGrpcStatus(status);
    if (!has_result) return absl::InternalError("Generate stream ended without a result");
    return result;
  }

  absl::StatusOr<v1::PutSphereSetResponse> PutSphereSet(const v1::PutSphereSetRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, &Stub::PutSphereSet, request, deadline);
  }

  absl::StatusOr<v1::GetSphereSetResponse> GetSphereSet(const v1::GetSphereSetRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, &Stub::GetSphereSet, request, deadline);
  }

  absl::StatusOr<v1::GetHierarchyResponse> GetHierarchy(const v1::GetHierarchyRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, &Stub::GetHierarchy, request, deadline);
  }

  absl::StatusOr<v1::UpdateDeformationResponse> UpdateDeformation(
      const v1::UpdateDeformationRequest& request, Deadline deadline) override {
    return CallUnary(*stub_, &Stub::UpdateDeformation, request, deadline);
  }

  absl::StatusOr<v1::DistanceResponse> Distance(const v1::DistanceRequest& request,
                                                Deadline deadline) override {
    return CallUnary(*stub_, &Stub::Distance, request, deadline);
  }

  absl::StatusOr<v1::EvaluateResponse> Evaluate(const v1::EvaluateRequest& request,
                                                Deadline deadline) override {
    return CallUnary(*stub_, &Stub::Evaluate, request, deadline);
  }

  absl::StatusOr<v1::CacheStatsResponse> CacheStats(const v1::CacheStatsRequest& request,
                                                    Deadline deadline) override {
    return CallUnary(*stub_, &Stub::CacheStats, request, deadline);
  }

  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> OpenDistanceStream(
      Deadline deadline) override {
    return std::make_unique<GrpcDistanceStream>(*stub_, deadline);
  }

 private:
  // Generated stubs are thread-safe; one serves every caller.
  const std::unique_ptr<v1::Inscribe::Stub> stub_;
};

}  // namespace

std::shared_ptr<Connection> MakeGrpcConnection(const std::string& target,
                                               const ConnectionOptions& options) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(options.max_message_bytes);
  arguments.SetMaxSendMessageSize(options.max_message_bytes);
  std::shared_ptr<grpc::ChannelCredentials> credentials =
      options.credentials ? options.credentials : grpc::InsecureChannelCredentials();
  return std::make_shared<GrpcConnection>(
      grpc::CreateCustomChannel(target, credentials, arguments));
}

}  // namespace inscribe::client
