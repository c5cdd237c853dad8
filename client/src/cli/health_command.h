// `inscribe health --server ADDR[,ADDR...]`: asks each server's standard gRPC health service
// whether inscribe.v1.Inscribe is SERVING. Exit 0 when every one is, 69 otherwise; the probe
// of container health checks and load balancers (remote only).
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddHealthCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
