// `inscribe convert SPHERES -o OUT`: a sphere file from one format into another (inscribe
// JSON, spheretree .sph, CSV, cuRobo YAML; OBJ meshes for viewers), without a mesh and
// without regenerating: what users do today by hand between tools.
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, it leaves its outcome in *outcome.
void AddConvertCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
