// `inscribe evaluate MESH SPHERES [--json]`: the quality report of any sphere file (ours or
// another tool's: JSON, spheretree .sph, CSV, cuRobo YAML) against a mesh.
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, it leaves its outcome in *outcome.
void AddEvaluateCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
