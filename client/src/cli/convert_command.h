// `inscribe convert SPHERES -o OUT`: a sphere file from one format into another (inscribe
// JSON, spheretree .sph, CSV, cuRobo YAML; OBJ meshes for viewers), without a mesh and
// without regenerating: what users do today by hand between tools.
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddConvertCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
