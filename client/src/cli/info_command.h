// `inscribe info MESH [--json]`: load, validate and describe a mesh.
#pragma once

#include <CLI/CLI.hpp>

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, its exit status is written to *exit_code.
void AddInfoCommand(CLI::App& app, int* exit_code);

}  // namespace inscribe::cli
