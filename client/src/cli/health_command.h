// `inscribe health --server ADDR[,ADDR...]`: asks each server's standard gRPC health service
// whether inscribe.v1.Inscribe is SERVING. Exit 0 when every one is, 69 otherwise; the probe
// of container health checks and load balancers (remote only).
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, it leaves its outcome in *outcome.
void AddHealthCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
