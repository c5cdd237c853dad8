// `inscribe stats --server ADDR [--json]`: the server's cache counters (remote only).
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, it leaves its outcome in *outcome.
void AddStatsCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
