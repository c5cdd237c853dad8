// Exit statuses shared by every `inscribe` subcommand.
#pragma once

namespace inscribe::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitUnusableMesh = 1;  // the file was read but the mesh cannot be used
inline constexpr int kExitBadInput = 2;      // missing, unreadable or malformed input
inline constexpr int kExitUsage = 64;        // bad command line (CLI11 prints why)

}  // namespace inscribe::cli
