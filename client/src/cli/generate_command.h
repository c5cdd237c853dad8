// `inscribe generate MESH [--voxel-size S | --max-spheres N] ...`: medial spheres for a mesh.
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddGenerateCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
