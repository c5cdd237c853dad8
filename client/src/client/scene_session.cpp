// SceneSession: a scene over one SceneStream call, its messages numbered and checked.
#include <chrono>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "inscribe/client/client.h"
#include "inscribe/wire/convert.h"

namespace inscribe::client {
namespace {

// A reply the server should never send: INTERNAL, with what is wrong with it.
absl::Status Malformed(absl::string_view problem) {
  return absl::InternalError(absl::StrCat("malformed SceneStream response: ", problem));
}

void AddObjects(const std::vector<SceneSessionObject>& objects, v1::SceneMessage* message) {
  message->mutable_add()->Reserve(static_cast<int>(objects.size()));
  for (const SceneSessionObject& object : objects) {
    wire::SceneObjectToProto(object.object, object.sphere_set_key, object.cover_key,
                             message->add_add());
  }
}

}  // namespace

SceneSession::SceneSession(std::unique_ptr<SceneStreamConnection> stream,
                           const SceneSessionOptions& options)
    : stream_(std::move(stream)), options_(options) {}

SceneSession::SceneSession(SceneSession&&) noexcept = default;
SceneSession& SceneSession::operator=(SceneSession&&) noexcept = default;
// Destroying the stream cancels the call if Close did not finish it.
SceneSession::~SceneSession() = default;

absl::Status SceneSession::Create(const std::vector<SceneSessionObject>& objects) {
  v1::SceneMessage message;
  message.set_volume(wire::VolumeToProto(options_.volume));
  AddObjects(objects, &message);
  wire::SceneIgnoredToProto(options_.ignored, &message);
  wire::SceneQueryToProto(options_.query, message.mutable_query());
  absl::StatusOr<SceneFrameResult> created = RoundTrip(message);
  if (!created.ok()) return created.status();
  created_ = *std::move(created);
  return absl::OkStatus();
}

absl::StatusOr<SceneFrameResult> SceneSession::Frame(
    const std::vector<std::pair<SceneObjectId, RigidPose>>& poses) {
  v1::SceneMessage message;
  wire::ScenePosesToProto(poses, &message);
  return RoundTrip(message);
}

absl::StatusOr<SceneFrameResult> SceneSession::Update(const SceneChanges& changes) {
  v1::SceneMessage message;
  for (SceneObjectId id : changes.remove) message.add_remove(id);
  AddObjects(changes.add, &message);
  wire::SceneIgnoredToProto(changes.ignore, &message);
  wire::ScenePosesToProto(changes.poses, &message);
  if (changes.query) wire::SceneQueryToProto(*changes.query, message.mutable_query());
  return RoundTrip(message);
}

absl::StatusOr<SceneFrameResult> SceneSession::RoundTrip(v1::SceneMessage& message) {
  if (!broken_.ok()) return broken_;
  if (stream_ == nullptr) return absl::FailedPreconditionError("scene session was moved from");
  message.set_frame(next_frame_);
  // Every failure below ends the session: the server's status, or a reply this message cannot
  // be matched with (whose stream is then out of step for good).
  absl::StatusOr<v1::SceneReply> reply =
      stream_->RoundTrip(message, std::chrono::system_clock::now() + options_.frame_timeout);
  if (!reply.ok()) return Break(reply.status());
  if (reply->frame() != next_frame_) {
    return Break(
        Malformed(absl::StrCat("frame ", next_frame_, " was answered as frame ", reply->frame())));
  }
  absl::StatusOr<SceneFrame> frame = wire::SceneFrameFromProto(*reply);
  if (!frame.ok()) return Break(Malformed(frame.status().message()));
  ++next_frame_;
  SceneFrameResult result;
  static_cast<SceneFrame&>(result) = *std::move(frame);
  result.objects = reply->objects();
  result.server_seconds = reply->seconds();
  return result;
}

absl::Status SceneSession::Break(absl::Status failure) {
  broken_ = failure;
  stream_.reset();  // cancels the call now, which frees the server's scene
  return failure;
}

absl::Status SceneSession::Close() {
  if (!broken_.ok()) return broken_;
  if (stream_ == nullptr) return absl::FailedPreconditionError("scene session was moved from");
  const absl::Status status = stream_->Finish();
  stream_.reset();
  broken_ = status.ok() ? absl::FailedPreconditionError("scene session is closed") : status;
  return status;
}

}  // namespace inscribe::client
