// DistanceSession: frames over one DistanceStream call, numbered and checked.
#include <chrono>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/client/client.h"
#include "inscribe/wire/convert.h"

namespace inscribe::client {

DistanceSession::DistanceSession(std::unique_ptr<DistanceStreamConnection> stream,
                                 const DistanceSessionOptions& options)
    : stream_(std::move(stream)), options_(options) {}

DistanceSession::DistanceSession(DistanceSession&&) noexcept = default;
DistanceSession& DistanceSession::operator=(DistanceSession&&) noexcept = default;
// Destroying the stream cancels the call if Close did not finish it.
DistanceSession::~DistanceSession() = default;

absl::StatusOr<std::vector<DistanceResult>> DistanceSession::Query(
    const std::vector<PosePair>& pairs) {
  if (!broken_.ok()) return broken_;
  if (stream_ == nullptr) return absl::FailedPreconditionError("distance session was moved from");

  v1::DistanceFrame frame;
  frame.set_frame(next_frame_);
  frame.set_volume(wire::VolumeToProto(options_.volume));
  wire::ToleranceToProto(options_.tolerance, frame.mutable_tolerance());
  frame.mutable_pairs()->Reserve(static_cast<int>(pairs.size()));
  for (const PosePair& pair : pairs) {
    v1::DistancePair* out = frame.add_pairs();
    out->set_sphere_set_a(pair.sphere_set_a);
    out->set_sphere_set_b(pair.sphere_set_b);
    wire::PoseToProto(pair.pose_a, out->mutable_pose_a());
    wire::PoseToProto(pair.pose_b, out->mutable_pose_b());
  }

  // Every failure below ends the session: the server's status, or a reply this frame cannot
  // be matched with (whose stream is then out of step for good).
  absl::Status failure;
  absl::StatusOr<std::vector<DistanceResult>> results;
  absl::StatusOr<v1::DistanceFrameResult> reply =
      stream_->RoundTrip(frame, std::chrono::system_clock::now() + options_.frame_timeout);
  if (!reply.ok()) {
    failure = reply.status();
  } else if (reply->frame() != next_frame_) {
    failure =
        absl::InternalError(absl::StrCat("malformed DistanceStream response: frame ", next_frame_,
                                         " was answered as frame ", reply->frame()));
  } else if (results = wire::DistanceResultsFromProto(reply->results()); !results.ok()) {
    failure = absl::InternalError(
        absl::StrCat("malformed DistanceStream response: ", results.status().message()));
  } else if (results->size() != pairs.size()) {
    failure = absl::InternalError(absl::StrCat("malformed DistanceStream response: frame ",
                                               next_frame_, " has ", results->size(),
                                               " results for ", pairs.size(), " pairs"));
  }
  if (!failure.ok()) {
    broken_ = failure;
    stream_.reset();  // cancels the call now rather than when the session goes away
    return failure;
  }
  ++next_frame_;
  return results;
}

absl::Status DistanceSession::Close() {
  if (!broken_.ok()) return broken_;
  if (stream_ == nullptr) return absl::FailedPreconditionError("distance session was moved from");
  const absl::Status status = stream_->Finish();
  stream_.reset();
  broken_ = status.ok() ? absl::FailedPreconditionError("distance session is closed") : status;
  return status;
}

}  // namespace inscribe::client
