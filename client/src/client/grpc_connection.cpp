// The gRPC implementation of Connection: a channel and the generated stub.
#include <chrono>
#include <condition_variable>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <utility>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "grpcpp/channel.h"
#include "grpcpp/client_context.h"
#include "grpcpp/create_channel.h"
#include "grpcpp/security/credentials.h"
#include "grpcpp/support/channel_arguments.h"
#include "grpcpp/support/sync_stream.h"
#include "inscribe/client/connection.h"
#include "inscribe/v1/service.grpc.pb.h"
#include "inscribe/wire/convert.h"
#include "inscribe/wire/service_address.h"

namespace inscribe::client {
namespace {

using Stub = v1::Inscribe::Stub;

// Sets what every call carries: its deadline and, when configured, the bearer token.
void PrepareContext(grpc::ClientContext& context, const std::string& token, Deadline deadline) {
  if (deadline != Deadline::max()) context.set_deadline(deadline);
  if (!token.empty()) context.AddMetadata("authorization", absl::StrCat("Bearer ", token));
}

// One attempt of a unary RPC through the generated (blocking) stub method `method`.
template <typename Request, typename Response>
absl::StatusOr<Response> CallUnary(Stub& stub, const std::string& token,
                                   grpc::Status (Stub::*method)(grpc::ClientContext*,
                                                                const Request&, Response*),
                                   const Request& request, Deadline deadline) {
  grpc::ClientContext context;
  PrepareContext(context, token, deadline);
  Response response;
  const grpc::Status status = (stub.*method)(&context, request, &response);
  if (!status.ok()) return wire::FromGrpcStatus(status);
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

// One open DistanceStream or SceneStream call (`rpc` names it in errors).
template <typename Message, typename Reply>
class GrpcFrameStream final : public FrameStream<Message, Reply> {
 public:
  using Opener =
      std::unique_ptr<grpc::ClientReaderWriter<Message, Reply>> (Stub::*)(grpc::ClientContext*);

  GrpcFrameStream(Stub& stub, Opener open, const char* rpc, const std::string& token,
                  Deadline deadline)
      : rpc_(rpc) {
    PrepareContext(context_, token, deadline);
    stream_ = (stub.*open)(&context_);
    watchdog_ = std::make_unique<StreamWatchdog>(&context_);
  }

  // Cancels an unfinished call, then collects its status so that nothing is left pending;
  // after TryCancel, Finish returns at once.
  ~GrpcFrameStream() override {
    watchdog_.reset();
    if (!finished_) {
      context_.TryCancel();
      stream_->Finish().IgnoreError();
    }
  }

  absl::StatusOr<Reply> RoundTrip(const Message& frame, Deadline deadline) override {
    if (finished_) return ended_;
    // Armed across the error path too, so that Finish cannot outlive the frame's deadline.
    watchdog_->Arm(deadline);
    Reply result;
    const bool answered = stream_->Write(frame) && stream_->Read(&result);
    absl::Status status;
    if (!answered) {
      status = wire::FromGrpcStatus(stream_->Finish());
      finished_ = true;
      if (status.ok()) {
        status = absl::InternalError(
            absl::StrCat(rpc_, " ended without answering frame ", frame.frame()));
      }
    }
    if (watchdog_->Disarm()) {
      // The call is cancelled, even if the answer slipped in just before.
      if (!finished_) stream_->Finish().IgnoreError();
      finished_ = true;
      status = absl::DeadlineExceededError(
          absl::StrCat("no answer to ", rpc_, " frame ", frame.frame(), " in time"));
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
    Reply unexpected;
    int extra = 0;
    while (stream_->Read(&unexpected)) ++extra;
    ended_ = wire::FromGrpcStatus(stream_->Finish());
    if (ended_.ok() && extra > 0) {
      ended_ = absl::InternalError(absl::StrCat(rpc_, " sent ", extra, " results for no frame"));
    }
    return ended_;
  }

 private:
  const char* const rpc_;
  grpc::ClientContext context_;
  std::unique_ptr<grpc::ClientReaderWriter<Message, Reply>> stream_;
  std::unique_ptr<StreamWatchdog> watchdog_;  // destroyed before context_
  bool finished_ = false;                     // stream_->Finish() has been called
  absl::Status ended_ = absl::FailedPreconditionError(absl::StrCat(rpc_, " already finished"));
};

class GrpcConnection final : public Connection {
 public:
  GrpcConnection(std::shared_ptr<grpc::Channel> channel, std::string token)
      : stub_(v1::Inscribe::NewStub(std::move(channel))), token_(std::move(token)) {}

  absl::StatusOr<v1::InspectMeshResponse> InspectMesh(const v1::InspectMeshRequest& request,
                                                      Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::InspectMesh, request, deadline);
  }

  absl::StatusOr<v1::PutMeshResponse> PutMesh(const v1::PutMeshRequest& request,
                                              Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::PutMesh, request, deadline);
  }

  absl::StatusOr<v1::GenerateResult> Generate(
      const v1::GenerateRequest& request, Deadline deadline,
      const std::function<void(double fraction)>& on_progress) override {
    grpc::ClientContext context;
    PrepareContext(context, token_, deadline);
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
    if (!status.ok()) return wire::FromGrpcStatus(status);
    if (!has_result) return absl::InternalError("Generate stream ended without a result");
    return result;
  }

  absl::StatusOr<v1::PutSphereSetResponse> PutSphereSet(const v1::PutSphereSetRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::PutSphereSet, request, deadline);
  }

