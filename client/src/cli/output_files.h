// The files a command writes: checked when the command line is parsed, before any work, and
// named on stderr once written.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace inscribe::cli {

// A CLI11 check for an option naming a file to write: not a folder, and its folder exists and
// this process may write there. Fails the parse ("-o: folder out/ does not exist") so that a
// wrong path costs nothing.
CLI::Validator WritableFile();
// Whether WritableFile refused a path in this process: main then exits kExitBadInput (2), as
// for any file that cannot be written, not kExitUsage.
bool OutputPathRefused();

// The sphere file format `path` gets: `format` when given, else its extension's. UsageError
// naming --format and the formats when neither says: checked before any work.
absl::Status CheckSphereOutputFormat(const std::string& path, const std::string& format);

// "inscribe: wrote PATH (WHAT)" on stderr: every command says so once per file it writes.
void ReportWritten(const std::string& path, absl::string_view what);

}  // namespace inscribe::cli
