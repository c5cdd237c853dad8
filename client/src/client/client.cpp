#include "inscribe/client/client.h"

#include <algorithm>
#include <functional>
#include <random>
#include <thread>
#include <utility>

#include "absl/strings/str_cat.h"
#include "inscribe/server/convert.h"

namespace inscribe::client {
namespace {

// Wait before attempt `attempt + 1` (attempt counts from 1): exponential, capped, jittered.
std::chrono::milliseconds Backoff(const RetryPolicy& policy, int attempt) {
  double ms = static_cast<double>(policy.initial_backoff.count());
  for (int i = 1; i < attempt; ++i) ms *= policy.multiplier;
  ms = std::min(ms, static_cast<double>(policy.max_backoff.count()));
  thread_local std::mt19937 random_bits{std::random_device{}()};
  ms *= std::uniform_real_distribution<double>(0.5, 1.0)(random_bits);
  return std::chrono::milliseconds(static_cast<std::int64_t>(ms));
}

// Runs `attempt` until it succeeds, fails with a code other than UNAVAILABLE, the attempts run
// out, or the next wait would end past `deadline`. For idempotent calls only. Every attempt
// gets the same (overall) deadline.
absl::Status RetryIdempotent(const RetryPolicy& policy, Deadline deadline,
                             const std::function<absl::Status(Deadline)>& attempt) {
  const int max_attempts = std::max(1, policy.max_attempts);
  for (int n = 1;; ++n) {
    absl::Status status = attempt(deadline);
    if (status.code() != absl::StatusCode::kUnavailable) return status;
    const std::chrono::milliseconds wait = Backoff(policy, n);
    if (n == max_attempts || std::chrono::system_clock::now() + wait >= deadline) {
      if (n == 1) return status;
      return absl::UnavailableError(
          absl::StrCat(status.message(), " (gave up after ", n, " attempts)"));
    }
    std::this_thread::sleep_for(wait);
  }
}

}  // namespace

Client::Client(std::shared_ptr<Connection> connection, ClientOptions options)
    : connection_(std::move(connection)), options_(std::move(options)) {}

absl::StatusOr<InspectMeshResult> Client::InspectMesh(const Mesh& mesh,
                                                      const InspectMeshOptions& options) const {
  v1::InspectMeshRequest request;
  server::MeshToProto(mesh, request.mutable_mesh());
  request.set_skip_self_intersections(options.skip_self_intersections);

  const Deadline deadline =
      std::chrono::system_clock::now() + options.timeout.value_or(options_.default_timeout);
  absl::StatusOr<v1::InspectMeshResponse> response;
  const absl::Status status = RetryIdempotent(options_.retry, deadline, [&](Deadline d) {
    response = connection_->InspectMesh(request, d);
    return response.status();
  });
  if (!status.ok()) return status;

  absl::StatusOr<MeshReport> report = server::MeshReportFromProto(response->report());
  if (!report.ok()) {
    return absl::InternalError(
        absl::StrCat("malformed InspectMesh response: ", report.status().message()));
  }
  return InspectMeshResult{std::move(*response->mutable_mesh_sha256()), *std::move(report)};
}

}  // namespace inscribe::client
