#include "command_outcome.h"

#include <iostream>
#include <optional>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"

namespace inscribe::cli {
namespace {

// The exit status a status carries (its decimal digits), when it carries one.
constexpr char kExitPayload[] = "type.inscribe.dev/cli-exit";
// Present on failures found in this process rather than answered by the service.
constexpr char kLocalPayload[] = "type.inscribe.dev/cli-local";

std::optional<int> CarriedExitCode(const absl::Status& status) {
  const absl::optional<absl::Cord> payload = status.GetPayload(kExitPayload);
  int code = 0;
  if (payload && absl::SimpleAtoi(std::string(*payload), &code)) return code;
  return std::nullopt;
}

}  // namespace

absl::Status CommandError(absl::StatusCode code, absl::string_view message, int exit_code) {
  absl::Status status(code, message);
  status.SetPayload(kLocalPayload, absl::Cord());
  return WithExitCode(std::move(status), exit_code);
}

absl::Status BadInputError(absl::string_view message) {
  return CommandError(absl::StatusCode::kInvalidArgument, message, kExitBadInput);
}
absl::Status UnusableMeshError(absl::string_view message) {
  return CommandError(absl::StatusCode::kFailedPrecondition, message, kExitUnusableMesh);
}
absl::Status UsageError(absl::string_view message) {
  return CommandError(absl::StatusCode::kInvalidArgument, message, kExitUsage);
}
absl::Status BugError(absl::string_view message) {
  return CommandError(absl::StatusCode::kInternal, message, kExitInternal);
}

absl::Status WithExitCode(absl::Status status, int exit_code) {
  status.SetPayload(kExitPayload, absl::Cord(absl::StrFormat("%d", exit_code)));
  return status;
}

absl::Status WithContext(absl::string_view context, const absl::Status& status) {
  absl::Status out(status.code(), absl::StrFormat("%s: %s", context, status.message()));
  status.ForEachPayload(
      [&out](absl::string_view type, const absl::Cord& payload) { out.SetPayload(type, payload); });
  return out;
}

int ExitCodeOf(const absl::Status& status) {
  if (status.ok()) return kExitOk;
  if (const std::optional<int> carried = CarriedExitCode(status)) return *carried;
  switch (status.code()) {
    case absl::StatusCode::kUnavailable:
    case absl::StatusCode::kDeadlineExceeded:
      return kExitServerUnavailable;
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kOutOfRange:
    case absl::StatusCode::kResourceExhausted:
      return kExitBadInput;
    case absl::StatusCode::kFailedPrecondition:
      return kExitUnusableMesh;
    case absl::StatusCode::kUnauthenticated:
    case absl::StatusCode::kPermissionDenied:
      return kExitNotAuthorized;
    default:
      return kExitInternal;
  }
}

int ReportOutcome(const CommandOutcome& outcome) {
  const absl::Status& status = outcome.status;
  if (status.ok()) return kExitOk;
  std::cerr << "inscribe: " << status.message();
  if (!outcome.server.empty() && !status.GetPayload(kLocalPayload)) {
    std::cerr << absl::StrFormat(" (server %s: %s)", outcome.server,
                                 absl::StatusCodeToString(status.code()));
  }
  std::cerr << "\n";
  return ExitCodeOf(status);
}

}  // namespace inscribe::cli
