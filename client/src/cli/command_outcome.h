// How a subcommand ends. Commands return an absl::Status; `main` prints it once
// (ReportOutcome) and maps it to the process's exit status once (ExitCodeOf).
#pragma once

#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"
#include "exit_codes.h"

namespace inscribe::cli {

// A failure found here, in this process (files, flags, a probe's verdict), ending the process
// with `exit_code`.
absl::Status CommandError(absl::StatusCode code, absl::string_view message, int exit_code);
// The usual ones.
absl::Status BadInputError(absl::string_view message);      // kExitBadInput
absl::Status UnusableMeshError(absl::string_view message);  // kExitUnusableMesh
absl::Status UsageError(absl::string_view message);         // kExitUsage
absl::Status BugError(absl::string_view message);           // kExitInternal: a bug here

// `status` (not OK), ending the process with `exit_code` instead of its code's usual one: for
// the few service answers a command reads differently (e.g. generate's INVALID_ARGUMENT is a
// bad command line). Keeps the message, the code and where it came from.
absl::Status WithExitCode(absl::Status status, int exit_code);

// `status` (not OK) with "<context>: " before its message; code and payloads kept.
absl::Status WithContext(absl::string_view context, const absl::Status& status);

// The exit status for `status`: OK is kExitOk; one made above or by WithExitCode carries its
// own; any other is the service's, mapped by code (UNAVAILABLE and DEADLINE_EXCEEDED are
// kExitServerUnavailable, INVALID_ARGUMENT / NOT_FOUND / OUT_OF_RANGE / RESOURCE_EXHAUSTED
// kExitBadInput, FAILED_PRECONDITION kExitUnusableMesh, UNAUTHENTICATED / PERMISSION_DENIED
// kExitNotAuthorized, anything else kExitInternal).
int ExitCodeOf(const absl::Status& status);

// What the subcommand that ran left for `main`.
struct CommandOutcome {
  absl::Status status;
  // The --server the command called ("" in embedded mode): the service's errors then name it.
  std::string server;
};

// Prints a failed outcome on stderr as one line, `inscribe: <message>`, followed by
// ` (server ADDR: CODE)` when the service at --server answered it; returns ExitCodeOf.
int ReportOutcome(const CommandOutcome& outcome);

}  // namespace inscribe::cli
