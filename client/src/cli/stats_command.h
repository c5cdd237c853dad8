// `inscribe stats --server ADDR [--json]`: the server's cache counters (remote only).
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddStatsCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
