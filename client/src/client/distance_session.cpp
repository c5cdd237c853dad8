// DistanceSession: frames over one DistanceStream call, numbered and checked.
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
  return absl::InternalError(absl::StrCat("malformed DistanceStream response: ", problem));
}

}  // namespace

DistanceSession::DistanceSession(std::unique_ptr<DistanceStreamConnection> stream,
                                 const DistanceSessionOptions& options)
    : stream_(std::move(stream)), options_(options) {}

DistanceSession::DistanceSession(DistanceSession&&) noexcept = default;
DistanceSession& DistanceSession::operator=(DistanceSession&&) noexcept = default;
// Destroying the stream cancels the call if Close did not finish it.
DistanceSession::~DistanceSession() = default;

absl::StatusOr<v1::DistanceFrameResult> DistanceSession::RoundTrip(
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
    out->set_cover_a(pair.cover_a);
    out->set_cover_b(pair.cover_b);
  }
  // Every failure below ends the session: the server's status, or a reply this frame cannot
  // be matched with (whose stream is then out of step for good).
  absl::StatusOr<v1::DistanceFrameResult> reply =
      stream_->RoundTrip(frame, std::chrono::system_clock::now() + options_.frame_timeout);
  if (!reply.ok()) return Break(reply.status());
  if (reply->frame() != next_frame_) {
    return Break(
        Malformed(absl::StrCat("frame ", next_frame_, " was answered as frame ", reply->frame())));
  }
  if (reply->results().distances_size() != static_cast<int>(pairs.size())) {
    return Break(
        Malformed(absl::StrCat("frame ", next_frame_, " has ", reply->results().distances_size(),
                               " results for ", pairs.size(), " pairs")));
  }
  ++next_frame_;
  return reply;
}

absl::Status DistanceSession::Break(absl::Status failure) {
  broken_ = failure;
  stream_.reset();  // cancels the call now rather than when the session goes away
  return failure;
}

absl::StatusOr<std::vector<DistanceResult>> DistanceSession::Query(
    const std::vector<PosePair>& pairs) {
  absl::StatusOr<v1::DistanceFrameResult> reply = RoundTrip(pairs);
  if (!reply.ok()) return reply.status();
  absl::StatusOr<std::vector<DistanceResult>> results =
      wire::DistanceResultsFromProto(reply->results());
  if (!results.ok()) return Break(Malformed(results.status().message()));
  return results;
}

absl::StatusOr<std::vector<CertifiedDistanceResult>> DistanceSession::QueryCertified(
    const std::vector<PosePair>& pairs) {
  absl::StatusOr<v1::DistanceFrameResult> reply = RoundTrip(pairs);
  if (!reply.ok()) return reply.status();
  absl::StatusOr<std::vector<CertifiedDistanceResult>> results =
      wire::CertifiedDistanceResultsFromProto(reply->results());
  if (!results.ok()) return Break(Malformed(results.status().message()));
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