  absl::StatusOr<v1::GetSphereSetResponse> GetSphereSet(const v1::GetSphereSetRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::GetSphereSet, request, deadline);
  }

  absl::StatusOr<v1::GetHierarchyResponse> GetHierarchy(const v1::GetHierarchyRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::GetHierarchy, request, deadline);
  }

  absl::StatusOr<v1::UpdateDeformationResponse> UpdateDeformation(
      const v1::UpdateDeformationRequest& request, Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::UpdateDeformation, request, deadline);
  }

  absl::StatusOr<v1::DistanceResponse> Distance(const v1::DistanceRequest& request,
                                                Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::Distance, request, deadline);
  }

  absl::StatusOr<v1::EvaluateResponse> Evaluate(const v1::EvaluateRequest& request,
                                                Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::Evaluate, request, deadline);
  }

  absl::StatusOr<v1::CertifyCoverResponse> CertifyCover(const v1::CertifyCoverRequest& request,
                                                        Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::CertifyCover, request, deadline);
  }

  absl::StatusOr<v1::CacheStatsResponse> CacheStats(const v1::CacheStatsRequest& request,
                                                    Deadline deadline) override {
    return CallUnary(*stub_, token_, &Stub::CacheStats, request, deadline);
  }

  absl::StatusOr<std::unique_ptr<DistanceStreamConnection>> OpenDistanceStream(
      Deadline deadline) override {
    return std::make_unique<GrpcFrameStream<v1::DistanceFrame, v1::DistanceFrameResult>>(
        *stub_, &Stub::DistanceStream, "DistanceStream", token_, deadline);
  }

  absl::StatusOr<std::unique_ptr<SceneStreamConnection>> OpenSceneStream(
      Deadline deadline) override {
    return std::make_unique<GrpcFrameStream<v1::SceneMessage, v1::SceneReply>>(
        *stub_, &Stub::SceneStream, "SceneStream", token_, deadline);
  }

 private:
  // Generated stubs are thread-safe; one serves every caller.
  const std::unique_ptr<v1::Inscribe::Stub> stub_;
  const std::string token_;  // empty: no authorization header
};

// The whole of a small text file, or INVALID_ARGUMENT naming it.
absl::StatusOr<std::string> ReadSmallFile(const std::string& path, absl::string_view what) {
  std::ifstream in(path, std::ios::binary);
  std::string text;
  if (in) {
    std::ostringstream buffer;
    buffer << in.rdbuf();
    text = buffer.str();
  }
  if (!in && !in.eof()) {
    return absl::InvalidArgumentError(absl::StrCat("cannot read ", what, " ", path));
  }
  if (text.size() > (std::size_t{1} << 20)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " ", path, " is ", text.size(), " bytes; at most 1 MiB"));
  }
  return text;
}

