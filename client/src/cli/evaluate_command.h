// `inscribe evaluate MESH SPHERES [--json]`: the quality report of any sphere file (ours or
// another tool's: JSON, spheretree .sph, CSV, cuRobo YAML) against a mesh.
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddEvaluateCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
