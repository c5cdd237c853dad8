// Exit statuses shared by every `inscribe` subcommand (64 and up follow sysexits.h).
#pragma once

namespace inscribe::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitUnusableMesh = 1;  // the file was read but the mesh cannot be used
inline constexpr int kExitBadInput = 2;      // missing, unreadable or malformed input
inline constexpr int kExitUsage = 64;        // bad command line (CLI11 prints why)
// --server: the server could not be reached (UNAVAILABLE after the client's retries) or did
// not answer within --timeout (DEADLINE_EXCEEDED). Worth retrying later; nothing is wrong
// with the input. sysexits' EX_UNAVAILABLE.
inline constexpr int kExitServerUnavailable = 69;
// --server refused the caller: no or a wrong bearer token (UNAUTHENTICATED; --token-file), or
// not allowed (PERMISSION_DENIED). Retrying will not help until the credentials change.
// sysexits' EX_NOPERM.
inline constexpr int kExitNotAuthorized = 77;
// A bug, here or in the server (an unexpected exception, INTERNAL, UNIMPLEMENTED, ...).
inline constexpr int kExitInternal = 70;

}  // namespace inscribe::cli