// A PEM file's text, or INVALID_ARGUMENT when it cannot be read or holds no PEM block labelled
// `label` ("CERTIFICATE", "PRIVATE KEY"). gRPC parses the PEM itself, but only in the first
// handshake, where a mix-up (a certificate given as the key, a key as the CA) would surface as
// an UNAVAILABLE that the client retries until its deadline; checking the label up front names
// the file instead.
absl::StatusOr<std::string> ReadPem(const std::string& path, absl::string_view what,
                                    absl::string_view label) {
  absl::StatusOr<std::string> text = ReadSmallFile(path, what);
  if (!text.ok()) return text.status();
  // The label may have a prefix ("RSA PRIVATE KEY", "EC PRIVATE KEY").
  if (!absl::StrContains(*text, "-----BEGIN ") ||
      !absl::StrContains(*text, absl::StrCat(label, "-----"))) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " ", path, " is not a PEM file holding a ", label));
  }
  if (absl::StrContains(*text, "-----BEGIN ENCRYPTED PRIVATE KEY-----")) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " ", path, " is encrypted; gRPC needs an unencrypted key"));
  }
  return text;
}

}  // namespace

std::shared_ptr<Connection> MakeGrpcConnection(const std::string& target,
                                               const ConnectionOptions& options) {
  grpc::ChannelArguments arguments;
  arguments.SetMaxReceiveMessageSize(options.max_message_bytes);
  arguments.SetMaxSendMessageSize(options.max_message_bytes);
  std::shared_ptr<grpc::ChannelCredentials> credentials =
      options.credentials ? options.credentials : grpc::InsecureChannelCredentials();
  return MakeGrpcConnection(
      grpc::CreateCustomChannel(wire::TargetWithDefaultPort(target), credentials, arguments),
      options.bearer_token);
}

std::shared_ptr<Connection> MakeGrpcConnection(std::shared_ptr<grpc::Channel> channel,
                                               const std::string& bearer_token) {
  return std::make_shared<GrpcConnection>(std::move(channel), bearer_token);
}

absl::StatusOr<std::shared_ptr<grpc::ChannelCredentials>> MakeTlsCredentials(
    const TlsFiles& files) {
  if (files.cert_file.empty() != files.key_file.empty()) {
    return absl::InvalidArgumentError(
        "a TLS client certificate needs both its certificate and its key file");
  }
  grpc::SslCredentialsOptions ssl;
  if (!files.ca_file.empty()) {
    absl::StatusOr<std::string> roots = ReadPem(files.ca_file, "TLS CA file", "CERTIFICATE");
    if (!roots.ok()) return roots.status();
    ssl.pem_root_certs = *std::move(roots);
  }
  if (!files.cert_file.empty()) {
    absl::StatusOr<std::string> chain =
        ReadPem(files.cert_file, "TLS certificate file", "CERTIFICATE");
    if (!chain.ok()) return chain.status();
    absl::StatusOr<std::string> key = ReadPem(files.key_file, "TLS key file", "PRIVATE KEY");
    if (!key.ok()) return key.status();
    ssl.pem_cert_chain = *std::move(chain);
    ssl.pem_private_key = *std::move(key);
  }
  return grpc::SslCredentials(ssl);
}

absl::StatusOr<std::string> ReadBearerToken(const std::string& path) {
  absl::StatusOr<std::string> text = ReadSmallFile(path, "token file");
  if (!text.ok()) return text.status();
  for (absl::string_view line : absl::StrSplit(*text, '\n')) {
    line = absl::StripAsciiWhitespace(line);
    if (line.empty() || absl::StartsWith(line, "#")) continue;
    for (char c : line) {
      // What an HTTP/2 header value may hold, less spaces (RFC 6750's token68 is narrower).
      if (c < 0x21 || c > 0x7e) {
        return absl::InvalidArgumentError(absl::StrCat(
            "token file ", path, ": the token holds a space or a non-printable character"));
      }
    }
    return std::string(line);
  }
  return absl::InvalidArgumentError(absl::StrCat("token file ", path, " holds no token"));
}

}  // namespace inscribe::client
