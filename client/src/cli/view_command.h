// `inscribe view MESH SPHERES [-o report.html]`: one self-contained HTML page showing the mesh
// and the spheres in 3D (three.js, embedded) with the quality report and the paper's Fig. 7
// histograms of signed distances between the boundary and the spheres' envelope.
#pragma once

#include <CLI/CLI.hpp>

#include "command_outcome.h"

namespace inscribe::cli {

// Registers the subcommand on `app`; when it runs, it leaves its outcome in *outcome.
void AddViewCommand(CLI::App& app, CommandOutcome* outcome);

}  // namespace inscribe::cli
